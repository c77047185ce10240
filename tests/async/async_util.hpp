// Helpers the asynchronous suites share: a weightless space that never sleeps (so
// written velocities stay as written), a 1 kg ball, a poll with a hang's deadline, and a
// watchdog for would-be deadlocks.
#pragma once

#include <spindle/engine/space.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <thread>
#include <utility>

namespace spindle::test {

inline SpaceSettings weightless() {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    return s;
}

// weightless(), stepped by elapsed time (as an AsyncRunner does).
inline SpaceSettings async_settings() {
    SpaceSettings s = weightless();
    s.time_step.use_internal_time_stepping = true;
    return s;
}

inline BodyDesc ball(const Vec3& position = Vec3::Zero(), MotionType type = MotionType::Dynamic) {
    BodyDesc d;
    d.type = type;
    d.position = position;
    d.shape = Shape::sphere(0.25);
    d.mass = 1;
    return d;
}

// How long a wait may last before it counts as a hang: a bound that only turns a hang
// into a failure (a loaded TSan run may take many times a quiet one's time).
inline constexpr std::chrono::seconds kHang{60};

// Polls until pred() holds; false if it still does not after kHang.
template <typename Pred>
bool eventually(Pred pred) {
    const auto deadline = std::chrono::steady_clock::now() + kHang;
    while (!pred()) {
        if (std::chrono::steady_clock::now() > deadline) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return true;
}

// Runs fn on its own thread and fails the test if it has not finished in time. A
// thread stuck on a lock cannot be recovered, so a deadlock ends the test program.
template <typename F>
void finishes_in_time(F fn) {
    std::packaged_task<void()> task(std::move(fn));
    std::future<void> done = task.get_future();
    std::thread(std::move(task)).detach();
    if (done.wait_for(kHang) != std::future_status::ready) {
        std::fprintf(stderr, "deadlock: not finished within %lld s\n", static_cast<long long>(kHang.count()));
        std::_Exit(1);
    }
    done.get();  // rethrows what fn threw
}

}  // namespace spindle::test
