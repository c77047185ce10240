// Prismatic joints (sliders): limits under gravity, the motor's speed and force cap, the
// spring's frequency and sag, and the rows that keep B on the axis without turning.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "joint_scenes.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

// A box (0.2 m cube) on a slider from a static anchor at the origin along `axis`.
struct Slider {
    BodyHandle anchor, body;
    JointHandle joint;
};

Slider make_slider(Space& space, const Vec3& axis, double mass, const PrismaticParams& params) {
    Slider s;
    s.anchor = add_static(space, Vec3::Zero());
    s.body = add_box(space, Vec3::Zero(), Vec3(0.1, 0.1, 0.1), mass);
    JointDesc d = JointDesc::prismatic_at(s.anchor, s.body, Vec3::Zero(), axis);
    PrismaticParams p = params;
    p.axis_a = axis;
    d.prismatic = p;
    s.joint = space.create_joint(d);
    return s;
}

}  // namespace

// Soft rows give under a load as springs of the joints' 60 Hz (w = 377 rad/s) for the
// mass they move: the limit under the weight by g / w^2 = 7e-5 m, the rotation under the
// 3.7 N m torque by tau / (I w^2) = 2.0e-3 rad (I = 0.0133 kg m^2), the anchor off the
// axis under the 36 N push by about F / (m w^2) = 1.3e-4 m.
TEST(Prismatic, VerticalSliderUnderGravityStopsAtItsLowerLimit) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    PrismaticParams p;
    p.enable_limit = true;
    p.lower_translation = -0.5;
    p.upper_translation = 0.3;
    const Slider s = make_slider(space, Vec3::UnitY(), 2, p);
    double lowest = 0;
    for (int i = 0; i < 120; ++i) {
        // Pushed sideways and twisted as it falls: the slider keeps it on the axis, unturned.
        space.add_force(s.body, Vec3(30, 0, -20));
        space.add_torque(s.body, Vec3(1, 2, 3));
        space.update();
        lowest = std::min(lowest, space.internal_position(s.body).y());
    }
    const Vec3 x = space.internal_position(s.body);
    const JointError e = space.internal_joint_error(s.joint);
    std::printf(
        "slider limit -0.5 m under gravity: lowest %.6f m, rests at %.6f m, off the axis %.2e m, turned %.2e rad\n",
        lowest, x.y(), x.head<1>().norm() + std::abs(x.z()), e.angular);
    EXPECT_NEAR(x.y(), -0.5, 2e-4);
    EXPECT_GT(lowest, -0.5 - 0.005);
    EXPECT_LT(std::abs(x.x()) + std::abs(x.z()), 1e-3);
    EXPECT_LT(e.angular, 2.5e-3);
    EXPECT_LT(space.internal_orientation(s.body).angularDistance(Quat::Identity()), 2.5e-3);
    EXPECT_LT(e.linear, 5e-4);
    // Thrown up, it stops at the upper limit.
    double highest = -1;
    space.set_linear_velocity(s.body, Vec3(0, 8, 0));
    for (int i = 0; i < 30; ++i) {
        space.update();
        highest = std::max(highest, space.internal_position(s.body).y());
    }
    std::printf("slider limit 0.3 m thrown up at 8 m/s: highest %.6f m\n", highest);
    EXPECT_LT(highest, 0.3 + 0.005);
    EXPECT_GT(highest, 0.29);
}

// A 5 kg box on a vertical slider driven up at 0.5 m/s: with 100 N it lifts its 49 N
// weight at that speed; with 30 N it slips down at g - 30 / 5 = 3.81 m/s^2.
TEST(Prismatic, MotorReachesItsSpeedAndItsForceCapHolds) {
    for (const double cap : {100.0, 30.0}) {
        Space space;
        space.set_sleep(SleepSettings{.enabled = false});
        PrismaticParams p;
        p.enable_motor = true;
        p.motor_speed = 0.5;
        p.max_motor_force = cap;
        const Slider s = make_slider(space, Vec3::UnitY(), 5, p);
        const int steps = 30;
        for (int i = 0; i < steps; ++i) space.update();
        const double v = space.internal_linear_velocity(s.body).y();
        const double expected = cap > 5 * kG ? 0.5 : -(kG - cap / 5) * steps * kDt;
        std::printf("slider motor 0.5 m/s, cap %.0f N, 5 kg: v %.6f m/s (expected %.6f)\n", cap, v, expected);
        EXPECT_NEAR(v, expected, cap > 5 * kG ? 1e-4 : 0.01 * std::abs(expected));
    }
}

// A 2 kg box on a horizontal slider with a 2 Hz spring toward 0.2 m (k = m (2 pi f)^2),
// released at 0: it oscillates about 0.2 m with a 0.5 s period.
TEST(Prismatic, SpringOscillatesAtItsFrequency) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    PrismaticParams p;
    p.enable_spring = true;
    p.spring_hertz = 2;
    p.target_translation = 0.2;
    const Slider s = make_slider(space, Vec3::UnitX(), 2, p);
    std::vector<double> crossings;
    double previous = -0.2, highest = 0;
    for (int i = 0; i < 60 * 3; ++i) {
        space.update();
        const double x = space.internal_position(s.body).x() - 0.2;
        if ((previous < 0) != (x < 0)) crossings.push_back(kDt * (i - 1 + previous / (previous - x)));
        previous = x;
        highest = std::max(highest, x + 0.2);
    }
    ASSERT_GE(crossings.size(), 3u);
    const double period = 2 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
    std::printf("slider spring 2 Hz: period %.5f s (0.5 analytic), highest %.4f m (0.4 undamped)\n", period, highest);
    EXPECT_NEAR(period, 0.5, 0.5 * 0.03);
    EXPECT_GT(highest, 0.35);  // an undamped spring swings through its target to about 0.4
}

// Hung on a vertical slider with a critically damped spring it settles below the target
// by m g / k = g / (2 pi f)^2: 0.0621 m at 2 Hz, whatever the mass.
TEST(Prismatic, SpringSettlesAtTargetMinusWeightOverStiffness) {
    for (const double mass : {1.0, 20.0}) {
        Space space;
        space.set_sleep(SleepSettings{.enabled = false});
        PrismaticParams p;
        p.enable_spring = true;
        p.spring_hertz = 2;
        p.spring_damping_ratio = 1;
        p.target_translation = 0.1;
        const Slider s = make_slider(space, Vec3::UnitY(), mass, p);
        for (int i = 0; i < 240; ++i) space.update();
        const double y = space.internal_position(s.body).y();
        const double expected = 0.1 - kG / std::pow(2 * kPi * 2, 2);
        std::printf("slider spring 2 Hz, target 0.1 m, %.0f kg: rests at %.6f m (expected %.6f)\n", mass, y, expected);
        EXPECT_NEAR(y, expected, 1e-4);
    }
}

// Between two moving bodies the axis turns with A: a pair spun about a tilted axis keeps
// B on A's axis and unturned relative to A, while B slides out under the spin to its
// upper limit.
TEST(Prismatic, KeepsBOnTheAxisOfASpinningA) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle a = add_box(space, Vec3::Zero(), Vec3(0.3, 0.2, 0.1), 2);
    const BodyHandle b = add_box(space, Vec3(0.5, 0, 0), Vec3(0.1, 0.1, 0.1), 1);
    JointDesc d = JointDesc::prismatic_at(a, b, Vec3(0.5, 0, 0), Vec3::UnitX());
    d.prismatic.enable_limit = true;
    d.prismatic.lower_translation = -0.2;
    d.prismatic.upper_translation = 0.4;
    const JointHandle joint = space.create_joint(d);
    space.set_angular_velocity(a, Vec3(0.5, 0, 3));
    JointError worst;
    for (int i = 0; i < 300; ++i) {
        space.update();
        const JointError e = space.internal_joint_error(joint);
        worst.linear = std::max(worst.linear, e.linear);
        worst.angular = std::max(worst.angular, e.angular);
    }
    const Quat qa = space.internal_orientation(a);
    const double along = (qa * Vec3::UnitX()).dot(space.internal_position(b) - space.internal_position(a));
    std::printf("slider on a spinning body: worst error %.2e m %.2e rad, B at %.4f m along A's axis (limit 0.9)\n",
                worst.linear, worst.angular, along);
    EXPECT_LT(worst.linear, 5e-3);
    EXPECT_LT(worst.angular, 5e-3);
    EXPECT_NEAR(along, 0.5 + 0.4, 5e-3);  // thrown out to the upper limit
    EXPECT_LT((space.internal_angular_velocity(b) - space.internal_angular_velocity(a)).norm(), 1e-3);  // turns with A
    EXPECT_GT(space.internal_angular_velocity(a).norm(), 0.3);
}
