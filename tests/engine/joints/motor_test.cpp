// Motor joints: a body driven to a target pose, the force cap, and the mouse joint
// pulling a body to a target the game moves every frame, written while updates run.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <thread>

#include "joint_scenes.hpp"

using namespace spindle;
using namespace spindle::test;

TEST(Motor, BringsABodyToItsTargetPose) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle base = add_box(space, Vec3::Zero(), Vec3(0.5, 0.5, 0.5), 50);
    const BodyHandle body = add_box(space, Vec3(1, 0, 0), Vec3(0.2, 0.1, 0.1), 1);
    JointDesc d = JointDesc::motor_between(base, body, Vec3(1, 0, 0));
    d.motor.max_force = 200;
    d.motor.max_torque = 50;
    const JointHandle joint = space.create_joint(d);
    const Vec3 offset(0.5, 0.3, -0.2);
    const Quat turn(Eigen::AngleAxis<Real>(0.8, Vec3(0, 0, 1)));
    space.set_motor_target(joint, offset, turn);
    space.set_angular_velocity(base, Vec3(0, 0.5, 0));  // the target turns with the base
    for (int i = 0; i < 120; ++i) space.update();
    const Quat qa = space.internal_orientation(base), qb = space.internal_orientation(body);
    const Vec3 target = space.internal_position(base) + qa * (Vec3(1, 0, 0) + offset);
    const Vec3 anchor = space.internal_position(body);  // the anchor is B's centre
    const double turned = (qa * turn).angularDistance(qb);
    const JointError e = space.internal_joint_error(joint);
    std::printf("motor joint: anchor %.2e m from its target, orientation %.2e rad off (error %.2e m, %.2e rad)\n",
                (anchor - target).norm(), turned, e.linear, e.angular);
    EXPECT_LT((anchor - target).norm(), 2e-3);
    EXPECT_LT(turned, 2e-3);
    EXPECT_NEAR(e.linear, (anchor - target).norm(), 1e-9);
    EXPECT_NEAR(e.angular, turned, 1e-6);
}

// A 1 kg body 1 m from its target, pulled with at most 2 N: it gains no more than 2 m/s^2.
TEST(Motor, ForceCapLimitsThePull) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle ground = add_static(space, Vec3::Zero());
    const BodyHandle body = add_sphere(space, Vec3::Zero(), 0.1, 1);
    JointDesc d = JointDesc::motor_between(ground, body, Vec3::Zero());
    d.motor.max_force = 2;
    d.motor.linear_offset = Vec3(1, 0, 0);
    space.create_joint(d);
    for (int i = 0; i < 30; ++i) space.update();
    const double v = space.internal_linear_velocity(body).x();
    std::printf("motor joint capped at 2 N on 1 kg: v %.6f m/s after 0.5 s (cap 1.0)\n", v);
    EXPECT_NEAR(v, 2 * 30 * kDt, 1e-6);
}

// A 1 kg ball dragged at its centre by a mouse joint (5 Hz, critically damped) to a
// target that moves 1.1 m in one second and stops: it follows, then rests below the
// target by its sag under gravity, g / w^2 = 0.0099 m (the spring is k = m w^2 for the
// mass it moves: grabbed off centre, the ball would turn and sag more).
TEST(Mouse, PullsABodyToAMovingTarget) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle ground = add_static(space, Vec3(0, -10, 0));
    const BodyHandle ball = add_sphere(space, Vec3::Zero(), 0.1, 1);
    const JointHandle mouse = space.create_joint(JointDesc::mouse_at(ground, ball, Vec3::Zero(), 5, 1, 1000));
    double worst_lag = 0;
    Vec3 target = Vec3::Zero();
    for (int i = 0; i < 180; ++i) {
        if (i <= 60) target = Vec3(i / 60.0, 0.5 * i / 60.0, 0);
        space.set_mouse_target(mouse, target);
        space.update();
        worst_lag = std::max(worst_lag, (space.internal_position(ball) - target).norm());
    }
    const Vec3 point = space.internal_position(ball);
    const double sag = kG / std::pow(2 * kPi * 5, 2);
    std::printf("mouse joint 5 Hz: worst lag %.4f m while moving, rests %.6f m below the target (g/w^2 %.6f), %.2e "
                "off\n",
                worst_lag, target.y() - point.y(), sag, (point - (target - Vec3(0, sag, 0))).norm());
    EXPECT_LT(worst_lag, 0.15);  // about (speed + sag) / (w / 2) for a critically damped follower
    EXPECT_NEAR(target.y() - point.y(), sag, 0.02 * sag);
    EXPECT_LT((point.head<1>() - target.head<1>()).norm() + std::abs(point.z() - target.z()), 1e-3);
}

// With at most 5 N the mouse cannot hold a 1 kg ball up: it falls at g - 5 m/s^2.
TEST(Mouse, MaxForceLetsAHeavyBodyGo) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle ground = add_static(space, Vec3(0, -10, 0));
    const BodyHandle ball = add_sphere(space, Vec3::Zero(), 0.1, 1);
    const JointHandle mouse = space.create_joint(JointDesc::mouse_at(ground, ball, Vec3::Zero(), 5, 1, 5));
    for (int i = 0; i < 30; ++i) {
        space.set_mouse_target(mouse, Vec3::Zero());
        space.update();
    }
    const double v = space.internal_linear_velocity(ball).y();
    std::printf("mouse joint capped at 5 N under a 9.81 N weight: v %.6f m/s after 0.5 s (analytic %.6f)\n", v,
                -(kG - 5) * 30 * kDt);
    // 1% slower than the cap: the spring takes the first hundredth of a second to stretch to 5 N.
    EXPECT_NEAR(v, -(kG - 5) * 30 * kDt, 0.01 * (kG - 5) * 30 * kDt);
}

TEST(Mouse, BadTargetsAreRejectedNamingTheValueAndChangeNothing) {
    Space space;
    const BodyHandle ground = add_static(space, Vec3(0, -10, 0));
    const BodyHandle ball = add_sphere(space, Vec3::Zero(), 0.1, 1);
    const JointHandle mouse = space.create_joint(JointDesc::mouse_at(ground, ball, Vec3::Zero(), 5, 1, 100));
    const JointHandle hinge = space.create_joint(JointDesc::hinge_at(ground, ball, Vec3(0, -10, 0), Vec3::UnitZ()));
    auto message = [](const auto& call) {
        try {
            call();
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    EXPECT_EQ(message([&] {
                  space.set_mouse_target(mouse, Vec3(nan, 0, 0));
              }).rfind("set_mouse_target: world_target", 0),
              0u);
    EXPECT_NE(message([&] {
                  space.set_motor_target(mouse, Vec3(0, 1e300 * 1e10, 0), Quat::Identity());
              }).find("linear_offset must be finite"),
              std::string::npos);
    EXPECT_NE(message([&] { space.set_motor_target(mouse, Vec3::Zero(), Quat(0, 0, 0, 0)); }).find("angular_offset"),
              std::string::npos);
    EXPECT_NE(message([&] { space.set_mouse_target(hinge, Vec3::Zero()); }).find("is not a live motor joint"),
              std::string::npos);
    space.destroy_joint(mouse);
    EXPECT_NE(message([&] { space.set_mouse_target(mouse, Vec3::Zero()); }).find("is not a live motor joint"),
              std::string::npos);
    // Nothing was written: the next update applies no write.
    space.update();
    EXPECT_EQ(space.last_update().writes_applied, 0);
}

// A target written for a joint destroyed before the next update is dropped and counted.
TEST(Mouse, ATargetForAJointDestroyedSinceIsDropped) {
    Space space;
    const BodyHandle ground = add_static(space, Vec3(0, -10, 0));
    const BodyHandle ball = add_sphere(space, Vec3::Zero(), 0.1, 1);
    const JointHandle mouse = space.create_joint(JointDesc::mouse_at(ground, ball, Vec3::Zero(), 5, 1, 100));
    space.set_mouse_target(mouse, Vec3(1, 0, 0));
    space.set_mouse_target(mouse, Vec3(2, 0, 0));  // the last write wins: one write
    space.destroy_joint(mouse);
    space.update();
    EXPECT_EQ(space.last_update().writes_rejected, 1);
}

// The game thread drags while the physics thread steps: targets written concurrently
// with update() are applied at the next ApplyWrites, the last one winning.
TEST(Mouse, TargetsWrittenFromAnotherThreadWhileUpdatingApply) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle ground = add_static(space, Vec3(0, -10, 0));
    const BodyHandle ball = add_sphere(space, Vec3::Zero(), 0.1, 1);
    const JointHandle mouse = space.create_joint(JointDesc::mouse_at(ground, ball, Vec3::Zero(), 5, 1, 1000));
    std::atomic<bool> done{false};
    std::thread game([&] {
        for (int i = 0; !done.load(); ++i) space.set_mouse_target(mouse, Vec3(0.001 * (i % 100), 0, 0));
    });
    for (int i = 0; i < 120; ++i) space.update();
    done = true;
    game.join();
    space.set_mouse_target(mouse, Vec3(0, 1, 0));
    for (int i = 0; i < 120; ++i) space.update();
    EXPECT_LT((space.internal_position(ball) - Vec3(0, 1, 0)).norm(), 1e-3);
}
