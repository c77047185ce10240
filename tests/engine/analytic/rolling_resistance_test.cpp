// Rolling resistance (BodyDesc::rolling_resistance, Box3D's): a rolling ball or capsule on
// flat ground slows at the rate its cap allows and stops; without it, it rolls on; a box or
// plank at rest stays at rest; the pair mixes the larger coefficient; a compound's part
// brakes with its own radius; a change after creation brakes from the next step.
//
// The rate: the row's angular impulse is at most c R N h a substep (c the coefficient, R the
// rolling radius, N h the normal impulse), a braking torque c R m g on a body of mass m
// rolling without slipping on level ground, so it slows at a = c g m R^2 / (I + m R^2) (I about
// its axis: 5/7 c g for a solid ball). The row stops the spin outright when it can, so it
// brakes at that cap until the body stops at v0 / a.
#include "scene_util.hpp"
#include "static_bodies.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace spindle;
using namespace spindle::stability;

namespace {

constexpr double kSpeed = 2;  // m/s, the rolling start

void add_ground(Space& space, double rolling_resistance = 0) {
    BodyDesc g = test::ground_plane();
    g.rolling_resistance = rolling_resistance;
    space.create_body(g);
}

// A body of radius r about the z axis rolling in +x at kSpeed without slipping.
BodyDesc rolling(const Shape& shape, double r, double rolling_resistance) {
    BodyDesc d;
    d.shape = shape;
    d.position = Vec3(0, r, 0);
    d.linear_velocity = Vec3(kSpeed, 0, 0);
    d.angular_velocity = Vec3(0, 0, -kSpeed / r);
    d.rolling_resistance = rolling_resistance;
    return d;
}

// The analytic deceleration of a body rolling on level ground against its cap:
// c g m R^2 / (I + m R^2), I its inertia about the rolling axis (z, world).
double braking(const BodyDesc& d, double c, double r) {
    const MassProperties mp = mass_of(d);
    const Mat3 inertia = d.orientation.toRotationMatrix() * mp.inertia * d.orientation.toRotationMatrix().transpose();
    return c * kGravity * mp.mass * r * r / (inertia(2, 2) + mp.mass * r * r);
}

struct Roll {
    std::vector<double> speed;  // along x after each step
    double stop_time = -1;      // s: the first step after which |v| < 1 mm/s (-1: never)
};

Roll roll(Space& space, BodyHandle body, int steps) {
    Roll r;
    for (int step = 1; step <= steps; ++step) {
        space.update();
        const double v = space.internal_linear_velocity(body).x();
        r.speed.push_back(v);
        if (r.stop_time < 0 && std::abs(v) < 1e-3) r.stop_time = step * kStep;
    }
    return r;
}

// The mean deceleration between two times (s), from the speeds after the steps then.
double deceleration(const Roll& r, double from, double to) {
    const auto at = [&](double t) { return r.speed[static_cast<std::size_t>(std::lround(t / kStep)) - 1]; };
    return (at(from) - at(to)) / (to - from);
}

}  // namespace

// A solid ball (radius 0.5, coefficient 0.1) slows at 5/7 c g, steadily, and stops at v0 / a;
// without rolling resistance it rolls on at its speed.
TEST(RollingResistance, BallSlowsAtItsCapAndStops_AndRollsOnWithout) {
    constexpr double kC = 0.1, kR = 0.5;
    auto space = make_space();
    add_ground(*space);
    const BodyDesc d = rolling(Shape::sphere(kR), kR, kC);
    const double a = braking(d, kC, kR);
    ASSERT_NEAR(a, 5.0 / 7.0 * kC * kGravity, 1e-9);
    const double stop = kSpeed / a;
    const BodyHandle ball = space->create_body(d);
    const Roll r = roll(*space, ball, static_cast<int>(1.5 * stop / kStep));
    const double measured = deceleration(r, 0.2 * stop, 0.8 * stop);
    // Steady: every step's loss over the same span within 10 % of a h (warm started, the row
    // carries its cap from substep to substep and from step to step).
    double worst_step = 0;
    for (auto k = static_cast<std::size_t>(0.1 * stop / kStep); k < static_cast<std::size_t>(0.9 * stop / kStep); ++k) {
        worst_step = std::max(worst_step, std::abs((r.speed[k - 1] - r.speed[k]) / kStep - a) / a);
    }
    std::printf("[ measure  ] ball c %.2f: deceleration %.4f m/s^2 (analytic %.4f), worst step %.3g of it, stopped at "
                "%.3f s (analytic %.3f s)\n",
                kC, measured, a, worst_step, r.stop_time, stop);
    EXPECT_NEAR(measured, a, 0.03 * a);
    EXPECT_LT(worst_step, 0.1);
    EXPECT_GT(r.stop_time, 0.95 * stop);
    EXPECT_LT(r.stop_time, 1.05 * stop + 2 * kStep);
    EXPECT_NEAR(space->internal_angular_velocity(ball).norm(), 0, 1e-2);

    auto free = make_space();
    add_ground(*free);
    const BodyHandle free_ball = free->create_body(rolling(Shape::sphere(kR), kR, 0));
    const Roll f = roll(*free, free_ball, static_cast<int>(stop / kStep));
    std::printf("[ measure  ] ball without: %.4f m/s after %.3f s\n", f.speed.back(), stop);
    EXPECT_GT(f.speed.back(), 0.99 * kSpeed);
}

// A capsule lying across its rolling direction (two contact points, one manifold) slows at
// its own analytic rate and settles; without rolling resistance it rolls on.
TEST(RollingResistance, CapsuleRollingOnItsSideSettles_AndRollsOnWithout) {
    constexpr double kC = 0.2, kR = 0.3;
    auto space = make_space();
    add_ground(*space);
    BodyDesc d = rolling(Shape::capsule(0.8, kR), kR, kC);
    d.orientation = Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()));  // its axis along z
    const double a = braking(d, kC, kR);
    const double stop = kSpeed / a;
    const BodyHandle capsule = space->create_body(d);
    const Roll r = roll(*space, capsule, static_cast<int>(1.5 * stop / kStep));
    const double measured = deceleration(r, 0.2 * stop, 0.8 * stop);
    std::printf("[ measure  ] capsule c %.2f: deceleration %.4f m/s^2 (analytic %.4f), stopped at %.3f s (analytic "
                "%.3f s), spin after %.3g rad/s\n",
                kC, measured, a, r.stop_time, stop, space->internal_angular_velocity(capsule).norm());
    EXPECT_NEAR(measured, a, 0.03 * a);
    EXPECT_GT(r.stop_time, 0.95 * stop);
    EXPECT_LT(r.stop_time, 1.05 * stop + 2 * kStep);
    EXPECT_LT(space->internal_angular_velocity(capsule).norm(), 1e-2);

    auto free = make_space();
    add_ground(*free);
    d.rolling_resistance = 0;
    const BodyHandle free_capsule = free->create_body(d);
    const Roll f = roll(*free, free_capsule, static_cast<int>(stop / kStep));
    std::printf("[ measure  ] capsule without: %.4f m/s after %.3f s\n", f.speed.back(), stop);
    EXPECT_GT(f.speed.back(), 0.99 * kSpeed);
}

// A cube and a plank (a large coefficient, 1) resting on the ground stay where they are: the
// row pushes no spin into a body at rest, so nothing creeps and no energy is gained.
TEST(RollingResistance, BoxAndPlankAtRestStayAtRest) {
    auto space = make_space();
    add_ground(*space, 1);
    std::vector<BodyHandle> bodies;
    for (const Vec3& half : {Vec3(0.5, 0.5, 0.5), Vec3(1.5, 0.1, 0.4)}) {
        BodyDesc d;
        d.shape = Shape::box(half);
        d.position = Vec3(bodies.size() * 5.0, half.y(), 0);
        d.rolling_resistance = 1;
        bodies.push_back(space->create_body(d));
    }
    for (int step = 0; step < 60; ++step) space->update();  // settled into the soft contact
    const std::vector<Vec3> settled = positions(*space, bodies);
    std::vector<Quat> turned;
    for (BodyHandle b : bodies) turned.push_back(space->internal_orientation(b));
    double fastest = 0, turn = 0;
    for (int step = 0; step < 600; ++step) {
        space->update();
        fastest = std::max(fastest, max_speed(*space, bodies));
        for (std::size_t i = 0; i < bodies.size(); ++i) {
            fastest = std::max(fastest, space->internal_angular_velocity(bodies[i]).norm());
            turn = std::max(turn, space->internal_orientation(bodies[i]).angularDistance(turned[i]));
        }
    }
    const double moved = max_displacement(*space, bodies, settled);
    std::printf("[ measure  ] at rest, 10 s: moved %.3g m, turned %.3g rad, fastest %.3g (m/s or rad/s)\n", moved, turn,
                fastest);
    EXPECT_LT(moved, 1e-5);
    EXPECT_LT(turn, 1e-5);
    EXPECT_LT(fastest, 1e-4);
}

// A pair takes the larger of its bodies' coefficients (Box3D's mix): a ball of 0.05 on
// ground of 0.2 brakes as 0.2, and so does a ball of 0.2 on ground of 0.05; not as 0.05 nor
// as their mean (0.125).
TEST(RollingResistance, APairMixesTheLargerCoefficient) {
    constexpr double kR = 0.5;
    for (const auto& [ball_c, ground_c] : {std::pair{0.05, 0.2}, std::pair{0.2, 0.05}}) {
        auto space = make_space();
        add_ground(*space, ground_c);
        const BodyDesc d = rolling(Shape::sphere(kR), kR, ball_c);
        const double a = braking(d, 0.2, kR);
        const BodyHandle ball = space->create_body(d);
        const Roll r = roll(*space, ball, static_cast<int>(0.8 * kSpeed / a / kStep) + 1);
        const double measured = deceleration(r, 0.1 * kSpeed / a, 0.7 * kSpeed / a);
        std::printf("[ measure  ] ball %.2f on ground %.2f: deceleration %.4f m/s^2 (0.2's %.4f)\n", ball_c, ground_c,
                    measured, a);
        EXPECT_NEAR(measured, a, 0.03 * a) << "ball " << ball_c << ", ground " << ground_c;
    }
}

// A compound's manifolds brake with their parts' radii (a compound body has no radius of its
// own): a compound of one ball part slows as the ball does.
TEST(RollingResistance, ACompoundsPartBrakesWithItsOwnRadius) {
    constexpr double kC = 0.1, kR = 0.5;
    auto space = make_space();
    add_ground(*space);
    const CompoundPart part{Shape::sphere(kR), Vec3::Zero(), Quat::Identity()};
    const BodyDesc d = rolling(Shape::compound(std::span(&part, 1)), kR, kC);
    const double a = braking(d, kC, kR);
    const BodyHandle body = space->create_body(d);
    const Roll r = roll(*space, body, static_cast<int>(0.8 * kSpeed / a / kStep) + 1);
    const double measured = deceleration(r, 0.1 * kSpeed / a, 0.7 * kSpeed / a);
    std::printf("[ measure  ] compound ball c %.2f: deceleration %.4f m/s^2 (analytic %.4f)\n", kC, measured, a);
    EXPECT_NEAR(measured, a, 0.03 * a);
}

// Set after creation (Space::set_rolling_resistance), it brakes from the next step on: the
// ball rolls freely for half a second, then slows at its cap.
TEST(RollingResistance, SetAfterCreationBrakesFromTheNextUpdate) {
    constexpr double kC = 0.1, kR = 0.5;
    auto space = make_space();
    add_ground(*space);
    const BodyHandle ball = space->create_body(rolling(Shape::sphere(kR), kR, 0));
    const Roll before = roll(*space, ball, 30);
    EXPECT_GT(before.speed.back(), 0.99 * kSpeed);
    space->set_rolling_resistance(ball, kC);
    EXPECT_EQ(space->internal_desc(ball).rolling_resistance, 0) << "buffered: nothing changes before the update";
    BodyDesc d = rolling(Shape::sphere(kR), kR, kC);
    const double a = braking(d, kC, kR);
    const Roll after = roll(*space, ball, 90);
    EXPECT_EQ(space->internal_desc(ball).rolling_resistance, kC);
    const double measured = deceleration(after, 0.25, 1.25);
    std::printf("[ measure  ] set after creation: deceleration %.4f m/s^2 (analytic %.4f)\n", measured, a);
    EXPECT_NEAR(measured, a, 0.03 * a);
}

// On a slope the row holds a ball whose coefficient is at least the slope's tangent (the
// friction force m g sin(t) at the contact needs a torque m g sin(t) R, at most c R m g cos(t)):
// a ball of 0.1 rests on a slope of 0.05 without creeping; on a slope of 0.2 it rolls down at
// 5/7 g (sin(t) - c cos(t)).
TEST(RollingResistance, BallHeldOnASlopeGentlerThanItsCoefficient_RollsDownASteeperOne) {
    constexpr double kC = 0.1, kR = 0.5;
    for (const double slope : {0.05, 0.2}) {
        auto space = make_space();
        const double angle = std::atan(slope);
        const Quat tilt(Eigen::AngleAxisd(angle, Vec3::UnitZ()));  // downhill is -x
        add_static_box(*space, Vec3(20, 0.5, 3), Vec3::Zero(), tilt, 0.9);
        BodyDesc d;
        d.shape = Shape::sphere(kR);
        d.position = tilt * Vec3(0, 0.5 + kR, 0);
        d.friction = 0.9;
        d.rolling_resistance = kC;
        const BodyHandle ball = space->create_body(d);
        const Vec3 downhill = tilt * -Vec3::UnitX();
        for (int step = 0; step < 30; ++step) space->update();  // settled into the soft contact
        const Vec3 start = space->internal_position(ball);
        for (int step = 0; step < 120; ++step) space->update();
        const double moved = (space->internal_position(ball) - start).dot(downhill);
        const double speed = space->internal_linear_velocity(ball).dot(downhill);
        const double a = 5.0 / 7.0 * kGravity * (std::sin(angle) - kC * std::cos(angle));
        std::printf("[ measure  ] slope %.2f, c %.2f: moved %.3g m over the last 2 s, speed %.4f m/s at 2.5 s (%s)\n",
                    slope, kC, moved, speed, a > 0 ? "rolls" : "held");
        if (a <= 0) {
            EXPECT_LT(std::abs(moved), 1e-3) << "slope " << slope;
            EXPECT_LT(std::abs(speed), 1e-3) << "slope " << slope;
        } else {
            // Rolling from rest at creation: speed a t after the 150 steps.
            EXPECT_NEAR(speed, a * (150 * kStep), 0.05 * a * (150 * kStep)) << "slope " << slope;
        }
    }
}
