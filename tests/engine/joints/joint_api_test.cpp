// Joint API: validation errors that name the field and change nothing, stale handles,
// and joints destroyed with their bodies.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>

#include "joint_scenes.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

std::string rejection(Space& space, const JointDesc& d) {
    try {
        space.create_joint(d);
    } catch (const Error& e) {
        return e.what();
    }
    return "(accepted)";
}

}  // namespace

TEST(JointValidation, BadJointsAreRejectedNamingTheFieldAndChangeNothing) {
    Space space;
    const BodyHandle ground = add_static(space, Vec3::Zero());
    const BodyHandle wall = add_static(space, Vec3(5, 0, 0));
    const BodyHandle a = add_sphere(space, Vec3(1, 0, 0), 0.1, 1);
    const BodyHandle b = add_sphere(space, Vec3(2, 0, 0), 0.1, 1);
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    const std::size_t bodies = space.body_count();

    auto expect = [&](const JointDesc& d, const std::string& part) {
        const std::string message = rejection(space, d);
        EXPECT_NE(message.find(part), std::string::npos) << "message: " << message;
        EXPECT_EQ(message.rfind("create_joint: ", 0), 0u) << "message: " << message;
    };
    expect(JointDesc::ball_socket_at(a, a, Vec3::Zero()), "body_a and body_b must be different bodies");
    expect(JointDesc::ball_socket_at(ground, wall, Vec3::Zero()), "at least one of body_a and body_b must be dynamic");
    expect(JointDesc::ball_socket_at(BodyHandle{99, 1}, a, Vec3::Zero()),
           "body_a: body 99 (generation 1) is not a live body");
    expect(JointDesc::ball_socket_at(a, BodyHandle{}, Vec3::Zero()), "body_b:");
    expect(JointDesc::ball_socket_at(a, b, Vec3(nan, 0, 0)), "anchors.a must be finite");
    JointDesc local = JointDesc::ball_socket_at(a, b, Vec3::Zero());
    local.anchors = JointAnchors::local(Vec3::Zero(), Vec3(0, std::numeric_limits<Real>::infinity(), 0));
    expect(local, "anchors.b must be finite");
    expect(JointDesc::hinge_at(a, b, Vec3::Zero(), Vec3::Zero()), "hinge.axis_a must be a finite, non-zero vector");
    JointDesc hinge = JointDesc::hinge_at(a, b, Vec3::Zero(), Vec3::UnitZ());
    hinge.hinge.enable_limit = true;
    hinge.hinge.lower_angle = 0.5;
    hinge.hinge.upper_angle = 0.2;
    expect(hinge, "hinge.lower_angle (0.5) must be <= hinge.upper_angle (0.2)");
    hinge.hinge.lower_angle = -4;
    expect(hinge, "hinge.lower_angle must be in [-pi, pi], got -4");
    hinge.hinge.enable_limit = false;
    hinge.hinge.max_motor_torque = -1;
    expect(hinge, "hinge.max_motor_torque must be finite and >= 0, got -1");
    JointDesc distance = JointDesc::distance_between(a, b, Vec3(1, 0, 0), Vec3(2, 0, 0));
    distance.distance.min_length = 2;
    distance.distance.max_length = 1;
    expect(distance, "distance.min_length (2) must be <= distance.max_length (1)");
    distance.distance.min_length = -1;
    expect(distance, "distance.min_length must be finite and >= 0, got -1");
    distance.distance.min_length = 0;
    distance.distance.spring_hertz = nan;
    expect(distance, "distance.spring_hertz");

    EXPECT_EQ(space.joint_count(), 0u);
    EXPECT_EQ(space.body_count(), bodies);
    // The rejected ones left no trace: a good joint still takes the first slot.
    const JointHandle good = space.create_joint(JointDesc::ball_socket_at(a, b, Vec3(1.5, 0, 0)));
    EXPECT_EQ(good.index, 0u);
    EXPECT_EQ(space.joint_count(), 1u);
}

TEST(JointValidation, SolverRejectsNegativeJointSoftness) {
    Space space;
    SolverSettings s;
    s.joint_hertz = -1;
    EXPECT_THROW(space.set_solver(s), Error);
    s.joint_hertz = 0;  // the stiffest stable
    EXPECT_NO_THROW(space.set_solver(s));
}

TEST(JointHandles, StaleHandlesAreDetectedNotAliased) {
    Space space;
    const BodyHandle ground = add_static(space, Vec3::Zero());
    const BodyHandle a = add_sphere(space, Vec3(1, 0, 0), 0.1, 1);
    const JointHandle first = space.create_joint(JointDesc::ball_socket_at(ground, a, Vec3::Zero()));
    EXPECT_TRUE(space.contains(first));
    space.destroy_joint(first);
    EXPECT_FALSE(space.contains(first));
    EXPECT_THROW(space.destroy_joint(first), Error);
    // The slot is reused with a new generation: the old handle still names nothing.
    const JointHandle second = space.create_joint(JointDesc::distance_between(ground, a, Vec3::Zero(), Vec3(1, 0, 0)));
    EXPECT_EQ(second.index, first.index);
    EXPECT_NE(second.generation, first.generation);
    EXPECT_FALSE(space.contains(first));
    try {
        space.internal_joint_error(first);
        ADD_FAILURE() << "a stale handle was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("is not a live joint"), std::string::npos) << e.what();
    }
    EXPECT_THROW(space.joint_desc(first), Error);
    EXPECT_THROW(space.destroy_joint(JointHandle{}), Error);
    EXPECT_EQ(space.joint_desc(second).type, JointType::Distance);
    EXPECT_THROW(space.internal_hinge_angle(second), Error);  // not a hinge
}

TEST(JointHandles, DestroyingABodyDestroysItsJoints) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const Chain chain = make_chain(space, Vec3(0, 5, 0), -Vec3::UnitY(), 3, 0.5, 1);
    ASSERT_EQ(space.joint_count(), 3u);
    space.destroy_body(chain.links[1]);  // joints 1 (links 0-1) and 2 (links 1-2)
    EXPECT_EQ(space.joint_count(), 1u);
    EXPECT_TRUE(space.contains(chain.joints[0]));
    EXPECT_FALSE(space.contains(chain.joints[1]));
    EXPECT_FALSE(space.contains(chain.joints[2]));
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_LT(space.internal_position(chain.links[2]).y(), 3.5);  // the cut end falls
    EXPECT_LT(space.internal_joint_error(chain.joints[0]).linear, 1e-3);
}

TEST(JointHandles, LocalAnchorsMatchWorldAnchors) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const BodyHandle ground = add_static(space, Vec3(0, 2, 0));
    const BodyHandle a = add_sphere(space, Vec3(1, 2, 0), 0.1, 1);
    const BodyHandle b = add_sphere(space, Vec3(1, 2, 3), 0.1, 1);
    space.create_joint(JointDesc::ball_socket_at(ground, a, Vec3(0, 2, 0)));
    // The same pendulum 3 m along z, its pivot given in each body's own frame.
    JointDesc local;
    local.body_a = ground;
    local.body_b = b;
    local.anchors = JointAnchors::local(Vec3(0, 0, 3), Vec3(-1, 0, 0));
    space.create_joint(local);
    double lowest = 2;
    for (int i = 0; i < 60; ++i) {
        space.update();
        lowest = std::min(lowest, space.internal_position(a).y());
    }
    EXPECT_LT((space.internal_position(b) - space.internal_position(a) - Vec3(0, 0, 3)).norm(), 1e-9);
    EXPECT_LT(lowest, 1.05);  // it did swing through the bottom
}
