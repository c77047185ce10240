// Interpolation (the seed, section 2.B).
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

using namespace spindle;

namespace {

constexpr double kStep = 0.016667;

Space make_space() {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    s.time_step.use_internal_time_stepping = true;
    s.time_step.duration = kStep;
    return Space(s);
}

BodyDesc moving(bool interpolate) {
    BodyDesc d;
    d.type = MotionType::Kinematic;
    d.shape = Shape::sphere(0.1);
    d.linear_velocity = Vec3(1, 0, 0);
    d.angular_velocity = Vec3(0, 0, 3);
    d.allow_interpolation = interpolate;
    return d;
}

// Two reads of one published step by a game thread, some real time apart, each with the
// instants just before taking the lock and just after the read.
struct ReadPair {
    MotionState first, second, first_update_clock, second_update_clock;
    PublishedTime time;
    std::int64_t before_first = 0, after_first = 0, before_second = 0, after_second = 0;
};

MotionState read_one(const Space& space, BodyHandle body, BlendClock clock) {
    MotionState out;
    space.motion_states().get_motion_states(std::span(&body, 1), std::span(&out, 1), clock);
    return out;
}

// Retries until both reads fall within one published step and the second is still
// blending (not capped at the newest step), as a slow machine may need.
ReadPair read_twice_within_a_step(const Space& space, BodyHandle body, std::chrono::milliseconds apart) {
    const MotionStateManager& states = space.motion_states();
    for (int attempt = 0; attempt < 50; ++attempt) {
        ReadPair r;
        r.before_first = now_nanoseconds();
        {
            const MotionStateLock::Hold hold(states.lock());
            r.first = space.motion_state(body);
            r.first_update_clock = read_one(space, body, BlendClock::Update);
            r.time = states.published_time();
        }
        r.after_first = now_nanoseconds();
        std::this_thread::sleep_for(apart);
        r.before_second = now_nanoseconds();
        const MotionStateLock::Hold hold(states.lock());
        r.second = space.motion_state(body);
        r.second_update_clock = read_one(space, body, BlendClock::Update);
        r.after_second = now_nanoseconds();
        if (states.published_steps_locked() == r.time.steps && states.alpha_locked() < 1) return r;
    }
    ADD_FAILURE() << "no two reads fell within one published step";
    return {};
}

Space runner_space(double step) {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    s.time_step.use_internal_time_stepping = true;
    s.time_step.duration = step;
    return Space(s);
}

}  // namespace

// Under an AsyncRunner, reads blend by their own clock: between two flips interpolated
// motion moves on at the real rate (one step behind), where the seed's blend stands still.
TEST(Interpolation, ReadClockMovesReadsOnBetweenFlipsAtTheRealRate) {
    constexpr double kLongStep = 0.1;  // s: room for two reads within one published step
    Space space = runner_space(kLongStep);
    const BodyHandle body = space.create_body(moving(true));  // 1 m/s along x from 0
    AsyncRunner runner(space);
    runner.start();
    while (space.motion_states().published_steps() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    const ReadPair r = read_twice_within_a_step(space, body, std::chrono::milliseconds(30));
    runner.stop();
    EXPECT_NE(r.time.clock_ns, 0);
    EXPECT_EQ(r.time.reads, BlendClock::Read);
    // The seed's blend: the same weight for both reads, from the update's banked time.
    const double banked = (static_cast<double>(r.time.steps) - 1 + r.time.banked_alpha) * kLongStep;
    EXPECT_NEAR(r.first_update_clock.position.x(), banked, 1e-9);
    EXPECT_EQ(r.second_update_clock.position, r.first_update_clock.position);
    // The reader's clock: the second read has moved on by the real time between them
    // (the lock was taken somewhere between each pair of instants), at 1 m/s.
    const double moved = r.second.position.x() - r.first.position.x();
    EXPECT_GE(moved, static_cast<double>(r.before_second - r.after_first) * 1e-9 - 1e-9);
    EXPECT_LE(moved, static_cast<double>(r.after_second - r.before_first) * 1e-9 + 1e-9);
    // And each is the banked time grown by the time since the update measured it.
    EXPECT_GE(r.first.position.x(), banked + static_cast<double>(r.before_first - r.time.clock_ns) * 1e-9 - 1e-9);
    EXPECT_LE(r.first.position.x(), banked + static_cast<double>(r.after_first - r.time.clock_ns) * 1e-9 + 1e-9);
}

// Every read under one hold of the lock shows the instant the lock was taken, so reads
// and scene queries made together agree, however long the hold.
TEST(Interpolation, ReadsUnderOneHoldShowOneInstant) {
    Space space = runner_space(0.1);
    const BodyHandle body = space.create_body(moving(true));
    AsyncRunner runner(space);
    runner.start();
    while (space.motion_states().published_steps() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    MotionState first, second;
    double alpha_first = 0, alpha_second = 0;
    {
        const MotionStateLock::Hold hold(space.motion_states().lock());
        first = space.motion_state(body);
        alpha_first = space.motion_states().alpha_locked();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        second = space.motion_state(body);
        alpha_second = space.motion_states().alpha_locked();
    }
    runner.stop();
    EXPECT_EQ(first.position, second.position);
    EXPECT_EQ(alpha_first, alpha_second);
}

// Reads that name no clock take the runner's from the published time, which each flip
// writes: they read it under the lock (ThreadSanitizer caught the clock read before it).
// Each read lies between the body's start and where the runner's time has taken it.
TEST(Interpolation, ReadsNamingNoClockAreSafeWhileTheRunnerFlips) {
    Space space = runner_space(0.001);  // a flip every millisecond
    const BodyHandle body = space.create_body(moving(true));
    AsyncRunner runner(space);
    const std::int64_t started = now_nanoseconds();
    runner.start();
    const std::uint64_t first = space.motion_states().published_steps();
    int reads = 0;
    // 50 flips and 51 reads, however the OS shares the CPUs between reader and runner.
    while ((space.motion_states().published_steps() < first + 50 || reads <= 50) && reads < 1'000'000) {
        MotionState out;
        space.motion_states().get_motion_states(std::span(&body, 1), std::span(&out, 1));
        const double since_start = static_cast<double>(now_nanoseconds() - started) * 1e-9;
        ASSERT_GE(out.position.x(), 0);
        ASSERT_LE(out.position.x(), since_start + 1e-9);
        ++reads;
    }
    runner.stop();
    EXPECT_GT(reads, 50);
}

// A runner asked for the seed's blend: reads stand still between flips.
TEST(Interpolation, RunnerWithTheUpdateClockKeepsTheSeedsBlend) {
    Space space = runner_space(0.1);
    const BodyHandle body = space.create_body(moving(true));
    AsyncRunnerOptions options;
    options.blend_clock = BlendClock::Update;
    AsyncRunner runner(space, options);
    runner.start();
    while (space.motion_states().published_steps() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    const ReadPair r = read_twice_within_a_step(space, body, std::chrono::milliseconds(30));
    runner.stop();
    EXPECT_EQ(r.time.reads, BlendClock::Update);
    EXPECT_EQ(r.second.position, r.first.position);
    EXPECT_NEAR(r.first.position.x(), (static_cast<double>(r.time.steps) - 1 + r.time.banked_alpha) * 0.1, 1e-9);
}

TEST(Interpolation, SeedExampleBlendsPointFourOfNewestAndPointSixOfPrevious) {
    Space space = make_space();
    const BodyHandle body = space.create_body(moving(true));
    space.update(kStep);             // step 1: x = kStep
    space.update(kStep + 0.006667);  // step 2: x = 2 kStep, 0.006667 left over
    ASSERT_EQ(space.last_update().steps, 1);
    EXPECT_NEAR(space.motion_states().alpha(), 0.4, 1e-4);
    const double alpha = 0.006667 / kStep;
    const double previous = kStep, newest = 2 * kStep;
    EXPECT_NEAR(space.position(body).x(), (1 - alpha) * previous + alpha * newest, 1e-12);
    EXPECT_NEAR(space.center_of_mass(body).x(), (1 - alpha) * previous + alpha * newest, 1e-12);
    // Orientation: slerp between the two steps' rotations about z.
    const double angle = 3 * ((1 - alpha) * previous + alpha * newest);
    EXPECT_NEAR(2 * std::atan2(space.orientation(body).z(), space.orientation(body).w()), angle, 1e-6);
}

TEST(Interpolation, WithTheFlagOffTheNewestStateIsReturned) {
    Space space = make_space();
    const BodyHandle body = space.create_body(moving(false));
    space.update(kStep);
    space.update(kStep + 0.006667);
    EXPECT_NEAR(space.position(body).x(), 2 * kStep, 1e-12);
}

TEST(Interpolation, BodiesWithoutTheFlagPayNothing) {
    Space space = make_space();
    for (int i = 0; i < 10; ++i) space.create_body(moving(false));
    for (int i = 0; i < 10; ++i) space.update(kStep);
    EXPECT_EQ(space.counters().interpolated_publishes, 0u);
    space.create_body(moving(true));
    space.update(kStep);
    EXPECT_EQ(space.counters().interpolated_publishes, 1u);
}

TEST(Interpolation, SlerpTakesTheShortestArc) {
    const Quat a(Eigen::AngleAxisd(0.1, Vec3::UnitZ()));
    Quat b(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
    b.coeffs() = -b.coeffs();  // the same rotation, on the far side of the 4D sphere
    const Quat mid = slerp_shortest(a, b, 0.5);
    EXPECT_NEAR(mid.angularDistance(Quat(Eigen::AngleAxisd(0.2, Vec3::UnitZ()))), 0.0, 1e-12);
}

TEST(Interpolation, ATeleportJumpsInsteadOfSliding) {
    Space space = make_space();
    const BodyHandle body = space.create_body(moving(true));
    space.update(kStep);
    space.update(kStep);
    space.set_position(body, Vec3(100, 0, 0));
    space.update(0.5 * kStep);  // no step: the teleport alone is published
    EXPECT_EQ(space.last_update().steps, 0);
    EXPECT_EQ(space.position(body), Vec3(100, 0, 0));
    space.update(kStep);  // one step on: blends between 100 and 100 + kStep only
    EXPECT_GE(space.position(body).x(), 100.0);
}

// An update that takes no step and applies no write leaves the awake bodies as they
// were: once both published buffers hold the newest step, flips refill nothing. What
// changes without a step (a buffered write, a direct internal change) still shows in
// every later read, whichever buffer is in front.
TEST(Interpolation, UpdatesWithoutAStepRepublishOnlyWhatChanged) {
    Space space = make_space();
    std::vector<BodyHandle> bodies;
    for (int i = 0; i < 10; ++i) bodies.push_back(space.create_body(moving(i != 4)));  // 4: read unblended
    space.update(kStep);
    const double tiny = kStep / 100;
    space.update(tiny);  // the other buffer catches up with the step
    const std::uint64_t caught_up = space.counters().awake_publishes;
    for (int i = 0; i < 20; ++i) space.update(tiny);
    EXPECT_EQ(space.counters().awake_publishes, caught_up);
    EXPECT_EQ(space.last_update().steps, 0);

    // An impulse changes the velocity at once, without marking the body changed.
    BodyDesc ball = moving(false);
    ball.type = MotionType::Dynamic;
    ball.position = Vec3(0, 10, 0);
    ball.mass = 2;
    const BodyHandle dynamic = space.create_body(ball);
    space.update(kStep);
    for (int i = 0; i < 3; ++i) space.update(tiny);
    const Vec3 pushed = space.linear_velocity(dynamic) + Vec3(0, 5, 0) / 2;  // mass 2 kg
    space.apply_impulse(dynamic, Vec3(0, 5, 0));
    for (int i = 0; i < 3; ++i) {
        space.update(tiny);
        EXPECT_TRUE(space.linear_velocity(dynamic).isApprox(pushed, 1e-12)) << "flip " << i;
    }
    MotionState moved = space.internal_motion_state(bodies[4]);
    moved.position = Vec3(7, 8, 9);
    space.set_internal_motion_state(bodies[4], moved);
    for (int i = 0; i < 3; ++i) {
        space.update(tiny);
        EXPECT_TRUE(space.position(bodies[4]).isApprox(Vec3(7, 8, 9), 1e-12)) << "flip " << i;
    }
    const std::uint64_t before = space.counters().awake_publishes;
    for (int i = 0; i < 5; ++i) space.update(tiny);
    EXPECT_EQ(space.counters().awake_publishes, before);
}
