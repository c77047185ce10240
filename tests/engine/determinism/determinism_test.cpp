// Same scene + same settings => bitwise identical states for 1, 2, 3 and 4 workers,
// and from run to run (design.md section 5).
#include <spindle/engine/space.hpp>
#include <spindle/scene/scene.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "work_stealing_jobs.hpp"

using namespace spindle;

namespace {

#ifdef SPINDLE_TSAN
constexpr int kSteps = 60;
#elif !defined(NDEBUG)
constexpr int kSteps = 120;
#else
constexpr int kSteps = 300;
#endif

// Boxes, spheres, capsules and hulls falling into a pile, a resting row that falls
// asleep, on a static floor box.
std::uint64_t run_mixed_scene(JobSystem& jobs) {
    Space space(SpaceSettings{}, &jobs);
    BodyDesc floor;
    floor.type = MotionType::Static;
    floor.shape = Shape::box(Vec3(20, 1, 20));
    floor.position = Vec3(0, -1, 0);
    space.create_body(floor);
    const Vec3 hull_points[] = {{0.5, 0, 0}, {-0.5, 0, 0}, {0, 0.6, 0}, {0, -0.4, 0.3}, {0, 0, -0.5}, {0.2, 0.3, 0.4}};
    const Shape shapes[] = {Shape::box(Vec3(0.4, 0.3, 0.5)), Shape::sphere(0.4), Shape::capsule(0.3, 0.25),
                            Shape::convex_hull(hull_points)};
    int n = 0;
    for (int layer = 0; layer < 4; ++layer) {
        for (int i = 0; i < 6; ++i) {
            for (int k = 0; k < 6; ++k) {
                BodyDesc d;
                d.shape = shapes[n % 4];
                d.position = Vec3(i * 1.1 - 3 + 0.1 * layer, 1 + layer * 1.2, k * 1.1 - 3);
                d.orientation = Quat(Eigen::AngleAxisd(0.3 * n, Vec3(1, 2, 3).normalized()));
                d.linear_velocity = Vec3(0.1 * (n % 5), 0, -0.1 * (n % 3));
                space.create_body(d);
                ++n;
            }
        }
    }
    for (int i = 0; i < 8; ++i) {  // far away, resting: falls asleep
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        d.position = Vec3(15, 0.5, -15 + 1.2 * i);
        space.create_body(d);
    }
    for (int i = 0; i < kSteps; ++i) space.update();
    return space.state_hash();
}

// Chains of bars on ball-socket and fixed joints, a motor-driven hinged wheel, and
// balls on spring ropes falling onto a floor: joints and contacts share the colours.
std::uint64_t run_jointed_scene(JobSystem& jobs) {
    Space space(SpaceSettings{}, &jobs);
    BodyDesc d;
    d.type = MotionType::Static;
    d.shape = Shape::plane(Vec3::UnitY(), 0);
    space.create_body(d);
    d.shape = Shape::sphere(0.1);
    d.position = Vec3(-3, 2, 0);
    const BodyHandle hub = space.create_body(d);
    for (int c = 0; c < 3; ++c) {
        d.type = MotionType::Static;
        d.shape = Shape::sphere(0.05);
        d.position = Vec3(2.0 * c, 3, 0);
        BodyHandle previous = space.create_body(d);
        d.type = MotionType::Dynamic;
        d.shape = Shape::box(Vec3(0.125, 0.02, 0.02));
        for (int i = 0; i < 12; ++i) {
            const Vec3 pivot(2.0 * c + 0.25 * i, 3, 0);
            d.position = pivot + Vec3(0.125, 0, 0);
            const BodyHandle link = space.create_body(d);
            space.create_joint(i % 3 == 2 ? JointDesc::fixed_at(previous, link, pivot)
                                          : JointDesc::ball_socket_at(previous, link, pivot));
            previous = link;
        }
    }
    d.shape = Shape::box(Vec3(0.5, 0.5, 0.1));
    d.position = Vec3(-3, 2, 0);
    JointDesc motor = JointDesc::hinge_at(hub, space.create_body(d), Vec3(-3, 2, 0), Vec3::UnitZ());
    motor.hinge.enable_motor = true;
    motor.hinge.motor_speed = 2;
    motor.hinge.max_motor_torque = 50;
    space.create_joint(motor);
    d.shape = Shape::sphere(0.25);
    for (int i = 0; i < 40; ++i) {
        d.position = Vec3(0.3 * (i % 20) - 1, 0.5 + 1.1 * (i / 20), 0.4);
        const BodyHandle ball = space.create_body(d);
        if (i % 4 != 0) continue;
        JointDesc rope = JointDesc::distance_between(hub, ball, Vec3(-3, 2, 0), d.position);
        rope.distance.enable_spring = true;
        rope.distance.spring_hertz = 2;
        space.create_joint(rope);
    }
    for (int i = 0; i < kSteps; ++i) space.update();
    EXPECT_GT(space.counters().joints_solved, 0u);
    EXPECT_GT(space.counters().contact_points_solved, 0u);
    return space.state_hash();
}

// The joints a ragdoll and a machine need: limbs of capsules on swing-twist joints
// (cones, twist ranges, friction) swinging down onto a floor, and boxes on sliders
// (limits, springs, motors) from the limbs' ends, a motor joint and a mouse joint whose
// target moves every step.
std::uint64_t run_limb_scene(JobSystem& jobs) {
    Space space(SpaceSettings{}, &jobs);
    BodyDesc d;
    d.type = MotionType::Static;
    d.shape = Shape::plane(Vec3::UnitY(), 0);
    const BodyHandle ground = space.create_body(d);
    for (int c = 0; c < 4; ++c) {
        d.type = MotionType::Static;
        d.shape = Shape::sphere(0.05);
        d.position = Vec3(1.5 * c, 2, 0);
        BodyHandle previous = space.create_body(d);
        d.type = MotionType::Dynamic;
        d.shape = Shape::capsule(0.15, 0.08);
        d.orientation = Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));  // capsules lie along x
        for (int i = 0; i < 6; ++i) {
            const Vec3 pivot(1.5 * c + 0.4 * i, 2, 0.1 * c);
            d.position = pivot + Vec3(0.2, 0, 0);
            const BodyHandle link = space.create_body(d);
            JointDesc joint = JointDesc::swing_twist_at(previous, link, pivot, Vec3::UnitX());
            joint.swing_twist.cone_half_angle = 0.3 + 0.1 * i;
            joint.swing_twist.twist_min = -0.2;
            joint.swing_twist.twist_max = 0.1 * c;
            joint.swing_twist.max_friction_torque = 0.05 * (c % 2);
            space.create_joint(joint);
            previous = link;
        }
        d.shape = Shape::box(Vec3(0.1, 0.1, 0.1));
        d.orientation = Quat::Identity();
        d.position = Vec3(1.5 * c + 2.6, 2, 0.1 * c);
        const BodyHandle slider = space.create_body(d);
        JointDesc joint = JointDesc::prismatic_at(previous, slider, d.position, Vec3(1, 1, c).normalized());
        joint.prismatic.enable_limit = true;
        joint.prismatic.lower_translation = -0.3;
        joint.prismatic.upper_translation = 0.2;
        joint.prismatic.enable_spring = c % 2 == 0;
        joint.prismatic.spring_hertz = 3;
        joint.prismatic.spring_damping_ratio = 0.3;
        joint.prismatic.enable_motor = c % 2 == 1;
        joint.prismatic.motor_speed = 1;
        joint.prismatic.max_motor_force = 20;
        space.create_joint(joint);
    }
    d.shape = Shape::box(Vec3(0.3, 0.2, 0.1));
    d.position = Vec3(-2, 1, 0);
    const BodyHandle driven = space.create_body(d);
    d.position = Vec3(-2, 2, 0);
    const BodyHandle dragged = space.create_body(d);
    JointDesc drive = JointDesc::motor_between(driven, dragged, Vec3(-2, 1.5, 0));
    drive.motor.linear_offset = Vec3(0.5, 0.2, 0);
    drive.motor.angular_offset = Quat(Eigen::AngleAxisd(0.7, Vec3::UnitY()));
    drive.motor.max_force = 100;
    drive.motor.max_torque = 20;
    drive.motor.angular_hertz = 4;
    drive.motor.angular_damping_ratio = 0.7;
    space.create_joint(drive);
    const JointHandle mouse = space.create_joint(JointDesc::mouse_at(ground, driven, Vec3(-2, 1.2, 0), 3, 0.8, 200));
    for (int i = 0; i < kSteps; ++i) {
        space.set_mouse_target(mouse, Vec3(-2 + std::sin(0.05 * i), 1.5 + 0.5 * std::cos(0.03 * i), 0));
        space.update();
    }
    EXPECT_GT(space.counters().joints_solved, 0u);
    EXPECT_GT(space.counters().contact_points_solved, 0u);
    return space.state_hash();
}

// Three levels of four ragdolls ([[ragdoll]]: swing-twist joints and limited hinges, a
// collision group each) dropped on a heightfield into piles: joints, limits and contacts
// between ragdolls in one island.
std::uint64_t run_ragdoll_scene(JobSystem& jobs) {
    const SceneDesc scene = parse_scene(R"(
[defaults]
friction = 1
restitution = 0.15
linear_damping = 0.05
angular_damping = 0.05
[[body]]
type = "static"
shape = { heightfield = { size = [12, 12], cells = [12, 12], amplitude = 0.5, wavelength = 8 } }
[[ragdoll]]
position = [-1.5, 1.1, -1.5]
orientation = [0.707107, -0.707107, 0, 0]
copies = { count = [2, 3, 2], step = [3, 0.6, 3] }
)",
                                        "ragdolls.toml");
    Space space(SpaceSettings{}, &jobs);
    build(scene, space);
    for (int i = 0; i < kSteps; ++i) space.update();
    EXPECT_GT(space.counters().joints_solved, 0u);
    EXPECT_GT(space.counters().contact_points_solved, 0u);
    return space.state_hash();
}

}  // namespace

TEST(Determinism, LimbSceneHashIsTheSameForOneToFourWorkers) {
    const std::uint64_t reference = [] {
        SingleThreadedJobSystem single;
        return run_limb_scene(single);
    }();
    for (unsigned workers : {1u, 2u, 3u, 4u}) {
        auto jobs = jobs_for(workers);
        EXPECT_EQ(run_limb_scene(*jobs), reference) << workers << " workers";
    }
}

TEST(Determinism, MixedSceneHashIsTheSameForOneToFourWorkers) {
    const std::uint64_t reference = [] {
        SingleThreadedJobSystem single;
        return run_mixed_scene(single);
    }();
    for (unsigned workers : {1u, 2u, 3u, 4u}) {
        auto jobs = jobs_for(workers);
        EXPECT_EQ(run_mixed_scene(*jobs), reference) << workers << " workers";
    }
}

TEST(Determinism, RunToRunIsIdentical) {
    auto jobs = jobs_for(2);
    const std::uint64_t first = run_mixed_scene(*jobs);
    EXPECT_EQ(run_mixed_scene(*jobs), first);
}

TEST(Determinism, JointedSceneHashIsTheSameForOneToFourWorkers) {
    const std::uint64_t reference = [] {
        SingleThreadedJobSystem single;
        return run_jointed_scene(single);
    }();
    for (unsigned workers : {2u, 3u, 4u}) {
        auto jobs = jobs_for(workers);
        EXPECT_EQ(run_jointed_scene(*jobs), reference) << workers << " workers";
    }
}

TEST(Determinism, RagdollSceneHashIsTheSameForOneToFourWorkers) {
    const std::uint64_t reference = [] {
        SingleThreadedJobSystem single;
        return run_ragdoll_scene(single);
    }();
    for (unsigned workers : {1u, 2u, 3u, 4u}) {
        auto jobs = jobs_for(workers);
        EXPECT_EQ(run_ragdoll_scene(*jobs), reference) << workers << " workers";
    }
}
