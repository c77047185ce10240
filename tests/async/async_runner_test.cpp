// The physics loop thread: pinning, elapsed-time stepping, clean stop, posting.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/platform/topology.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <thread>

using namespace spindle;

namespace {

SpaceSettings async_settings() {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    s.time_step.use_internal_time_stepping = true;
    return s;
}

BodyDesc ball() {
    BodyDesc d;
    d.shape = Shape::sphere(0.25);
    d.mass = 1;
    return d;
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
    ASSERT_EQ(result.wait_for(std::chrono::seconds(10)), std::future_status::ready);
    const auto [binding, name] = result.get();
    runner.stop();
    EXPECT_EQ(binding, std::vector<unsigned>{pu});
    EXPECT_EQ(name, "physics-test");
}

TEST(AsyncRunner, StepsFollowElapsedTime) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    runner.stop();
    const AsyncStats stats = runner.stats();
    // About 18 steps of 1/60 s in 0.3 s; a loaded machine may drop some, never add.
    EXPECT_GE(stats.steps, 5u);
    EXPECT_LE(static_cast<double>(stats.steps), stats.seconds * 60 + 2);
    EXPECT_GT(stats.updates, 0u);
    EXPECT_GE(stats.update_ms_p99, stats.update_ms_p50);
    EXPECT_GE(stats.lock_us_max, stats.lock_us_p99);
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
    ASSERT_EQ(handle.wait_for(std::chrono::seconds(10)), std::future_status::ready);
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
