// Joint behaviour: hinge limits and motors, welds, distance limits, collision between
// jointed bodies, work counters, islands and sleeping.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "joint_scenes.hpp"
#include "static_bodies.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

// A 1 m bar along +x from a hinge at the origin about z, under gravity.
struct HingedBar {
    BodyHandle anchor, bar;
    JointHandle joint;
};

HingedBar make_hinged_bar(Space& space, const HingeParams& params) {
    HingedBar h;
    h.anchor = add_static(space, Vec3::Zero());
    h.bar = add_box(space, Vec3(0.5, 0, 0), Vec3(0.5, 0.05, 0.05), 1);
    JointDesc d = JointDesc::hinge_at(h.anchor, h.bar, Vec3::Zero(), Vec3::UnitZ());
    d.hinge = params;
    h.joint = space.create_joint(d);
    return h;
}

}  // namespace

TEST(Hinge, LimitHoldsTheAngleWithinItsRange) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    HingeParams params;
    params.enable_limit = true;
    params.lower_angle = -0.5;
    params.upper_angle = 0.25;
    const HingedBar h = make_hinged_bar(space, params);
    // Falls clockwise onto the lower limit, then is thrown up against the upper one.
    double lowest = 0, highest = 0;
    for (int i = 0; i < 240; ++i) {
        if (i == 120) space.set_angular_velocity(h.bar, Vec3(0, 0, 30));
        space.update();
        const double angle = space.internal_hinge_angle(h.joint);
        lowest = std::min(lowest, angle);
        highest = std::max(highest, angle);
        if (i == 119) {
            EXPECT_NEAR(angle, -0.5, 0.01);  // resting on the lower limit
        }
    }
    std::printf("hinge limit [-0.5, 0.25]: angles reached [%.4f, %.4f] rad\n", lowest, highest);
    EXPECT_GT(lowest, -0.5 - 0.02);
    EXPECT_LT(highest, 0.25 + 0.02);
    EXPECT_GT(highest, 0.2);  // it did reach the upper limit
    EXPECT_LT(space.internal_joint_error(h.joint).linear, 1e-3);
    EXPECT_LT(space.internal_joint_error(h.joint).angular, 1e-3);
}

// The bar falls from level onto a lower limit of -0.5 rad. A soft limit (4 Hz, damping
// ratio 0.5) lets it overshoot far more than the rigid one, then settles on the limit,
// sagging under the bar's weight as a spring of k = I w^2 for the inertia the limit row
// turns (the bar's about its centre, 0.0842 kg m^2): m g (L/2) cos(angle) / k = 0.077 rad.
TEST(Hinge, SoftLimitOvershootsMoreThanARigidOneAndSettlesOnTheLimit) {
    double overshoot[2] = {}, rest[2] = {};
    for (const int soft : {0, 1}) {
        Space space;
        space.set_sleep(SleepSettings{.enabled = false});
        HingeParams params;
        params.enable_limit = true;
        params.lower_angle = -0.5;
        params.upper_angle = 0.5;
        params.limit_spring_hertz = soft ? 4 : 0;
        params.limit_damping_ratio = soft ? 0.5 : 0;
        const HingedBar h = make_hinged_bar(space, params);
        double lowest = 0;
        for (int i = 0; i < 300; ++i) {
            space.update();
            lowest = std::min(lowest, space.internal_hinge_angle(h.joint));
        }
        overshoot[soft] = -0.5 - lowest;
        rest[soft] = space.internal_hinge_angle(h.joint);
        std::printf("hinge limit -0.5 rad, %s: overshoot %.5f rad, rests at %.5f rad\n", soft ? "soft 4 Hz" : "rigid",
                    overshoot[soft], rest[soft]);
    }
    const double inertia = 1.0 * (1.0 + 0.01) / 12, k = inertia * std::pow(2 * kPi * 4, 2);
    const double sag = 1 * 9.81 * 0.5 * std::cos(rest[1]) / k;
    EXPECT_LT(overshoot[0], 0.01);
    EXPECT_GT(overshoot[1], 5 * overshoot[0] + 0.05);
    EXPECT_NEAR(rest[0], -0.5, 0.005);
    EXPECT_NEAR(rest[1], -0.5 - sag, 0.02 * sag);
}

TEST(Hinge, MotorReachesTargetSpeedAndRespectsItsTorque) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle anchor = add_static(space, Vec3::Zero());
    // A wheel (1 x 1 x 0.2 m, 6 kg: I about z = 1 kg m^2) turning about its own centre.
    const BodyHandle wheel = add_box(space, Vec3::Zero(), Vec3(0.5, 0.5, 0.1), 6);
    JointDesc d = JointDesc::hinge_at(anchor, wheel, Vec3::Zero(), Vec3::UnitZ());
    d.hinge.enable_motor = true;
    d.hinge.motor_speed = 3;
    d.hinge.max_motor_torque = 2;
    const JointHandle joint = space.create_joint(d);
    // Torque-limited at first: w = tau t / I.
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_NEAR(space.internal_angular_velocity(wheel).z(), 2 * 0.5 / 1.0, 0.01);
    for (int i = 0; i < 90; ++i) space.update();
    const double speed = space.internal_angular_velocity(wheel).z();
    std::printf("hinge motor: target 3 rad/s, reached %.6f rad/s\n", speed);
    EXPECT_NEAR(speed, 3, 1e-3);
    EXPECT_LT(space.internal_angular_velocity(wheel).head<2>().norm(), 1e-6);  // only about the axis

    space.set_hinge_motor(joint, true, -1, 100);
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_NEAR(space.internal_angular_velocity(wheel).z(), -1, 1e-3);
}

TEST(Fixed, KeepsTheRelativePoseOfASpinningPair) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle a = add_box(space, Vec3::Zero(), Vec3(0.3, 0.2, 0.1), 2);
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.1, 0.4, 0.1));
    d.position = Vec3(0.6, 0.1, 0);
    d.orientation = Quat(Eigen::AngleAxis<Real>(0.7, Vec3(1, 1, 0).normalized()));
    d.mass = 1;
    const BodyHandle b = space.create_body(d);
    const JointHandle joint = space.create_joint(JointDesc::fixed_at(a, b, Vec3(0.4, 0.1, 0)));
    space.set_angular_velocity(a, Vec3(1, 2, 3));
    space.set_linear_velocity(a, Vec3(0.5, 0, 0));
    const Quat relative0 = d.orientation;  // a starts at identity
    JointError worst;
    for (int i = 0; i < 300; ++i) {
        space.update();
        const JointError e = space.internal_joint_error(joint);
        worst.linear = std::max(worst.linear, e.linear);
        worst.angular = std::max(worst.angular, e.angular);
    }
    const Quat relative = space.internal_orientation(a).conjugate() * space.internal_orientation(b);
    std::printf("fixed joint, spinning: worst error %.2e m, %.2e rad\n", worst.linear, worst.angular);
    EXPECT_LT(worst.linear, 2e-3);
    EXPECT_LT(worst.angular, 5e-3);
    EXPECT_LT(relative.angularDistance(relative0), 5e-3);
    EXPECT_GT(space.internal_angular_velocity(b).norm(), 1);  // b turns with a
}

TEST(Fixed, CantileverBarelySags) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle wall = add_static(space, Vec3::Zero());
    const BodyHandle beam = add_box(space, Vec3(0.5, 0, 0), Vec3(0.5, 0.05, 0.05), 1);
    const JointHandle joint = space.create_joint(JointDesc::fixed_at(wall, beam, Vec3::Zero()));
    for (int i = 0; i < 120; ++i) space.update();
    const JointError e = space.internal_joint_error(joint);
    std::printf("fixed joint cantilever: sag %.2e m at the weld, %.2e rad\n", e.linear, e.angular);
    EXPECT_LT(e.angular, 0.01);
    EXPECT_LT(e.linear, 1e-3);
}

TEST(Distance, RigidRodKeepsItsLength) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle anchor = add_static(space, Vec3(0, 3, 0));
    const BodyHandle bob = add_sphere(space, Vec3(1.5, 3, 0), 0.1, 1);
    const JointHandle joint =
        space.create_joint(JointDesc::distance_between(anchor, bob, Vec3(0, 3, 0), Vec3(1.5, 3, 0)));
    double worst = 0;
    for (int i = 0; i < 300; ++i) {
        space.update();
        worst = std::max(worst, space.internal_joint_error(joint).linear);
    }
    EXPECT_NEAR((space.internal_position(bob) - Vec3(0, 3, 0)).norm(), 1.5, 2e-3);
    EXPECT_LT(worst, 5e-3);
}

TEST(Distance, RopeCatchesAtMaxLength) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle anchor = add_static(space, Vec3(0, 3, 0));
    const BodyHandle bob = add_sphere(space, Vec3(0.2, 2.8, 0), 0.1, 1);
    JointDesc d = JointDesc::distance_between(anchor, bob, Vec3(0, 3, 0), Vec3(0.2, 2.8, 0));
    d.distance.enable_spring = true;  // no spring force: free between the limits
    d.distance.enable_limit = true;
    d.distance.max_length = 1;
    space.create_joint(d);
    double longest = 0;
    for (int i = 0; i < 240; ++i) {
        space.update();
        longest = std::max(longest, (space.internal_position(bob) - Vec3(0, 3, 0)).norm());
    }
    std::printf("rope, max 1 m: longest %.4f m\n", longest);
    EXPECT_LT(longest, 1.01);
    EXPECT_GT(longest, 0.99);  // it fell until the rope caught it
}

TEST(Distance, MinLengthKeepsBodiesApart) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle a = add_sphere(space, Vec3(-1, 0, 0), 0.1, 1);
    const BodyHandle b = add_sphere(space, Vec3(1, 0, 0), 0.1, 1);
    JointDesc d = JointDesc::distance_between(a, b, Vec3(-1, 0, 0), Vec3(1, 0, 0));
    d.distance.enable_spring = true;
    d.distance.enable_limit = true;
    d.distance.min_length = 0.5;
    space.create_joint(d);
    space.set_linear_velocity(a, Vec3(2, 0, 0));
    space.set_linear_velocity(b, Vec3(-2, 0, 0));
    double shortest = 2;
    for (int i = 0; i < 120; ++i) {
        space.update();
        shortest = std::min(shortest, (space.internal_position(b) - space.internal_position(a)).norm());
    }
    EXPECT_GT(shortest, 0.49);
    EXPECT_LT(shortest, 0.52);
}

TEST(Collision, JointedBodiesDoNotCollideUnlessAsked) {
    for (bool collide : {false, true}) {
        Space space;
        space.set_gravity(Vec3::Zero());
        const BodyHandle a = add_sphere(space, Vec3(0, 0, 0), 0.5, 1);
        const BodyHandle b = add_sphere(space, Vec3(0.6, 0, 0), 0.5, 1);  // overlapping
        JointDesc d = JointDesc::ball_socket_at(a, b, Vec3(0.3, 0, 0));
        d.collide_connected = collide;
        space.create_joint(d);
        space.update();
        EXPECT_EQ(space.last_update().contacts, collide ? 1u : 0u) << "collide_connected " << collide;
    }
}

TEST(Collision, CreatingAJointDropsTheContactAndDestroyingItRestoresIt) {
    Space space;
    space.set_gravity(Vec3::Zero());
    const BodyHandle a = add_sphere(space, Vec3(0, 0, 0), 0.5, 1);
    const BodyHandle b = add_sphere(space, Vec3(0.99, 0, 0), 0.5, 1);
    space.update();
    ASSERT_EQ(space.last_update().contacts, 1u);
    const JointHandle joint = space.create_joint(JointDesc::ball_socket_at(a, b, Vec3(0.5, 0, 0)));
    space.update();
    EXPECT_EQ(space.last_update().contacts, 0u);
    space.destroy_joint(joint);
    space.update();
    EXPECT_EQ(space.last_update().contacts, 1u);
}

TEST(Counters, ASceneWithoutJointsSolvesNone) {
    Space space;
    test::add_ground_plane(space);
    for (int i = 0; i < 4; ++i) add_sphere(space, Vec3(1.2 * i, 0.5, 0), 0.5, 1);
    for (int i = 0; i < 60; ++i) space.update();
    EXPECT_GT(space.counters().contact_points_solved, 0u);
    EXPECT_EQ(space.counters().joints_solved, 0u);
}

TEST(Counters, JointsSolvedCountsJointIterations) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const Chain chain = make_chain(space, Vec3(0, 5, 0), Vec3::UnitX(), 3, 0.5, 1);
    for (int i = 0; i < 10; ++i) space.update();
    const SolverSettings& s = space.settings().solver;
    EXPECT_EQ(space.counters().joints_solved,
              3u * 10u * static_cast<unsigned>(s.substeps * (s.iterations + s.relax_iterations)));
}

TEST(Sleeping, AHangingChainSleepsAsOneIslandAndWakesTogether) {
    Space space;
    const Chain chain = make_chain(space, Vec3(0, 5, 0), -Vec3::UnitY(), 4, 0.5, 1);
    for (int i = 0; i < 120; ++i) space.update();
    for (BodyHandle link : chain.links) ASSERT_FALSE(space.internal_is_awake(link));
    const std::uint64_t solved = space.counters().joints_solved;
    const std::uint64_t integrated = space.counters().bodies_integrated;
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_EQ(space.counters().joints_solved, solved);  // a sleeping island's joints cost nothing
    EXPECT_EQ(space.counters().bodies_integrated, integrated);

    space.set_linear_velocity(chain.links.back(), Vec3(1, 0, 0));
    space.update();
    for (BodyHandle link : chain.links) EXPECT_TRUE(space.internal_is_awake(link));  // through the joints
    EXPECT_GT(space.counters().joints_solved, solved);
}

TEST(Sleeping, AMovingBodyWakesASleeperJointedToIt) {
    Space space;
    const BodyHandle top = add_static(space, Vec3(0, 5, 0));
    BodyDesc k;
    k.type = MotionType::Kinematic;
    k.shape = Shape::sphere(0.1);
    k.position = Vec3(0, 4, 0);
    const BodyHandle carrier = space.create_body(k);
    (void)top;
    const BodyHandle bob = add_sphere(space, Vec3(0, 3, 0), 0.1, 1);
    space.create_joint(JointDesc::ball_socket_at(carrier, bob, Vec3(0, 4, 0)));
    for (int i = 0; i < 120; ++i) space.update();
    ASSERT_FALSE(space.internal_is_awake(bob));
    space.set_linear_velocity(carrier, Vec3(1, 0, 0));  // wakes the carrier only
    space.update();
    space.update();
    EXPECT_TRUE(space.internal_is_awake(bob));
    for (int i = 0; i < 60; ++i) space.update();
    EXPECT_GT(space.internal_position(bob).x(), 0.5);  // dragged along
}

TEST(Sleeping, CreatingAJointWakesBothBodies) {
    Space space;
    const BodyHandle a = add_static(space, Vec3(0, 5, 0));
    test::add_ground_plane(space);
    const BodyHandle ball = add_sphere(space, Vec3(0, 0.5, 0), 0.5, 1);
    for (int i = 0; i < 90; ++i) space.update();
    ASSERT_FALSE(space.internal_is_awake(ball));
    space.create_joint(JointDesc::distance_between(a, ball, Vec3(0, 5, 0), Vec3(0, 0.5, 0)));
    EXPECT_TRUE(space.internal_is_awake(ball));
}

// The solver keeps a step's colours while its constraints stay the same (here: no
// manifolds, the same joints); a joint made or destroyed between steps must still be
// solved from the next step on, or no longer.
TEST(JointColours, AJointMadeOrDestroyedBetweenStepsActsFromTheNextStep) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle anchor = add_static(space, Vec3::Zero());
    const BodyHandle hanging = add_sphere(space, Vec3(0, -1, 0), 0.2, 1);
    const JointHandle held = space.create_joint(JointDesc::ball_socket_at(anchor, hanging, Vec3::Zero()));
    const BodyHandle falling = add_sphere(space, Vec3(3, -1, 0), 0.2, 1);
    for (int i = 0; i < 10; ++i) space.update();
    const Vec3 caught_at = space.internal_position(falling);
    space.create_joint(JointDesc::ball_socket_at(anchor, falling, caught_at));  // a rod to the first anchor
    space.destroy_joint(held);
    for (int i = 0; i < 60; ++i) space.update();
    // The caught sphere stays at the rod's end (it swings about the anchor, never away).
    EXPECT_NEAR((space.internal_position(falling) - Vec3::Zero()).norm(), caught_at.norm(), 0.02);
    EXPECT_LT(space.internal_position(hanging).y(), -4.0) << "the released sphere falls";
}
