// AsyncRunner: owns the physics loop thread (the seed, section 1.B). The thread pins
// itself to the layout's physics hardware thread, records the time at the start of
// every iteration and passes the elapsed time to Space::update(dt).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace spindle {

class Space;

struct AsyncRunnerOptions {
    std::optional<unsigned> physics_pu;  // real PU (OS index) to pin the loop to; none: unpinned
    std::string thread_name = "spindle-physics";
    // With internal time stepping, sleep until the next step is due instead of
    // spinning through updates that take no step (they would only re-publish).
    bool sleep_when_idle = true;
};

struct AsyncStats {
    std::uint64_t updates = 0;
    std::uint64_t steps = 0;
    std::uint64_t steps_dropped = 0;  // whole steps' worth of time dropped by the cap
    double seconds = 0;               // wall time the loop has run
    double steps_per_second = 0;
    double update_ms_p50 = 0, update_ms_p99 = 0, update_ms_max = 0;  // updates that took a step
    double lock_us_p50 = 0, lock_us_p99 = 0, lock_us_max = 0;        // flip's hold of the motion-state lock
};

class AsyncRunner {
public:
    // The space must outlive the runner. Nothing runs until start().
    explicit AsyncRunner(Space& space, AsyncRunnerOptions options = {});
    // Stops (as stop()) if running.
    ~AsyncRunner();
    AsyncRunner(const AsyncRunner&) = delete;
    AsyncRunner& operator=(const AsyncRunner&) = delete;

    // Starts the physics loop thread. Who may call: the owner thread. Throws
    // spindle::Error if already running or the PU cannot be pinned (reported from the
    // new thread before start() returns).
    void start();
    // Ends the loop, joins the thread, then applies and publishes every buffered write
    // made before the call (Space::flush), so none is lost; writes to destroyed bodies
    // are counted in Space::last_update().writes_rejected. Who may call: the owner
    // thread. Deadlock: calling it from a function passed to post() (the loop thread).
    void stop();
    bool running() const noexcept { return m_running.load(std::memory_order_acquire); }

    // Runs fn on the physics loop thread before its next update (structural changes
    // such as create_body while running). Any thread. fn must not call stop().
    void post(std::function<void(Space&)> fn);

    // Any thread.
    AsyncStats stats() const;

private:
    void loop(std::promise<void>* started);
    void record(double update_seconds, double lock_seconds, int steps, double dropped_seconds);

    Space& m_space;
    AsyncRunnerOptions m_options;
    std::thread m_thread;
    std::atomic<bool> m_running{false};
    std::atomic<bool> m_stop{false};

    std::mutex m_posted_lock;
    std::vector<std::function<void(Space&)>> m_posted;

    mutable std::mutex m_stats_lock;
    AsyncStats m_totals;
    std::vector<float> m_update_samples;  // ms, ring of the last kSamples
    std::vector<float> m_lock_samples;    // us
    std::size_t m_next_sample = 0;
    double m_dropped_seconds = 0;
};

}  // namespace spindle
