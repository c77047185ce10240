// Structural calls (create_body, destroy_body, joints, settings, internal reads) from a
// thread other than the one updating are rejected with an Error while an update runs
// or an AsyncRunner owns the space, and never corrupt memory (TSan runs this suite).
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "async_util.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

// Every structural call once, on a space with one body `body`; counts the ones that threw.
int structural_calls_rejected(Space& space, BodyHandle body, std::string& message) {
    int rejected = 0;
    auto attempt = [&](auto call) {
        try {
            call();
        } catch (const Error& e) {
            rejected += 1;
            message = e.what();
        }
    };
    attempt([&] { space.destroy_body(space.create_body(ball(Vec3(5, 5, 5)))); });
    attempt([&] {
        const BodyHandle other = space.create_body(ball(Vec3(0, 2, 0)));
        space.destroy_joint(space.create_joint(JointDesc::distance_between(body, other, Vec3::Zero(), Vec3(0, 2, 0))));
        space.destroy_body(other);
    });
    attempt([&] { space.set_gravity(Vec3(0, -1, 0)); });
    attempt([&] { space.set_solver(space.settings().solver); });
    attempt([&] { (void)space.internal_motion_state(body); });
    attempt([&] { (void)space.internal_desc(body); });
    attempt([&] { (void)space.state_hash(); });
    attempt([&] { space.update(); });
    return rejected;
}

}  // namespace

TEST(StructureGate, EveryStructuralCallFromAnotherThreadIsRejectedWhileARunnerRuns) {
    Space space(async_settings());
    const BodyHandle body = space.create_body(ball());
    AsyncRunner runner(space);
    runner.start();
    std::string message;
    EXPECT_EQ(structural_calls_rejected(space, body, message), 8);
    EXPECT_NE(message.find("AsyncRunner::post"), std::string::npos) << message;
    EXPECT_EQ(space.body_count(), 1u);
    // Posted, the same calls run on the loop thread.
    int rejected_on_loop = -1;
    runner.post([&](Space& s) { rejected_on_loop = structural_calls_rejected(s, body, message); }).get();
    EXPECT_EQ(rejected_on_loop, 0) << message;
    runner.stop();
    // Stopped, the owner thread may call them again.
    EXPECT_EQ(structural_calls_rejected(space, body, message), 0) << message;
}

// Without a runner: one thread updates in a loop, another makes and destroys bodies
// flat out. Each call either runs between updates or throws naming the update; the
// space stays whole (TSan sees no race, the body count adds up). The updating thread
// pauses between updates now and then: when both threads share one core (beside a
// real-time process on the other), the maker runs only when the updater is preempted,
// nearly always inside an update, and half the runs pinned to one core made no body.
TEST(StructureGate, StructuralCallsDuringAnotherThreadsUpdateThrowAndCorruptNothing) {
    Space space(weightless());
    for (int i = 0; i < 64; ++i) space.create_body(ball(Vec3(i, 0, 0)));
    std::atomic<bool> running{true};
    std::atomic<int> updates{0};
    std::thread physics([&] {
        while (running.load()) {
            space.update();
            // Now and then a pause between updates (see above).
            if (updates.fetch_add(1) % 64 == 0) std::this_thread::sleep_for(std::chrono::microseconds(100));
        }
    });
    int made = 0, rejected = 0;
    std::vector<BodyHandle> mine;
    while (updates.load() < 200 || made == 0 || rejected == 0) {
        try {
            if (mine.size() < 32) {
                mine.push_back(space.create_body(ball(Vec3(0, 10, 0))));
                made += 1;
            } else {
                space.destroy_body(mine.back());
                mine.pop_back();
            }
        } catch (const Error& e) {
            rejected += 1;
            EXPECT_NE(std::string(e.what()).find("an update is running on another thread"), std::string::npos)
                << e.what();
        }
        if (updates.load() > 100000) break;  // neither outcome showed up: fail below
    }
    running.store(false);
    physics.join();
    EXPECT_GT(made, 0);
    EXPECT_GT(rejected, 0);
    EXPECT_EQ(space.body_count(), 64u + mine.size());
    for (BodyHandle b : mine) EXPECT_TRUE(space.contains(b));
    space.update();  // the pipeline still runs over what was made
}

// contains() and body_count() read what is published: any thread, while bodies are made.
TEST(StructureGate, ContainsAndBodyCountAreSafeFromAnyThread) {
    Space space(async_settings());
    AsyncRunner runner(space);
    runner.start();
    std::vector<BodyHandle> made;
    for (int i = 0; i < 50; ++i) {
        made.push_back(runner.post([i](Space& s) { return s.create_body(ball(Vec3(i, 0, 0))); }).get());
        EXPECT_TRUE(space.contains(made.back()));
        EXPECT_EQ(space.body_count(), made.size());
    }
    runner.post([&](Space& s) { s.destroy_body(made.front()); }).get();
    EXPECT_FALSE(space.contains(made.front()));
    EXPECT_EQ(space.body_count(), made.size() - 1);
    runner.stop();
}
