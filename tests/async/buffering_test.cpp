// Buffered and internal properties, motion states and their lock (the seed, section 2).
#include <spindle/engine/entity.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include "async_util.hpp"

#include <atomic>
#include <iomanip>
#include <thread>
#include <vector>

using namespace spindle;
using namespace spindle::test;

TEST(Buffering, WriteIsInvisibleUntilTheNextUpdate) {
    Space space(weightless());
    const BodyHandle body = space.create_body(ball(Vec3(0, 0, 0)));
    space.set_position(body, Vec3(5, 0, 0));
    EXPECT_EQ(space.internal_position(body), Vec3(0, 0, 0));
    EXPECT_EQ(space.position(body), Vec3(0, 0, 0));
    space.update();
    EXPECT_EQ(space.internal_position(body), Vec3(5, 0, 0));
    EXPECT_EQ(space.position(body), Vec3(5, 0, 0));
}

TEST(Buffering, LastWriteToAPropertyWins) {
    Space space(weightless());
    const BodyHandle body = space.create_body(ball(Vec3::Zero()));
    space.set_linear_velocity(body, Vec3(1, 0, 0));
    space.set_linear_velocity(body, Vec3(2, 0, 0));
    space.set_position(body, Vec3(1, 1, 1));
    MotionState state;
    state.position = Vec3(7, 0, 0);
    state.linear_velocity = Vec3(0, 3, 0);
    space.set_motion_state(body, state);
    space.set_position(body, Vec3(9, 0, 0));  // after the motion state: the position wins
    space.update();
    EXPECT_NEAR(space.internal_linear_velocity(body).y(), 3.0, 1e-12);
    EXPECT_NEAR(space.internal_linear_velocity(body).x(), 0.0, 1e-12);
    EXPECT_NEAR(space.internal_position(body).x(), 9.0, 1e-12);  // applied before the step; v has no x
}

TEST(Buffering, ReadsReturnThePublishedStepNotTheLiveOne) {
    Space space(weightless());
    const BodyHandle body = space.create_body(ball(Vec3::Zero()));
    space.set_internal_motion_state(body, MotionState{Vec3(3, 0, 0), Quat::Identity(), Vec3::Zero(), Vec3::Zero(), {}});
    EXPECT_EQ(space.internal_position(body).x(), 3.0);
    EXPECT_EQ(space.position(body).x(), 0.0);  // not published until the flip
    space.update();
    EXPECT_EQ(space.position(body).x(), 3.0);
}

TEST(Buffering, StaleHandlesAreReportedEverywhere) {
    Space space(weightless());
    const BodyHandle body = space.create_body(ball(Vec3::Zero()));
    space.update();
    space.destroy_body(body);
    const BodyHandle reused = space.create_body(ball(Vec3(1, 0, 0)));
    EXPECT_EQ(reused.index, body.index);
    EXPECT_NE(reused.generation, body.generation);
    space.update();
    EXPECT_THROW(space.position(body), Error);
    EXPECT_THROW(space.set_position(body, Vec3::Zero()), Error);
    EXPECT_THROW(space.internal_position(body), Error);
    EXPECT_THROW(space.destroy_body(body), Error);
    EXPECT_EQ(space.position(reused), Vec3(1, 0, 0));
    try {
        space.position(body);
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("stale"), std::string::npos) << e.what();
    }
}

TEST(Buffering, WriteToABodyDestroyedBeforeTheUpdateIsReportedNotApplied) {
    Space space(weightless());
    const BodyHandle body = space.create_body(ball(Vec3::Zero()));
    space.set_position(body, Vec3(1, 2, 3));
    space.destroy_body(body);
    space.update();
    EXPECT_EQ(space.last_update().writes_rejected, 1);
    EXPECT_EQ(space.last_update().writes_applied, 0);
}

TEST(Buffering, NanWritesAreRejectedAtOnce) {
    Space space(weightless());
    const BodyHandle body = space.create_body(ball(Vec3::Zero()));
    EXPECT_THROW(space.set_position(body, Vec3(std::nan(""), 0, 0)), Error);
    EXPECT_THROW(space.set_orientation(body, Quat(0, 0, 0, 0)), Error);
    space.update();
    EXPECT_EQ(space.last_update().writes_applied, 0);
}

TEST(Buffering, FourThreadsWritingWhileThePhysicsThreadUpdatesLoseNothing) {
    SpaceSettings settings = weightless();
    settings.solver.max_linear_speed = 1e9;  // the velocity counts the writes: no speed limit in the way
    Space space(settings);
    std::vector<BodyHandle> bodies;
    // Each ball on its own line along x (10 m apart in y): a faster ball never catches up with
    // another, whose contact would trade velocity between them only to within rounding.
    for (int i = 0; i < 8; ++i) bodies.push_back(space.create_body(ball(Vec3(0, 10.0 * i, 0))));
    constexpr int kThreads = 4;
    constexpr int kWritesPerThread = 25000;  // 100k in all
    std::atomic<bool> writing{true};
    std::thread physics([&] {
        while (writing.load()) space.update();
    });
    std::vector<std::thread> writers;
    for (int t = 0; t < kThreads; ++t) {
        writers.emplace_back([&, t] {
            for (int k = 0; k < kWritesPerThread; ++k) {
                // Each write is one unit of impulse on a 1 kg body: lose one and the sum shows it.
                space.apply_impulse(bodies[static_cast<std::size_t>((t * 31 + k) % 8)], Vec3(1, 0, 0));
            }
        });
    }
    for (std::thread& w : writers) w.join();
    writing.store(false);
    physics.join();
    space.update();  // applies whatever arrived after the last update
    double total = 0;
    for (BodyHandle b : bodies) total += space.internal_linear_velocity(b).x();
    EXPECT_EQ(total, kThreads * kWritesPerThread) << std::setprecision(17) << total;
}

TEST(Buffering, ReaderNeverSeesTwoStepsMixed) {
    // Every body follows the same per-step value (x = step * v * dt), so a snapshot
    // with two different x values mixes two steps.
    Space space(weightless());
    std::vector<BodyHandle> bodies;
    for (int i = 0; i < 64; ++i) {
        BodyDesc d = ball(Vec3(0, 2.0 * i, 0), MotionType::Kinematic);
        d.linear_velocity = Vec3(1, 0, 0);
        d.allow_interpolation = false;
        bodies.push_back(space.create_body(d));
    }
    std::atomic<bool> running{true};
    std::atomic<int> snapshots{0}, torn{0};
    std::thread reader([&] {
        std::vector<BodyHandle> handles;
        std::vector<MotionState> states;
        while (running.load()) {
            space.motion_states().get_all_motion_states(handles, states);
            for (const MotionState& s : states) {
                if (s.position.x() != states.front().position.x()) {
                    torn.fetch_add(1);
                    break;
                }
            }
            snapshots.fetch_add(1);
        }
    });
#ifdef SPINDLE_TSAN
    constexpr int kUpdates = 2000;
#else
    constexpr int kUpdates = 10000;
#endif
    for (int i = 0; i < kUpdates; ++i) space.update();
    running.store(false);
    reader.join();
    EXPECT_EQ(torn.load(), 0);
    EXPECT_GT(snapshots.load(), 0);
    EXPECT_NEAR(space.position(bodies[0]).x(), kUpdates / 60.0, 1e-6);
}

TEST(MotionStates, CopiesAllOrListedBodiesAndRejectsStaleHandles) {
    Space space(weightless());
    const BodyHandle a = space.create_body(ball(Vec3(1, 0, 0)));
    const BodyHandle b = space.create_body(ball(Vec3(2, 0, 0)));
    const BodyHandle c = space.create_body(ball(Vec3(3, 0, 0)));
    space.destroy_body(b);
    space.update();
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    EXPECT_EQ(space.motion_states().get_all_motion_states(handles, states), 2u);
    EXPECT_EQ(handles, (std::vector<BodyHandle>{a, c}));
    EXPECT_EQ(states[1].position.x(), 3.0);
    std::vector<MotionState> out(2);
    const BodyHandle listed[] = {c, a};
    space.motion_states().get_motion_states(listed, out);
    EXPECT_EQ(out[0].position.x(), 3.0);
    EXPECT_EQ(out[1].position.x(), 1.0);
    const BodyHandle stale[] = {a, b};
    out[0].position.x() = -1;
    EXPECT_THROW(space.motion_states().get_motion_states(stale, out), Error);
    EXPECT_EQ(out[0].position.x(), -1);  // nothing written
}

TEST(MotionStates, HoldingTheLockKeepsThePhysicsThreadFromFlipping) {
    Space space(weightless());
    BodyDesc d = ball(Vec3::Zero(), MotionType::Kinematic);
    d.linear_velocity = Vec3(1, 0, 0);
    const BodyHandle body = space.create_body(d);
    std::atomic<bool> running{true};
    std::thread physics([&] {
        while (running.load()) space.update();
    });
    bool stable = true;
    for (int round = 0; round < 50; ++round) {
        std::scoped_lock hold(space.motion_states().lock());
        const std::uint64_t steps = space.motion_states().published_steps_locked();
        const MotionState first = space.motion_states().read_locked(body);
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        stable = stable && steps == space.motion_states().published_steps_locked() &&
                 first.position == space.motion_states().read_locked(body).position;
    }
    running.store(false);
    physics.join();
    EXPECT_TRUE(stable);
}

TEST(Buffering, AnEntityOutsideASpaceReadsAndWritesItsOwnValues) {
    Entity body(ball(Vec3(1, 0, 0)));
    EXPECT_FALSE(body.in_space());
    body.set_position(Vec3(2, 0, 0));  // direct: visible at once
    EXPECT_EQ(body.position(), Vec3(2, 0, 0));
    body.set_linear_velocity(Vec3(0, 0, 6));
    EXPECT_EQ(body.linear_velocity(), Vec3(0, 0, 6));

    Space space(weightless());
    body.add_to(space);
    ASSERT_TRUE(body.in_space());
    EXPECT_EQ(body.position(), Vec3(2, 0, 0));
    body.set_position(Vec3(3, 0, 0));  // buffered now: not before the next update
    EXPECT_EQ(body.position(), Vec3(2, 0, 0));
    space.update();
    EXPECT_NEAR(body.position().z(), 0.1, 1e-12);  // 6 m/s for 1/60 s
    EXPECT_EQ(body.position().x(), 3.0);

    body.remove_from_space();  // keeps its live values
    EXPECT_FALSE(body.in_space());
    EXPECT_EQ(space.body_count(), 0u);
    EXPECT_EQ(body.position().x(), 3.0);
    body.set_position(Vec3(4, 0, 0));
    EXPECT_EQ(body.position().x(), 4.0);
}

// get_all_motion_states copies runs of bodies that need no blending and blends the
// rest: between steps, each body it returns equals that body's own read, interpolating
// or not, across a hole where a body was destroyed; at a step boundary all are raw.
TEST(MotionStates, CopyOfAllBlendsExactlyTheBodiesThatInterpolate) {
    Space space(async_settings());
    std::vector<BodyHandle> made;
    for (int i = 0; i < 7; ++i) {
        BodyDesc d = ball(Vec3(i, 0, 0));
        d.linear_velocity = Vec3(1 + i, 0, 0);
        d.angular_velocity = Vec3(0, 0, 2);
        d.allow_interpolation = i % 3 != 1;  // runs of both kinds
        made.push_back(space.create_body(d));
    }
    space.destroy_body(made[3]);
    const Real dt = space.settings().time_step.duration;
    space.update(2.5 * dt);  // alpha 0.5
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    ASSERT_EQ(space.motion_states().get_all_motion_states(handles, states), 6u);
    int blended = 0;
    for (std::size_t k = 0; k < handles.size(); ++k) {
        const MotionState own = space.motion_state(handles[k]);
        EXPECT_EQ(states[k].position, own.position) << k;
        EXPECT_EQ(states[k].orientation.coeffs(), own.orientation.coeffs()) << k;
        EXPECT_EQ(states[k].linear_velocity, own.linear_velocity) << k;
        blended += states[k].position != space.internal_position(handles[k]);
    }
    EXPECT_EQ(blended, 4);  // bodies 0, 2, 5, 6 interpolate (3 was destroyed)
    EXPECT_EQ(handles[3], made[4]);
}

// The same without a hole, where the copy takes all slots at once when nothing blends:
// the handles are the bodies made, in order, and each state is that body's own read,
// blended where the body interpolates and raw where none does.
TEST(MotionStates, CopyOfAllWithoutHolesBlendsOnlyWhereNeeded) {
    for (const bool any_interpolates : {true, false}) {
        Space space(async_settings());
        space.destroy_body(space.create_body(ball(Vec3::Zero())));
        space.update();  // slot 0 is free again: its next body has generation 2
        std::vector<BodyHandle> made;
        for (int i = 0; i < 6; ++i) {
            BodyDesc d = ball(Vec3(i, 0, 0));
            d.linear_velocity = Vec3(1 + i, 0, 0);
            d.angular_velocity = Vec3(0, 0, 2);
            d.allow_interpolation = any_interpolates && i % 2 == 0;
            made.push_back(space.create_body(d));
        }
        const Real dt = space.settings().time_step.duration;
        space.update(2.5 * dt);  // alpha 0.5
        std::vector<BodyHandle> handles;
        std::vector<MotionState> states;
        ASSERT_EQ(space.motion_states().get_all_motion_states(handles, states), 6u);
        EXPECT_EQ(handles, made);
        EXPECT_EQ(made[0].generation, 2u);
        int blended = 0;
        for (std::size_t k = 0; k < handles.size(); ++k) {
            const MotionState own = space.motion_state(made[k]);
            EXPECT_EQ(states[k].position, own.position) << k;
            EXPECT_EQ(states[k].orientation.coeffs(), own.orientation.coeffs()) << k;
            blended += states[k].position != space.internal_position(made[k]);
        }
        EXPECT_EQ(blended, any_interpolates ? 3 : 0);
    }
}

// Creation and destruction publish to both buffers and both query scenes at once, so the
// flips after them copy nothing for those bodies (a world of a million static bodies
// would otherwise be copied twice more); reads and queries still see every body on each
// buffer, and a change outside a step is still published at the next two flips.
TEST(Buffering, CreatedAndDestroyedBodiesAreNotPublishedAgainAtTheFlips) {
    Space space(weightless());
    std::vector<BodyHandle> floor;
    std::vector<BodyHandle> hits;
    EXPECT_EQ(space.overlap_box(Aabb{Vec3(-1, -1, -1), Vec3(1, 1, 1)}, hits), 0u);  // the query scenes exist
    for (int i = 0; i < 40; ++i) {
        BodyDesc d = ball(Vec3(i, 0, 0), MotionType::Static);
        d.user_data = 100 + static_cast<std::uint64_t>(i);
        floor.push_back(space.create_body(d));
    }
    const BodyHandle moving = space.create_body(ball(Vec3(0, 5, 0)));
    space.destroy_body(floor[7]);
    const Aabb everything{Vec3(-10, -10, -10), Vec3(50, 10, 10)};
    for (int flip = 0; flip < 3; ++flip) {
        space.update();
        EXPECT_EQ(space.counters().changed_publishes, 0u) << "flip " << flip;
        EXPECT_FALSE(space.contains(floor[7]));
        for (int i = 0; i < 40; ++i) {
            if (i == 7) continue;
            EXPECT_EQ(space.position(floor[i]), Vec3(i, 0, 0)) << "flip " << flip;
            EXPECT_EQ(space.user_data(floor[i]), 100u + static_cast<std::uint64_t>(i)) << "flip " << flip;
        }
        EXPECT_EQ(space.overlap_box(everything, hits), 40u) << "flip " << flip;  // 39 static and the ball
    }
    EXPECT_EQ(space.position(moving), Vec3(0, 5, 0));

    space.set_position(floor[3], Vec3(3, -4, 0));  // a write: published at the next two flips
    for (int flip = 0; flip < 3; ++flip) {
        space.update();
        EXPECT_EQ(space.position(floor[3]), Vec3(3, -4, 0)) << "flip " << flip;
    }
    EXPECT_EQ(space.counters().changed_publishes, 2u);
}
