// Continuous collision: a fast-spinning bar does not sweep through a thin static wall
// (speculative contacts see only the linear closing speed, so without the swept test it
// does), flagged `fast` or not: a body is swept in the steps that move some point of it
// farther than half its thinnest half-size (Box3D's choice), a flagged one in every step.
// Slow and kinematic bodies pay nothing for it: a step without a body to sweep has no
// Continuous stage at all.
#include <spindle/engine/space.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "static_bodies.hpp"

using namespace spindle;

namespace continuous_test {

namespace {

struct BarRun {
    double max_tip_x = -1e9;
    std::uint64_t swept_tests = 0;
};

// A 4 m bar spinning at 60 rad/s about its centre 1 m from a 4 cm wall: within one
// step its tip turns from x = 0.07 to x = 1.0, through the wall at x = 0.48..0.52.
// Added to `space` (gravity turned off) after whatever it holds; returns the bar.
BodyDesc bar_at_wall(Space& space) {
    space.set_gravity(Vec3::Zero());
    test::add_static_box(space, Vec3(0.02, 5, 5), Vec3(0.5, 0, 0));
    BodyDesc bar;
    bar.shape = Shape::box(Vec3(2, 0.05, 0.05));
    bar.position = Vec3(-1, 0, 0);
    bar.orientation = Quat(Eigen::AngleAxisd(2.0, Vec3::UnitZ()));
    bar.angular_velocity = Vec3(0, 0, -60);
    return bar;
}

BodyHandle add_bar_and_wall(Space& space, bool fast) {
    BodyDesc bar = bar_at_wall(space);
    bar.fast = fast;
    return space.create_body(bar);
}

// One worker, the caller: no threads.
WorkStealingJobSystem::Options one_worker() {
    WorkStealingJobSystem::Options options;
    options.worker_pus = {0};
    options.pin = false;
    return options;
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

// A static box whose top is y = 0, half_x by half_z about the origin.
void add_ground(Space& space, Real half_x, Real half_z) {
    test::add_static_box(space, Vec3(half_x, 0.5, half_z), Vec3(0, -0.5, 0));
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

// Its tip moves 1.0 m a step, twenty times its half-thickness: swept without the flag.
TEST(Continuous, WithoutTheFlagTheBarIsSweptWhileItSpinsFast) {
    const BarRun run = spin_bar_at_wall(false);
    EXPECT_LT(run.max_tip_x, 0.48 + 0.01);
    EXPECT_GT(run.swept_tests, 0u);
}

// The same bar kinematic: it is driven, not stopped by what it meets, so never swept.
TEST(Continuous, AKinematicBarIsNeverSwept) {
    Space space;
    const BodyHandle bar = add_bar_and_wall(space, false);
    space.set_motion_type(bar, MotionType::Kinematic);
    space.set_angular_velocity(bar, Vec3(0, 0, -60));
    const BarRun run = spin(space, bar);
    EXPECT_GT(run.max_tip_x, 0.52);  // through the wall, as a kinematic body may go
    EXPECT_EQ(run.swept_tests, 0u);
}

// The extents the check reads are remade with the shape (attach()): the bar made as a ball
// of radius 1, which turning at 10 rad/s moves its points 0.24 m a step, under half its
// radius (not swept), then given the bar's shape, whose tip moves 0.33 m a step, more than
// the wall and the bar's thickness together: it would pass through without a sweep.
TEST(Continuous, TheSweepMeasuresTheShapeSetLast) {
    Space space;
    BodyDesc ball = bar_at_wall(space);
    ball.shape = Shape::sphere(1);
    ball.angular_velocity = Vec3(0, 0, -10);
    const BodyHandle bar = space.create_body(ball);
    space.set_shape(bar, Shape::box(Vec3(2, 0.05, 0.05)));
    const BarRun run = spin(space, bar);
    EXPECT_LT(run.max_tip_x, 0.48 + 0.01);
    EXPECT_GT(run.swept_tests, 0u);
}

// Boxes stacked on the ground and balls dropped onto it from 2 m (at most 6.3 m/s, 0.1 m
// a step, under half their half-size): no step sweeps anything.
TEST(Continuous, SlowBodiesAreNeverSwept) {
    WorkStealingJobSystem jobs(one_worker());
    jobs.enable_trace(true);
    Space space(SpaceSettings{}, &jobs);
    add_ground(space, 20, 20);
    for (int i = 0; i < 5; ++i) {
        BodyDesc box;
        box.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        box.position = Vec3(0, 0.5 + i, 0);
        space.create_body(box);
        add_ball(space, Vec3(3.0 + 1.5 * i, 2.5, 0), false);
    }
    for (int i = 0; i < 120; ++i) space.update();
    EXPECT_EQ(space.counters().swept_tests, 0u);
    EXPECT_EQ(continuous_stages(jobs), 0);
}

// A ball rolling at 10 m/s on the ground: its top moves 20 m/s, 0.33 m a step, more than
// half its radius, but a turn moves none of a ball's surface (its rounding turns onto
// itself), and its centre moves 0.17 m a step: never swept.
TEST(Continuous, ABallRollingFastIsNotSweptForItsSpin) {
    Space space;
    add_ground(space, 50, 5);
    BodyDesc ball;
    ball.shape = Shape::sphere(0.5);
    ball.position = Vec3(-40, 0.5, 0);
    ball.linear_velocity = Vec3(10, 0, 0);
    ball.angular_velocity = Vec3(0, 0, -20);
    const BodyHandle handle = space.create_body(ball);
    for (int i = 0; i < 60; ++i) space.update();
    EXPECT_GT(space.internal_motion_state(handle).position.x(), -40 + 9);  // it rolled
    EXPECT_EQ(space.counters().swept_tests, 0u);
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
    WorkStealingJobSystem jobs(one_worker());
    jobs.enable_trace(true);
    Space space(SpaceSettings{}, &jobs);
    add_ball(space, Vec3(0, 10, 0), false);
    for (int i = 0; i < 5; ++i) space.update();
    EXPECT_EQ(continuous_stages(jobs), 0);
    const BodyHandle fast = add_ball(space, Vec3(5, 10, 0), true);
    space.update();
    EXPECT_EQ(continuous_stages(jobs), 1);  // a flagged body is swept every step
    space.destroy_body(fast);
    for (int i = 0; i < 5; ++i) space.update();
    EXPECT_EQ(continuous_stages(jobs), 1);
}

}  // namespace continuous_test
