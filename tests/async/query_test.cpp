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
#include <random>
#include <thread>
#include <vector>

#include "async_util.hpp"
#include "collision/cast.hpp"
#include "static_bodies.hpp"

namespace spindle {
namespace {

using namespace std::chrono_literals;

// Four threads query (one also reads contact events) while the runner steps balls
// bouncing in their own columns. Each query is made with the motion-state lock held,
// beside a read of the ball's motion state: the ray straight down its column must meet it
// exactly on top, at the pose read. They query until every ball has landed (a Begin
// event read), the loop took 20 steps and 1,000 queries were made: counted, not timed,
// so a slow or loaded machine only takes longer.
TEST(AsyncQueries, FourThreadsQueryTheStepTheyReadWhileTheRunnerSteps) {
    SpaceSettings settings = test::async_settings();
    settings.gravity = {0, -9.81, 0};
    Space space(settings);
    test::add_ground_plane(space);
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
    std::atomic<int> queries{0}, misses{0}, mismatches{0}, landed{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&, t] {
            int c = t;
            std::vector<ContactEvent> read;
            std::vector<bool> seen_landing(kColumns, false);  // thread 0's only
            while (!stop.load(std::memory_order_relaxed)) {
                if (t == 0) {  // one thread also reads the events as they are published
                    read.clear();
                    space.read_contact_events(read);
                    for (const ContactEvent& e : read) {
                        if (e.kind != ContactEventKind::Begin) continue;
                        for (std::size_t b = 0; b < balls.size(); ++b) {
                            if ((e.body_a == balls[b] || e.body_b == balls[b]) && !seen_landing[b]) {
                                seen_landing[b] = true;
                                landed.fetch_add(1, std::memory_order_relaxed);
                            }
                        }
                    }
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
    const bool done = test::eventually([&] {
        return landed.load() == kColumns && queries.load() > 1000 &&
               space.motion_states().published_steps() - steps_before > 20;
    });
    stop = true;
    for (std::thread& thread : threads) thread.join();
    const std::uint64_t steps_after = space.motion_states().published_steps();
    runner.stop();
    EXPECT_TRUE(done) << "not all of: every ball landed, 1,000 queries, 20 steps";
    EXPECT_GT(queries.load(), 1000);
    EXPECT_EQ(misses.load(), 0);
    EXPECT_EQ(mismatches.load(), 0);
    EXPECT_GT(steps_after - steps_before, 20u);  // the physics loop kept stepping
    EXPECT_EQ(landed.load(), kColumns);          // every ball landed, its Begin event read
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
    for (int flip = 0; flip < 2; ++flip) {  // the scene that was held, too, once it is in front again
        space.update();
        for (int i = 1; i <= 20; ++i) {
            const std::optional<QueryHit> hit = space.cast_ray({-2.0 * i, 5, 0}, {-2.0 * i, -5, 0});
            ASSERT_TRUE(hit) << "flip " << flip << " body " << i;
            EXPECT_EQ(hit->body, made[static_cast<std::size_t>(i - 1)]);
        }
    }
}

// Bodies of three shapes on a grid, drifting and turning, for the first-query tests; their
// shapes by handle for a brute-force pass.
struct Drifters {
    std::vector<BodyHandle> handles;
    std::vector<Shape> shapes;
};

Drifters make_drifters(Space& space) {
    std::mt19937 random(5);
    std::uniform_real_distribution<Real> drift(-0.3, 0.3), spin(-2, 2);
    const Shape kinds[] = {Shape::sphere(0.4), Shape::box({0.4, 0.3, 0.35}), Shape::capsule(0.3, 0.2)};
    Drifters d;
    for (int i = 0; i < 40; ++i) {
        BodyDesc desc = test::ball({2.5 * (i % 8), 0.5 * drift(random), 2.5 * (i / 8)});
        desc.shape = kinds[i % 3];
        desc.linear_velocity = {drift(random), drift(random), drift(random)};
        desc.angular_velocity = {spin(random), spin(random), spin(random)};
        d.handles.push_back(space.create_body(desc));
        d.shapes.push_back(desc.shape);
    }
    return d;
}

// Rays down through the grid, each answered by the space and by a brute-force pass over
// the bodies at the poses get_motion_states reads: the same body at the same fraction,
// bit for bit. The caller makes sure both see one step (a held lock, a posted function,
// or a runner taking no step). Returns the rays that met a body.
int compare_with_brute_force(const Space& space, const Drifters& d, std::mt19937& random, int rays) {
    std::uniform_int_distribution<int> column(0, 7), row(0, 4);
    std::uniform_real_distribution<Real> jitter(-0.3, 0.3);
    std::vector<MotionState> states(d.handles.size());
    space.motion_states().get_motion_states(d.handles, states);
    int hits = 0;
    for (int r = 0; r < rays; ++r) {
        // Near a body's starting column, slanted a little: most meet it, some miss.
        const Vec3 top(2.5 * column(random), 5, 2.5 * row(random));
        const Vec3 from = top + Vec3(jitter(random), 0, jitter(random));
        const Vec3 to = top + Vec3(jitter(random), -10, jitter(random));
        Real best = 2;
        BodyHandle nearest{};
        for (std::size_t k = 0; k < d.handles.size(); ++k) {
            CastHit h;
            if (ray_cast(d.shapes[k], {states[k].position, states[k].orientation}, from, to, h) && h.fraction < best) {
                best = h.fraction;
                nearest = d.handles[k];
            }
        }
        const std::optional<QueryHit> hit = space.cast_ray(from, to);
        EXPECT_EQ(hit.has_value(), best <= 1) << "ray " << r;
        if (!hit) continue;
        EXPECT_EQ(hit->body, nearest) << "ray " << r;
        EXPECT_EQ(hit->fraction, best) << "ray " << r;
        ++hits;
    }
    return hits;
}

// The first query of a space whose runner updates: the game thread may not build the
// scenes (the loop owns the space), so it waits for the next flip to build the one it
// publishes. The runner takes no step meanwhile (time scale 0, still publishing), so
// the query and the reads show one instant whenever each is made.
TEST(AsyncQueries, FirstQueryFromTheGameThreadWhileTheRunnerUpdatesMatchesABruteForcePass) {
    Space space(test::async_settings());
    const Drifters d = make_drifters(space);
    AsyncRunner runner(space);
    runner.start();
    ASSERT_TRUE(test::eventually([&] { return space.motion_states().published_steps() > 10; }));
    runner.set_time_scale(0);
    std::uint64_t steps = 0;
    ASSERT_TRUE(test::eventually([&] {
        const std::uint64_t before = space.motion_states().published_steps();
        std::this_thread::sleep_for(50ms);
        steps = space.motion_states().published_steps();
        return steps == before;
    }));
    std::mt19937 random(3);
    test::finishes_in_time([&] { EXPECT_GT(compare_with_brute_force(space, d, random, 60), 10); });
    EXPECT_EQ(space.motion_states().published_steps(), steps);  // still the same instant
    // Stepping again, the flips keep the scenes: queries under one hold, exact.
    runner.set_time_scale(1);
    for (int round = 0; round < 20; ++round) {
        std::this_thread::sleep_for(10ms);
        std::scoped_lock hold(space.motion_states().lock());
        compare_with_brute_force(space, d, random, 10);
    }
    EXPECT_TRUE(test::eventually([&] { return space.motion_states().published_steps() > steps; }));
    runner.stop();
}

// The first query made while holding the motion-state lock as the runner steps: it cannot
// wait for a flip (the flip waits for its lock), so it builds the scenes while the physics
// thread waits at the flip; the answer is exact for the step the hold shows.
TEST(AsyncQueries, FirstQueryUnderTheLockWhileTheRunnerStepsMatchesABruteForcePass) {
    Space space(test::async_settings());
    const Drifters d = make_drifters(space);
    AsyncRunner runner(space);
    runner.start();
    ASSERT_TRUE(test::eventually([&] { return space.motion_states().published_steps() > 10; }));
    std::mt19937 random(4);
    test::finishes_in_time([&] {
        std::scoped_lock hold(space.motion_states().lock());
        EXPECT_GT(compare_with_brute_force(space, d, random, 60), 10);
    });
    const std::uint64_t steps = space.motion_states().published_steps();
    ASSERT_TRUE(test::eventually([&] { return space.motion_states().published_steps() > steps + 3; }));
    std::scoped_lock hold(space.motion_states().lock());
    compare_with_brute_force(space, d, random, 20);
}

// The first query from a posted function: on the loop thread between updates the space
// may be read, so it builds the scenes itself, at once, while the runner steps.
TEST(AsyncQueries, FirstQueryInAPostedFunctionWhileTheRunnerStepsMatchesABruteForcePass) {
    Space space(test::async_settings());
    const Drifters d = make_drifters(space);
    AsyncRunner runner(space);
    runner.start();
    ASSERT_TRUE(test::eventually([&] { return space.motion_states().published_steps() > 10; }));
    std::mt19937 random(6);
    std::future<int> hits = runner.post([&](Space& s) { return compare_with_brute_force(s, d, random, 60); });
    test::finishes_in_time([&] { EXPECT_GT(hits.get(), 10); });
    const std::uint64_t steps = space.motion_states().published_steps();
    ASSERT_TRUE(test::eventually([&] { return space.motion_states().published_steps() > steps + 3; }));
    std::scoped_lock hold(space.motion_states().lock());
    compare_with_brute_force(space, d, random, 20);
}

}  // namespace
}  // namespace spindle
