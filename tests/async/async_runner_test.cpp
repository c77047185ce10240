// The physics loop thread: pinning, elapsed-time stepping, clean stop, posting, what
// happens to exceptions, and the rules that turn would-be deadlocks into errors.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/platform/topology.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <gtest/gtest.h>

#include "async_util.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <future>
#include <limits>
#include <string>
#include <thread>

using namespace spindle;
using namespace spindle::test;

namespace {

// A single-threaded job system that shows what the update thread does: which thread
// runs updates, a sleep in every step (a known lower bound on an update's time), and
// a one-shot failure of the broadphase's parallel range, which makes Space::update
// throw the way a failing job does.
class WatchedJobs final : public JobSystem {
public:
    std::atomic<std::thread::id> first_updater{};
    std::atomic<int> sleep_ms_per_step{0};
    std::atomic<bool> fail_next_broadphase{false};

    unsigned worker_count() const noexcept override { return 1; }
    void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                      RangeFn fn) override {
        if (std::strcmp(name, "Bounds") == 0 && fail_next_broadphase.exchange(false)) {
            throw Error("injected job failure");
        }
        m_jobs.parallel_for(name, begin, end, grain, fn);
    }
    void run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) override {
        m_jobs.run_phases(name, phases, fn);
    }
    void run_graph(StageGraph& graph) override { m_jobs.run_graph(graph); }
    void trace_begin(const char* stage) noexcept override {
        if (std::strcmp(stage, "ApplyWrites") == 0) {
            std::thread::id none{};
            first_updater.compare_exchange_strong(none, std::this_thread::get_id());
        }
        if (std::strcmp(stage, "Solver") == 0 && sleep_ms_per_step.load() > 0) {
            std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms_per_step.load()));
        }
    }
    void trace_end() noexcept override {}

private:
    SingleThreadedJobSystem m_jobs;
};

template <typename T>
bool ready_in_time(std::future<T>& f) {
    return f.wait_for(kHang) == std::future_status::ready;
}

}  // namespace

TEST(AsyncRunner, LoopThreadIsPinnedAndNamed) {
    Space space(async_settings());
    const Topology machine = Topology::from_system();
    const unsigned pu = machine.pus().back().os_index;
    AsyncRunner runner(space, AsyncRunnerOptions{.physics_pu = pu, .thread_name = "physics-test"});
    runner.start();
    std::promise<std::pair<std::vector<unsigned>, std::string>> seen;
    runner.post([&](Space&) { seen.set_value({current_binding(), current_thread_name()}); });
    auto result = seen.get_future();
    ASSERT_EQ(result.wait_for(kHang), std::future_status::ready);
    const auto [binding, name] = result.get();
    runner.stop();
    EXPECT_EQ(binding, std::vector<unsigned>{pu});
    EXPECT_EQ(name, "physics-test");
}

TEST(AsyncRunner, StepsFollowElapsedTime) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.start();
    // Five steps at least, however long a loaded machine takes for them; then the bound.
    EXPECT_TRUE(eventually([&] { return runner.stats().steps >= 5; }));
    runner.stop();
    const AsyncStats stats = runner.stats();
    // A loaded machine may drop steps, never add: no more than the seconds it ran allow.
    EXPECT_GE(stats.steps, 5u);
    EXPECT_LE(static_cast<double>(stats.steps), stats.seconds * 60 + 2);
    EXPECT_GT(stats.updates, 0u);
}

TEST(AsyncRunner, StatsAgreeWithWhatTheLoopDid) {
    WatchedJobs jobs;
    jobs.sleep_ms_per_step = 2;  // every update that takes a step lasts at least 2 ms
    Space space(async_settings(), &jobs);
    space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_TRUE(eventually([&] { return runner.stats().steps >= 1; }));  // a loaded machine's first step may come later
    runner.stop();
    const AsyncStats stats = runner.stats();
    ASSERT_GT(stats.steps, 0u);
    // The space's own count: stop()'s flush takes no step, so they must be equal.
    EXPECT_EQ(stats.steps, space.counters().steps);
    EXPECT_GE(stats.updates, stats.steps / static_cast<std::uint64_t>(space.settings().time_step.max_steps_per_frame));
    // In the units they name: milliseconds at least the sleep, within the loop's wall
    // time; the flip's lock hold (microseconds) is part of an update.
    EXPECT_GE(stats.update_ms_p50, 2.0);
    EXPECT_LE(stats.update_ms_max, stats.seconds * 1e3);
    EXPECT_LE(stats.lock_us_max, stats.update_ms_max * 1e3);
    // No time is made up: the steps taken and the steps' worth dropped fit in the seconds
    // run. (A loop starved past the cap, 10 steps' worth, drops time: a loaded machine's may.)
    const double step_seconds = space.settings().time_step.duration;
    EXPECT_LE(static_cast<double>(stats.steps + stats.steps_dropped), stats.seconds / step_seconds + 1);
}

TEST(AsyncRunner, StatsCountTheStepsTheCapDrops) {
    Space space(async_settings());
    space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    // A posted function that takes half a second: the next update is due 30 steps, takes the
    // cap's 10, carries 10 and drops the rest, 10 or more steps' worth.
    std::future<void> slow = runner.post([](Space&) { std::this_thread::sleep_for(std::chrono::milliseconds(500)); });
    ASSERT_TRUE(ready_in_time(slow));
    EXPECT_TRUE(eventually([&] { return runner.stats().steps_dropped >= 10; }));
    runner.stop();
    const AsyncStats stats = runner.stats();
    const double step_seconds = space.settings().time_step.duration;
    EXPECT_GE(stats.steps_dropped, 10u);
    EXPECT_LE(static_cast<double>(stats.steps + stats.steps_dropped), stats.seconds / step_seconds + 1);
}

TEST(AsyncRunner, PostedFunctionsRunOnTheThreadThatUpdates) {
    WatchedJobs jobs;
    Space space(async_settings(), &jobs);
    AsyncRunner runner(space);
    runner.start();
    std::future<std::thread::id> first = runner.post([](Space&) { return std::this_thread::get_id(); });
    std::future<std::thread::id> second = runner.post([](Space&) { return std::this_thread::get_id(); });
    ASSERT_TRUE(ready_in_time(first));
    ASSERT_TRUE(ready_in_time(second));
    const std::thread::id ran_on = first.get();
    runner.stop();
    EXPECT_NE(ran_on, std::this_thread::get_id());
    EXPECT_EQ(ran_on, jobs.first_updater.load());  // the loop thread, recorded by its first update
    EXPECT_EQ(second.get(), ran_on);
}

TEST(AsyncRunner, StopAppliesEveryWriteMadeBeforeIt) {
    SpaceSettings settings = async_settings();
    settings.solver.max_linear_speed = 1e9;  // the velocity counts the writes: no speed limit in the way
    Space space(settings);
    const BodyHandle body = space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    constexpr int kWrites = 20000;
    for (int i = 0; i < kWrites; ++i) space.apply_impulse(body, Vec3(1, 0, 0));
    runner.stop();
    EXPECT_FALSE(runner.running());
    EXPECT_EQ(space.internal_linear_velocity(body).x(), kWrites);
    EXPECT_EQ(space.linear_velocity(body).x(), kWrites);  // published too
}

TEST(AsyncRunner, PostedFunctionsChangeStructureOnTheLoopThread) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.start();
    std::promise<BodyHandle> created;
    runner.post([&](Space& s) { created.set_value(s.create_body(ball())); });
    auto handle = created.get_future();
    ASSERT_EQ(handle.wait_for(kHang), std::future_status::ready);
    const BodyHandle body = handle.get();
    runner.stop();
    EXPECT_TRUE(space.contains(body));
    EXPECT_EQ(space.position(body), Vec3::Zero());
}

TEST(AsyncRunner, BadPhysicsThreadIsReportedByStart) {
    Space space(async_settings());
    AsyncRunner runner(space, AsyncRunnerOptions{.physics_pu = 100000u});
    EXPECT_THROW(runner.start(), Error);
    EXPECT_FALSE(runner.running());
}

TEST(AsyncRunner, PostReturnsTheFunctionsResult) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.start();
    std::future<BodyHandle> created = runner.post([](Space& s) { return s.create_body(ball()); });
    ASSERT_TRUE(ready_in_time(created));
    const BodyHandle body = created.get();
    runner.stop();
    EXPECT_TRUE(space.contains(body));
}

TEST(AsyncRunner, PostedExceptionGoesToTheFutureAndTheLoopGoesOn) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.start();
    BodyDesc bad = ball();
    bad.mass = -1;  // create_body throws spindle::Error by design
    std::future<BodyHandle> rejected = runner.post([bad](Space& s) { return s.create_body(bad); });
    ASSERT_TRUE(ready_in_time(rejected));
    EXPECT_THROW(rejected.get(), Error);
    EXPECT_TRUE(runner.running());
    std::future<BodyHandle> created = runner.post([](Space& s) { return s.create_body(ball()); });
    ASSERT_TRUE(ready_in_time(created));
    const BodyHandle body = created.get();
    EXPECT_NO_THROW(runner.stats());
    EXPECT_NO_THROW(runner.stop());
    EXPECT_EQ(space.body_count(), 1u);
    EXPECT_TRUE(space.contains(body));
}

TEST(AsyncRunner, PostedExceptionRunByStopOrTheDestructorGoesToTheFuture) {
    Space space(async_settings());
    std::future<void> from_stop, from_destructor, never_run;
    {
        AsyncRunner runner(space);
        runner.start();
        runner.stop();
        // Posted after stop: runs at the next start.
        from_stop = runner.post([](Space&) { throw Error("posted failure"); });
        runner.start();
        from_destructor = runner.post([](Space&) { throw Error("posted failure"); });
    }  // the destructor stops the loop; each function ran on the loop or in stop()
    {
        AsyncRunner runner(space);
        never_run = runner.post([](Space&) {});  // never started: the destructor breaks the promise
    }
    ASSERT_EQ(never_run.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    EXPECT_THROW(never_run.get(), std::future_error);
    ASSERT_EQ(from_stop.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    ASSERT_EQ(from_destructor.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    EXPECT_THROW(from_stop.get(), Error);
    EXPECT_THROW(from_destructor.get(), Error);
}

TEST(AsyncRunner, UpdateFailureEndsTheLoopKeepsWritesAndIsReportedByStop) {
    WatchedJobs jobs;
    SpaceSettings settings = async_settings();
    settings.solver.max_linear_speed = 1e9;  // the velocity counts the writes: no speed limit in the way
    Space space(settings, &jobs);
    const BodyHandle body = space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    int writes = 0;
    for (; writes < 1000; ++writes) space.apply_impulse(body, Vec3(1, 0, 0));
    jobs.fail_next_broadphase = true;
    // Writes go on being accepted while (and after) the loop fails.
    const auto deadline = std::chrono::steady_clock::now() + kHang;
    while (runner.running() && std::chrono::steady_clock::now() < deadline) {
        space.apply_impulse(body, Vec3(1, 0, 0));
        ++writes;
    }
    ASSERT_FALSE(runner.running());
    for (int i = 0; i < 10; ++i, ++writes) space.apply_impulse(body, Vec3(1, 0, 0));

    // Until stop(), stats() and post() report the failure; stop() reports it once.
    EXPECT_THROW(runner.stats(), Error);
    EXPECT_THROW((void)runner.post([](Space&) {}), Error);
    try {
        runner.stop();
        ADD_FAILURE() << "stop() did not report the loop's failure";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("injected job failure"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(runner.running());
    EXPECT_NO_THROW(runner.stop());
    EXPECT_NO_THROW(runner.stats());
    // Every accepted write was applied and published: none was lost to the failure.
    EXPECT_EQ(space.internal_linear_velocity(body).x(), writes);
    EXPECT_EQ(space.linear_velocity(body).x(), writes);
    // The runner may start again.
    runner.start();
    EXPECT_TRUE(runner.running());
    runner.stop();
}

TEST(AsyncRunner, DestructorSwallowsAFailureNobodyAskedFor) {
    WatchedJobs jobs;
    Space space(async_settings(), &jobs);
    space.create_body(ball());
    {
        AsyncRunner runner(space);
        runner.start();
        jobs.fail_next_broadphase = true;
        const auto deadline = std::chrono::steady_clock::now() + kHang;
        while (runner.running() && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
        ASSERT_FALSE(runner.running());
    }  // must not throw nor terminate
    SUCCEED();
}

TEST(AsyncRunner, StopFromAPostedFunctionThrowsAndTheLoopGoesOn) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.start();
    std::future<void> stopping = runner.post([&](Space&) { runner.stop(); });
    ASSERT_TRUE(ready_in_time(stopping));
    EXPECT_THROW(stopping.get(), Error);
    EXPECT_TRUE(runner.running());
    runner.stop();
}

TEST(AsyncRunner, StopWhileHoldingTheMotionStateLockThrowsInsteadOfHanging) {
    Space space(async_settings());
    const BodyHandle body = space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    finishes_in_time([&] {
        std::scoped_lock hold(space.motion_states().lock());
        try {
            runner.stop();
            ADD_FAILURE() << "stop() under the motion-state lock did not throw";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("motion-state lock"), std::string::npos) << e.what();
        }
    });
    EXPECT_TRUE(runner.running());
    space.apply_impulse(body, Vec3(2, 0, 0));
    runner.stop();
    EXPECT_EQ(space.linear_velocity(body).x(), 2.0);
}

TEST(AsyncRunner, StatsFromAnyThreadWhileTheLoopChangesTheTimeStep) {
    // stats() must not read the space's settings, which a posted set_time_step writes
    // (TSan reports the race if it does).
    Space space(async_settings());
    space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    std::atomic<bool> done{false};
    std::atomic<std::uint64_t> reads{0};
    auto reader = [&] {
        while (!done.load()) {
            const AsyncStats s = runner.stats();
            EXPECT_LE(s.steps_dropped, s.steps + 1000);
            reads.fetch_add(1);
        }
    };
    std::thread a(reader), b(reader);
    std::future<void> last;
    for (int i = 0; i < 200; ++i) {
        TimeStepSettings next;
        next.use_internal_time_stepping = true;
        next.duration = i % 2 == 0 ? 1.0 / 120 : 1.0 / 60;
        last = runner.post([next](Space& s) { s.set_time_step(next); });
        std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    ASSERT_TRUE(ready_in_time(last));
    done = true;
    a.join();
    b.join();
    runner.stop();
    EXPECT_GT(reads.load(), 0u);
    EXPECT_EQ(space.settings().time_step.duration, 1.0 / 60);
}

TEST(AsyncRunner, TimeScaleSlowsTheSteps) {
    Space space(async_settings());
    space.create_body(ball());
    AsyncRunner runner(space);
    runner.set_time_scale(0.25);
    runner.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    EXPECT_TRUE(eventually([&] { return runner.stats().steps >= 1; }));  // a loaded machine's first step may come later
    runner.stop();
    const AsyncStats stats = runner.stats();
    // A quarter of about 36 steps: a loaded machine may take fewer, never more.
    EXPECT_GE(stats.steps, 1u);
    EXPECT_LE(static_cast<double>(stats.steps), stats.seconds * 60 * 0.25 + 2);
    EXPECT_EQ(runner.time_scale(), 0.25);
}

TEST(AsyncRunner, PausedRunnerRunsPostedFunctionsAndAdvanceTakesOneStep) {
    Space space(async_settings());
    BodyDesc moving = ball();
    moving.linear_velocity = Vec3(1, 0, 0);
    const BodyHandle body = space.create_body(moving);
    AsyncRunner runner(space);
    runner.set_time_scale(0);
    runner.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    auto ran = runner.post([](Space& s) { return s.counters().steps; });
    ASSERT_TRUE(ready_in_time(ran));
    EXPECT_EQ(ran.get(), 0u);

    const MotionStateManager& states = space.motion_states();
    runner.advance(space.settings().time_step.duration);
    for (int i = 0; i < 1000 && states.published_steps() < 1; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_EQ(states.published_steps(), 1u);
    // Paused again after the step: reads by the reader's clock stand still too.
    const MotionState first = states.read(body);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const MotionState later = states.read(body);
    EXPECT_EQ(states.published_steps(), 1u);
    EXPECT_EQ(first.position, later.position);
    // The step was taken (raw), and the blend, standing at the step before, did not run on
    // to it at the real rate.
    MotionState raw;
    states.get_raw_motion_states(std::span(&body, 1), std::span(&raw, 1));
    EXPECT_GT(raw.position.x(), 0.0);
    EXPECT_LT(later.position.x(), raw.position.x());
    runner.stop();
    EXPECT_EQ(space.counters().steps, 1u);
}

TEST(AsyncRunner, AScaleSetWhileAPostedFunctionRunsTakesItsUpdate) {
    // The loop sleeps until a step is due, so each iteration's update would take one. A
    // posted function holds an iteration until the scale is 0: that iteration's update
    // must already take no step (a function posted after set_time_scale runs in an
    // iteration at the new scale), and no later one either.
    Space space(async_settings());
    space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    const MotionStateManager& states = space.motion_states();
    for (int round = 0; round < 10; ++round) {
        std::promise<void> release;
        std::promise<std::uint64_t> running;
        std::shared_future<void> released = release.get_future().share();
        auto held = runner.post([&running, released](Space& s) {
            running.set_value(s.counters().steps);
            released.wait();
        });
        const std::uint64_t steps = running.get_future().get();
        runner.set_time_scale(0);
        release.set_value();
        ASSERT_TRUE(ready_in_time(held));
        auto after = runner.post([](Space& s) { return s.counters().steps; });
        ASSERT_TRUE(ready_in_time(after));
        EXPECT_EQ(after.get(), steps) << "round " << round;
        EXPECT_EQ(states.published_steps(), steps) << "round " << round;
        runner.set_time_scale(1);
        std::this_thread::sleep_for(std::chrono::milliseconds(40));
    }
    runner.stop();
}

TEST(AsyncRunner, BadTimeScaleOrAdvanceIsRefusedAndChangesNothing) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.set_time_scale(0.5);
    for (const double bad : {std::nan(""), -1.0, std::numeric_limits<double>::infinity()}) {
        try {
            runner.set_time_scale(bad);
            ADD_FAILURE() << "accepted a time scale of " << bad;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("set_time_scale"), std::string::npos) << e.what();
        }
        EXPECT_EQ(runner.time_scale(), 0.5);
        EXPECT_THROW(runner.advance(bad), Error);
    }
    runner.advance(1e308);
    EXPECT_THROW(runner.advance(1e308), Error);  // the sum would be infinite
    runner.set_time_scale(0);
    runner.start();
    runner.stop();  // the one finite advance was dropped by the step cap, not thrown
    EXPECT_LE(space.counters().steps, static_cast<std::uint64_t>(space.settings().time_step.max_steps_per_frame));
}
