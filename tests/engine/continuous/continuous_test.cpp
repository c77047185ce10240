// Continuous collision: a fast-spinning bar flagged `fast` does not sweep through a
// thin static wall (speculative contacts see only the linear closing speed, so
// without the swept test it does), and bodies not flagged pay nothing for it: a scene
// without fast bodies has no Continuous stage at all.
#include <spindle/engine/space.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

using namespace spindle;

namespace {

struct BarRun {
    double max_tip_x = -1e9;
    std::uint64_t swept_tests = 0;
};

// A 4 m bar spinning at 60 rad/s about its centre 1 m from a 4 cm wall: within one
// step its tip turns from x = 0.07 to x = 1.0, through the wall at x = 0.48..0.52.
// Added to `space` (gravity turned off) after whatever it holds; returns the bar.
BodyHandle add_bar_and_wall(Space& space, bool fast) {
    space.set_gravity(Vec3::Zero());
    BodyDesc wall;
    wall.type = MotionType::Static;
    wall.shape = Shape::box(Vec3(0.02, 5, 5));
    wall.position = Vec3(0.5, 0, 0);
    space.create_body(wall);
    BodyDesc bar;
    bar.shape = Shape::box(Vec3(2, 0.05, 0.05));
    bar.position = Vec3(-1, 0, 0);
    bar.orientation = Quat(Eigen::AngleAxisd(2.0, Vec3::UnitZ()));
    bar.angular_velocity = Vec3(0, 0, -60);
    bar.fast = fast;
    return space.create_body(bar);
}

// 30 steps of the bar: how far its tips reached, and the sweeps paid for.
BarRun spin(Space& space, BodyHandle bar) {
    BarRun run;
    for (int i = 0; i < 30; ++i) {
        space.update();
        const MotionState s = space.internal_motion_state(bar);
        for (double end : {2.0, -2.0})
            run.max_tip_x = std::max(run.max_tip_x, (s.position + s.orientation * Vec3(end, 0, 0)).x());
    }
    run.swept_tests = space.counters().swept_tests;
    return run;
}

BarRun spin_bar_at_wall(bool fast) {
    Space space;
    return spin(space, add_bar_and_wall(space, fast));
}

// A ball far from everything, out of the bar's way.
BodyHandle add_ball(Space& space, const Vec3& position, bool fast) {
    BodyDesc d;
    d.shape = Shape::sphere(0.5);
    d.position = position;
    d.fast = fast;
    return space.create_body(d);
}

// Stages named "Continuous" in a job system's trace.
long continuous_stages(const WorkStealingJobSystem& jobs) {
    const std::vector<TraceEvent> events = jobs.trace_events();
    return std::count_if(events.begin(), events.end(),
                         [](const TraceEvent& e) { return std::strcmp(e.name, "Continuous") == 0; });
}

}  // namespace

TEST(Continuous, FastSpinningBarStopsAtAThinWall) {
    const BarRun run = spin_bar_at_wall(true);
    EXPECT_LT(run.max_tip_x, 0.48 + 0.01);  // the wall's near face, plus a little soft penetration
    EXPECT_GT(run.swept_tests, 0u);
}

TEST(Continuous, WithoutTheFlagTheBarSweepsThroughAndNoSweepIsPaidFor) {
    const BarRun run = spin_bar_at_wall(false);
    EXPECT_GT(run.max_tip_x, 0.52);  // the case the swept test exists for
    EXPECT_EQ(run.swept_tests, 0u);
}

// The stage runs only while fast bodies live (World::fast_bodies): these check that
// the count never reads zero while one does.
TEST(Continuous, AFastBarMadeAfterSlowBodiesIsStillSwept) {
    Space space;
    for (int i = 0; i < 3; ++i) add_ball(space, Vec3(30, 3.0 * i, 0), false);
    for (int i = 0; i < 5; ++i) space.update();  // steps without a fast body
    const BarRun run = spin(space, add_bar_and_wall(space, true));
    EXPECT_LT(run.max_tip_x, 0.48 + 0.01);
    EXPECT_GT(run.swept_tests, 0u);
}

TEST(Continuous, AFastBarIsStillSweptAfterOtherBodiesComeAndGo) {
    Space space;
    const BodyHandle first_fast = add_ball(space, Vec3(30, 0, 0), true);
    space.update();
    space.destroy_body(first_fast);  // none left: the next step skips the stage
    space.update();
    const BodyHandle bar = add_bar_and_wall(space, true);
    const BodyHandle other_fast = add_ball(space, Vec3(30, 3, 0), true);
    space.destroy_body(add_ball(space, Vec3(-30, 0, 0), false));  // not fast: takes nothing off the count
    space.destroy_body(other_fast);                               // takes itself off, not the bar
    const BarRun run = spin(space, bar);
    EXPECT_LT(run.max_tip_x, 0.48 + 0.01);
    EXPECT_GT(run.swept_tests, 0u);
}

TEST(Continuous, WithoutFastBodiesTheStageDoesNotRun) {
    WorkStealingJobSystem::Options options;
    options.worker_pus = {0};  // one worker, the caller: no threads
    options.pin = false;
    WorkStealingJobSystem jobs(options);
    jobs.enable_trace(true);
    Space space(SpaceSettings{}, &jobs);
    add_ball(space, Vec3(0, 10, 0), false);
    for (int i = 0; i < 5; ++i) space.update();
    EXPECT_EQ(continuous_stages(jobs), 0);
    const BodyHandle fast = add_ball(space, Vec3(5, 10, 0), true);
    space.update();
    EXPECT_EQ(continuous_stages(jobs), 2);  // its pose before the solver, its sweep after
    space.destroy_body(fast);
    for (int i = 0; i < 5; ++i) space.update();
    EXPECT_EQ(continuous_stages(jobs), 2);
}
