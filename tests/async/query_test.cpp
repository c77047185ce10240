// Scene queries from game threads while the physics loop runs (TSan runs this suite):
// a query sees exactly the step the thread's reads see, never waits for a step, and a
// query held across steps delays none of them.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include "async_util.hpp"

namespace spindle {
namespace {

using namespace std::chrono_literals;

// Four threads query (one also reads contact events) while the runner steps balls
// bouncing in their own columns. Each
// query is made with the motion-state lock held, beside a read of the ball's motion
// state: the ray straight down its column must meet it exactly on top, at the pose read.
TEST(AsyncQueries, FourThreadsQueryTheStepTheyReadWhileTheRunnerSteps) {
    SpaceSettings settings = test::async_settings();
    settings.gravity = {0, -9.81, 0};
    Space space(settings);
    BodyDesc ground;
    ground.type = MotionType::Static;
    ground.shape = Shape::plane({0, 1, 0}, 0);
    space.create_body(ground);
    constexpr int kColumns = 16;
    constexpr Real kRadius = 0.25;
    std::vector<BodyHandle> balls;
    for (int c = 0; c < kColumns; ++c) {
        BodyDesc d = test::ball({2.0 * c, 1 + 0.2 * c, 0});
        d.restitution = 0.9;
        d.contact_events = true;         // bouncing: begins, ends and hits for the event reader
        d.angular_velocity = {0, 3, 0};  // spins in place: its top stays on the column's axis
        balls.push_back(space.create_body(d));
    }
    AsyncRunner runner(space);
    runner.start();
    std::atomic<bool> stop{false};
    std::atomic<int> queries{0}, misses{0}, mismatches{0}, events{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&, t] {
            int c = t;
            std::vector<ContactEvent> read;
            while (!stop.load(std::memory_order_relaxed)) {
                if (t == 0) {  // one thread also reads the events as they are published
                    read.clear();
                    events.fetch_add(static_cast<int>(space.read_contact_events(read)), std::memory_order_relaxed);
                }
                c = (c + 1) % kColumns;
                std::scoped_lock hold(space.motion_states().lock());
                const MotionState seen = space.motion_state(balls[static_cast<std::size_t>(c)]);
                const Vec3 x(seen.position.x(), 0, seen.position.z());
                const std::optional<QueryHit> hit = space.cast_ray(x + Vec3(0, 30, 0), x + Vec3(0, -1, 0));
                queries.fetch_add(1, std::memory_order_relaxed);
                if (!hit || hit->body != balls[static_cast<std::size_t>(c)]) {
                    misses.fetch_add(1, std::memory_order_relaxed);
                } else if (std::abs(hit->point.y() - (seen.position.y() + kRadius)) > 1e-9) {
                    mismatches.fetch_add(1, std::memory_order_relaxed);
                }
            }
        });
    }
    const std::uint64_t steps_before = space.motion_states().published_steps();
    std::this_thread::sleep_for(1500ms);
    stop = true;
    for (std::thread& thread : threads) thread.join();
    const std::uint64_t steps_after = space.motion_states().published_steps();
    runner.stop();
    EXPECT_GT(queries.load(), 1000);
    EXPECT_EQ(misses.load(), 0);
    EXPECT_EQ(mismatches.load(), 0);
    EXPECT_GT(steps_after - steps_before, 20u);  // the physics loop kept stepping
    EXPECT_GT(events.load(), kColumns);          // every ball landed at least once
}

// A ray cast down through the origin on its own thread whose filter waits, at its first
// candidate, until release(): the query holds the scene it took for as long as a test wants.
class HeldQuery {
public:
    explicit HeldQuery(Space& space) {
        m_answer = std::async(std::launch::async, [this, &space] {
            QueryFilter filter;
            filter.accept = [this, first = true](BodyHandle) mutable {
                if (first) {
                    first = false;
                    m_inside.set_value();
                    m_released.wait();
                }
                return true;
            };
            return space.cast_ray({0, 5, 0}, {0, -5, 0}, filter);
        });
        m_inside.get_future().wait();
    }
    // Lets the query finish; its answer.
    std::optional<QueryHit> release() {
        m_go.set_value();
        return m_answer.get();
    }

private:
    std::promise<void> m_inside, m_go;
    std::shared_future<void> m_released = m_go.get_future().share();
    std::future<std::optional<QueryHit>> m_answer;
};

// A query that stays inside its walk (its filter waits) while the game steps three
// times: every update finishes, the physics thread copies the scene the query holds,
// and the query answers from the step it started on.
TEST(AsyncQueries, AQueryHeldAcrossStepsDelaysNoneOfThem) {
    Space space(test::weightless());
    const BodyHandle target = space.create_body(test::ball({0, 0, 0}));
    HeldQuery query(space);
    const std::uint64_t copies_before = space.counters().query_scene_copies;
    test::finishes_in_time([&] {
        space.set_position(target, {5, 0, 0});
        for (int i = 0; i < 3; ++i) space.update();
    });
    EXPECT_GE(space.counters().query_scene_copies, copies_before + 1);
    EXPECT_FALSE(space.cast_ray({0, 5, 0}, {0, -5, 0}));  // a new query sees the body moved
    const std::optional<QueryHit> held = query.release();
    ASSERT_TRUE(held);  // the held one answers from its own step
    EXPECT_EQ(held->body, target);
    EXPECT_NEAR(held->point.y(), 0.25, 1e-12);
}

// Bodies made while a query walks the published scene: none is copied under the lock
// (that would stall every reader once per body); queries meet them from the next update.
TEST(AsyncQueries, BodiesMadeWhileAQueryHoldsTheSceneReachQueriesAtTheNextUpdate) {
    Space space(test::weightless());
    space.create_body(test::ball({0, 0, 0}));
    space.update();
    HeldQuery query(space);
    std::vector<BodyHandle> made;
    for (int i = 1; i <= 20; ++i) made.push_back(space.create_body(test::ball({-2.0 * i, 0, 0})));
    EXPECT_EQ(space.counters().query_scene_copies, 0u);
    EXPECT_EQ(space.counters().query_publishes_deferred, 20u);
    EXPECT_FALSE(space.cast_ray({-2, 5, 0}, {-2, -5, 0}));            // not yet: the held scene is published
    EXPECT_EQ(space.motion_state(made[0]).position, Vec3(-2, 0, 0));  // reads see it at once
    EXPECT_TRUE(query.release());
    space.update();
    for (int i = 1; i <= 20; ++i) {
        const std::optional<QueryHit> hit = space.cast_ray({-2.0 * i, 5, 0}, {-2.0 * i, -5, 0});
        ASSERT_TRUE(hit) << i;
        EXPECT_EQ(hit->body, made[static_cast<std::size_t>(i - 1)]);
    }
}

}  // namespace
}  // namespace spindle
