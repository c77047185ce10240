// Joints keep the engine's determinism: the same scene gives bitwise the same states
// on 1 to 4 workers (joints and contacts share the colours of the parallel solver).
#include <spindle/engine/space.hpp>
#include <spindle/platform/topology.hpp>
#include <spindle/scheduler/single_threaded.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <gtest/gtest.h>

#include <memory>

#include "joint_scenes.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

#ifdef SPINDLE_TSAN
constexpr int kSteps = 30;
#else
constexpr int kSteps = 90;
#endif

std::unique_ptr<JobSystem> jobs_for(unsigned workers) {
    if (workers == 1) return std::make_unique<SingleThreadedJobSystem>();
    const Topology machine = Topology::from_system();
    WorkStealingJobSystem::Options options;
    for (unsigned i = 0; i < workers; ++i) options.worker_pus.push_back(machine.pus()[i % machine.pus().size()].os_index);
    options.pin = workers <= machine.pus().size();
    return std::make_unique<WorkStealingJobSystem>(options);
}

// Chains of every joint type beside balls on ropes falling onto a floor, so joints and
// contacts fill the same colours.
std::uint64_t run_jointed_scene(JobSystem& jobs) {
    Space space(SpaceSettings{}, &jobs);
    BodyDesc ground;
    ground.type = MotionType::Static;
    ground.shape = Shape::plane(Vec3::UnitY(), 0);
    space.create_body(ground);
    for (int c = 0; c < 3; ++c) {
        const Chain chain = make_chain(space, Vec3(2.0 * c, 3, 0), Vec3::UnitX(), 12, 0.25, 1, c == 1 ? 20 : 0);
        for (std::size_t i = 0; i + 1 < chain.links.size(); i += 3) {
            const Vec3 anchor(2.0 * c + 0.25 * static_cast<double>(i + 1), 3, 0);
            space.create_joint(JointDesc::fixed_at(chain.links[i], chain.links[i + 1], anchor));
        }
    }
    const BodyHandle hub = add_static(space, Vec3(-3, 2, 0));
    const BodyHandle wheel = add_box(space, Vec3(-3, 2, 0), Vec3(0.5, 0.5, 0.1), 3);
    JointDesc motor = JointDesc::hinge_at(hub, wheel, Vec3(-3, 2, 0), Vec3::UnitZ());
    motor.hinge.enable_motor = true;
    motor.hinge.motor_speed = 2;
    motor.hinge.max_motor_torque = 50;
    space.create_joint(motor);
    for (int i = 0; i < 40; ++i) {
        const Vec3 p(0.3 * (i % 20) - 1, 0.5 + 1.1 * (i / 20), 0.4);
        const BodyHandle ball = add_sphere(space, p, 0.25, 1);
        if (i % 4 != 0) continue;
        JointDesc rope = JointDesc::distance_between(hub, ball, Vec3(-3, 2, 0), p);
        rope.distance.enable_spring = true;
        rope.distance.spring_hertz = 2;
        space.create_joint(rope);
    }
    for (int i = 0; i < kSteps; ++i) space.update();
    EXPECT_GT(space.counters().joints_solved, 0u);
    EXPECT_GT(space.counters().contact_points_solved, 0u);
    return space.state_hash();
}

}  // namespace

TEST(JointDeterminism, JointedSceneHashIsTheSameForOneToFourWorkers) {
    const std::uint64_t reference = [] {
        SingleThreadedJobSystem single;
        return run_jointed_scene(single);
    }();
    for (unsigned workers : {1u, 2u, 3u, 4u}) {
        auto jobs = jobs_for(workers);
        EXPECT_EQ(run_jointed_scene(*jobs), reference) << workers << " workers";
    }
}
