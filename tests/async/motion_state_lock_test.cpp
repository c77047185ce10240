// The motion-state lock: a thread holding it can still write and read, and what would
// wait for itself forever (taking it twice, updating under it) throws instead.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include "async_util.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

using namespace spindle;
using namespace spindle::test;

TEST(MotionStateLock, EveryBufferedWriteWorksUnderTheHeldLock) {
    Space space(weightless());
    const BodyHandle body = space.create_body(ball());
    space.update();
    finishes_in_time([&] {
        std::scoped_lock hold(space.motion_states().lock());
        space.set_position(body, Vec3(1, 2, 3));
        space.set_orientation(body, Quat::Identity());
        space.set_linear_velocity(body, Vec3(1, 0, 0));
        space.set_angular_velocity(body, Vec3(0, 1, 0));
        space.set_motion_state(body, MotionState{Vec3(4, 5, 6), Quat::Identity(), Vec3(2, 0, 0), Vec3::Zero()});
        space.add_force(body, Vec3(0, 0, 1));
        space.add_torque(body, Vec3(0, 0, 1));
        space.apply_impulse(body, Vec3(1, 0, 0));
        space.apply_angular_impulse(body, Vec3(0, 0, 1));
        space.wake(body);
    });
    space.flush();
    EXPECT_EQ(space.last_update().writes_applied, 10);
    EXPECT_EQ(space.position(body), Vec3(4, 5, 6));
    EXPECT_EQ(space.linear_velocity(body).x(), 3.0);
}

TEST(MotionStateLock, StaleHandlesAreStillRejectedWithoutTheLock) {
    Space space(weightless());
    // Past the first block of slots of the lock-free generation table.
    std::vector<BodyHandle> bodies;
    for (int i = 0; i < 1500; ++i) bodies.push_back(space.create_body(ball()));
    const BodyHandle old = bodies[1400];
    space.destroy_body(old);
    const BodyHandle reused = space.create_body(ball());
    ASSERT_EQ(reused.index, old.index);
    finishes_in_time([&] {
        std::scoped_lock hold(space.motion_states().lock());
        EXPECT_THROW(space.apply_impulse(old, Vec3(1, 0, 0)), Error);
        EXPECT_THROW(space.set_position(BodyHandle{reused.index, 0}, Vec3::Zero()), Error);
        EXPECT_NO_THROW(space.apply_impulse(reused, Vec3(1, 0, 0)));
        EXPECT_NO_THROW(space.apply_impulse(bodies[1499], Vec3(1, 0, 0)));
    });
    space.flush();
    EXPECT_EQ(space.last_update().writes_applied, 2);
    EXPECT_EQ(space.linear_velocity(reused).x(), 1.0);
}

TEST(MotionStateLock, ReadsUnderTheHeldLockReadTheHeldStep) {
    SpaceSettings settings = weightless();
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    BodyDesc moving = ball();
    moving.linear_velocity = Vec3(1, 0, 0);
    const BodyHandle body = space.create_body(moving);
    AsyncRunner runner(space);
    runner.start();
    finishes_in_time([&] {
        std::scoped_lock hold(space.motion_states().lock());
        const MotionStateManager& states = space.motion_states();
        const std::uint64_t steps = states.published_steps_locked();
        const MotionState held = states.read_locked(body);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the loop would flip meanwhile
        EXPECT_EQ(space.position(body), held.position);
        EXPECT_EQ(space.motion_state(body).linear_velocity, held.linear_velocity);
        EXPECT_EQ(states.published_steps(), steps);
        std::vector<BodyHandle> handles;
        std::vector<MotionState> all;
        EXPECT_EQ(states.get_all_motion_states(handles, all), 1u);
        EXPECT_EQ(all[0].position, held.position);
        MotionState one;
        states.get_raw_motion_states(std::span<const BodyHandle>(&body, 1), std::span<MotionState>(&one, 1));
        EXPECT_EQ(one.linear_velocity, held.linear_velocity);
    });
    runner.stop();
}

TEST(MotionStateLock, TakingItTwiceOnOneThreadThrows) {
    Space space(weightless());
    MotionStateLock& lock = space.motion_states().lock();
    finishes_in_time([&] {
        std::scoped_lock hold(lock);
        EXPECT_TRUE(lock.held_by_this_thread());
        EXPECT_THROW(lock.lock(), Error);
        EXPECT_THROW((void)lock.try_lock(), Error);
        bool other_got_it = true;
        std::thread([&] {
            EXPECT_FALSE(lock.held_by_this_thread());
            other_got_it = lock.try_lock();
        }).join();
        EXPECT_FALSE(other_got_it);
    });
    EXPECT_FALSE(lock.held_by_this_thread());
    EXPECT_TRUE(lock.try_lock());
    lock.unlock();
}

TEST(MotionStateLock, UpdateUnderTheHeldLockThrowsAndChangesNothing) {
    Space space(weightless());
    BodyDesc moving = ball();
    moving.linear_velocity = Vec3(1, 0, 0);
    const BodyHandle body = space.create_body(moving);
    space.apply_impulse(body, Vec3(1, 0, 0));
    finishes_in_time([&] {
        std::scoped_lock hold(space.motion_states().lock());
        EXPECT_THROW(space.update(1.0 / 60), Error);
        EXPECT_THROW(space.update(), Error);
        EXPECT_THROW(space.flush(), Error);
    });
    EXPECT_EQ(space.counters().steps, 0u);
    EXPECT_EQ(space.internal_linear_velocity(body).x(), 1.0);  // the impulse still waits in the buffer
    space.update();
    EXPECT_EQ(space.internal_linear_velocity(body).x(), 2.0);
}

TEST(MotionStateLock, CreateAndDestroyUnderTheHeldLockPublishAtOnce) {
    Space space(weightless());
    finishes_in_time([&] {
        std::scoped_lock hold(space.motion_states().lock());
        BodyDesc d = ball();
        d.position = Vec3(1, 2, 3);
        const BodyHandle body = space.create_body(d);
        EXPECT_EQ(space.position(body), Vec3(1, 2, 3));
        space.destroy_body(body);
        EXPECT_THROW(space.position(body), Error);
    });
}
