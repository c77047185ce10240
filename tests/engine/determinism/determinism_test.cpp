// Same scene + same settings => bitwise identical states for 1, 2, 3 and 4 workers,
// and from run to run (design.md section 5).
#include <spindle/engine/space.hpp>
#include <spindle/scene/scene.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <memory>
#include <vector>

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

// A static floor box, its top at y = 0, half_width to each side.
void add_floor(Space& space, Real half_width) {
    BodyDesc floor;
    floor.type = MotionType::Static;
    floor.shape = Shape::box(Vec3(half_width, 1, half_width));
    floor.position = Vec3(0, -1, 0);
    space.create_body(floor);
}

// Boxes, spheres, capsules and hulls falling into a pile, a resting row that falls
// asleep, on a static floor box.
std::uint64_t run_mixed_scene(JobSystem& jobs) {
    Space space(SpaceSettings{}, &jobs);
    add_floor(space, 20);
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

// Light boxes carrying heavier ones (support mass scaling, support_scales.cpp): columns
// of rising masses, planks across light cubes, and heavy boxes dropped on light ones,
// some onto the columns and some in the air.
std::uint64_t run_heavy_on_light_scene(JobSystem& jobs) {
    Space space(SpaceSettings{}, &jobs);
    add_floor(space, 30);
    auto box = [&](const Vec3& half, const Vec3& position, double mass, const Vec3& velocity = Vec3::Zero()) {
        BodyDesc d;
        d.shape = Shape::box(half);
        d.position = position;
        d.mass = mass;
        d.linear_velocity = velocity;
        d.orientation = Quat(Eigen::AngleAxisd(0.05 * (position.x() - position.z()), Vec3::UnitY()));
        space.create_body(d);
    };
    for (int i = 0; i < 6; ++i) {
        for (int k = 0; k < 6; ++k) {
            const Vec3 base(i * 3.0 - 7.5, 0, k * 3.0 - 7.5);
            const double ratio = 2.0 + 7 * ((i + k) % 4);
            for (int level = 0; level < 3; ++level) {
                box(Vec3::Constant(0.4), base + Vec3(0, 0.4 + 0.8 * level, 0), std::pow(ratio, level));
            }
            box(Vec3::Constant(0.3), base + Vec3(0.1, 4 + 0.5 * ((i * 6 + k) % 3), 0), 500);  // dropped on it
        }
    }
    for (int i = 0; i < 4; ++i) {
        const double z = 12 + 2.5 * i;
        box(Vec3::Constant(0.4), Vec3(-3, 0.4, z), 1);
        box(Vec3::Constant(0.4), Vec3(3, 0.4, z), 1);
        box(Vec3(4, 0.2, 0.6), Vec3(0, 1.0, z), 200.0 * (i + 1));
        box(Vec3::Constant(0.4), Vec3(-12, 6 + i, z), 1);                    // in the air,
        box(Vec3::Constant(0.4), Vec3(-12, 7 + i, z), 100, Vec3(0, -4, 0));  // hit from above
    }
    for (int i = 0; i < kSteps; ++i) space.update();
    return space.state_hash();
}

// A block of 6,400 touching spheres on a floor: tens of thousands of contacts made in one step and
// thousands lost in the next, when every other sphere of the top layers is moved away. So
// many that the contact index claims, rehashes and erases in jobs (contact_index.cpp),
// which the TSan build checks here.
std::uint64_t run_contact_churn_scene(JobSystem& jobs) {
    SpaceSettings settings;
    settings.sleep.enabled = false;
    Space space(settings, &jobs);
    add_floor(space, 30);  // the block presses on it: the contacts' order reaches the result
    std::vector<BodyHandle> moved;
    BodyDesc d;
    d.shape = Shape::sphere(0.5);
    for (int y = 0; y < 4; ++y) {
        for (int i = 0; i < 40; ++i) {
            for (int k = 0; k < 40; ++k) {
                d.position = Vec3(i - 20, y + 0.5, k - 20);
                const BodyHandle body = space.create_body(d);
                if (y >= 2 && (i + k) % 2 == 0) moved.push_back(body);
            }
        }
    }
    space.update();
    const std::uint64_t made = space.counters().contacts_updated;  // the contacts of the first step
    for (std::size_t k = 0; k < moved.size(); ++k) space.set_position(moved[k], Vec3(0, 100 + 3.0 * k, 0));
    space.update();
    const std::uint64_t kept = space.counters().contacts_updated - made;
    space.update();
    EXPECT_GT(made, 20000u);  // the index has 65,536 slots or more
    EXPECT_GT(made, kept + 2000);
    return space.state_hash();
}

// A scene's hash on work stealing with each worker count equals the single-threaded one.
void expect_hash_of_single_thread(std::uint64_t (*run)(JobSystem&),
                                  std::initializer_list<unsigned> worker_counts = {1u, 2u, 3u, 4u}) {
    const std::uint64_t reference = [&] {
        SingleThreadedJobSystem single;
        return run(single);
    }();
    for (unsigned workers : worker_counts) {
        auto jobs = jobs_for(workers);
        EXPECT_EQ(run(*jobs), reference) << workers << " workers";
    }
}

}  // namespace

TEST(Determinism, HeavyOnLightSceneHashIsTheSameForOneToFourWorkers) {
    expect_hash_of_single_thread(run_heavy_on_light_scene);
}

TEST(Determinism, LimbSceneHashIsTheSameForOneToFourWorkers) { expect_hash_of_single_thread(run_limb_scene); }

TEST(Determinism, MixedSceneHashIsTheSameForOneToFourWorkers) { expect_hash_of_single_thread(run_mixed_scene); }

TEST(Determinism, RunToRunIsIdentical) {
    auto jobs = jobs_for(2);
    const std::uint64_t first = run_mixed_scene(*jobs);
    EXPECT_EQ(run_mixed_scene(*jobs), first);
}

TEST(Determinism, JointedSceneHashIsTheSameForOneToFourWorkers) {
    expect_hash_of_single_thread(run_jointed_scene, {2u, 3u, 4u});
}

TEST(Determinism, RagdollSceneHashIsTheSameForOneToFourWorkers) { expect_hash_of_single_thread(run_ragdoll_scene); }

TEST(Determinism, ContactsMadeAndLostByTheThousandHashTheSameOnTwoAndFourWorkers) {
    expect_hash_of_single_thread(run_contact_churn_scene, {2u, 4u});
}
