// AsyncRunner: owns the physics loop thread (the seed, section 1.B). The thread pins
// itself to the layout's physics hardware thread, records the time at the start of
// every iteration and passes the elapsed time to Space::update(dt).
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include <spindle/engine/motion_state_manager.hpp>

namespace spindle {

class Space;

struct AsyncRunnerOptions {
    std::optional<unsigned> physics_pu;  // real PU (OS index) to pin the loop to; none: unpinned
    std::string thread_name = "spindle-physics";
    // With internal time stepping, sleep until the next step is due instead of
    // spinning through updates that take no step (they would only re-publish).
    bool sleep_when_idle = true;
    // Where reads without a clock of their own take the blend from (motion_state_manager.hpp):
    // Read lets interpolated motion move on between updates at the real rate; Update is
    // the seed's blend, fixed from one flip to the next.
    BlendClock blend_clock = BlendClock::Read;
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

// Failures. Nothing a posted function or Space::update throws ends the process:
//  - a posted function's exception goes to the future post() returned; the loop goes on;
//  - an exception from Space::update ends the loop (running() turns false). Writes made
//    before it stay in the write buffer or the live state; none is dropped. Until stop(),
//    stats() and post() throw it; stop() finishes the stop (runs what was posted,
//    flushes) and then throws it, once. The destructor never throws (it drops a failure
//    nobody asked for; call stop() to see it).
class AsyncRunner {
public:
    // The space must outlive the runner. Nothing runs until start().
    explicit AsyncRunner(Space& space, AsyncRunnerOptions options = {});
    // Stops (as stop()) if started, swallowing what stop() would throw. Who may call:
    // the owner thread, not holding the motion-state lock (stopping would wait for the
    // loop's flip, which waits for that lock: it aborts with a message instead).
    ~AsyncRunner();
    AsyncRunner(const AsyncRunner&) = delete;
    AsyncRunner& operator=(const AsyncRunner&) = delete;

    // Starts the physics loop thread. Who may call: the owner thread. Throws
    // spindle::Error if already started (after a failure too: stop() first) or the PU
    // cannot be pinned (reported from the new thread before start() returns).
    void start();
    // Ends the loop, joins the thread, runs what was posted and not yet run (on this
    // thread), then applies and publishes every buffered write made before the call
    // (Space::flush), so none is lost; writes to destroyed bodies are counted in
    // Space::last_update().writes_rejected. Then throws the loop's failure, if any.
    // Who may call: the owner thread. Waits for: the loop's current iteration (an
    // update, posted functions). Throws spindle::Error instead of deadlocking when
    // called from the loop thread (a posted function) or by a thread holding the
    // motion-state lock (the loop's flip waits for it); the runner keeps running then.
    void stop();
    bool running() const noexcept { return m_running.load(std::memory_order_acquire); }

    // Runs fn(space) on the physics loop thread before its next update (structural
    // changes such as create_body while running) and returns a future of its result or
    // of the exception it threw. Any thread, the loop thread included (fn runs at the
    // next iteration). Functions posted before start() run at the first iteration;
    // those still queued at stop() run in stop() on the stopping thread; those posted
    // after stop() wait for the next start() (destroying the runner breaks their
    // futures: std::future_error, broken_promise). Throws the loop's failure until
    // stop(). Deadlock: waiting on the future on the loop thread (fn runs only after
    // the caller returns), or while holding the motion-state lock (the loop may be in
    // its flip, waiting for that lock, before it gets to fn).
    template <typename F>
    auto post(F&& fn) -> std::future<std::invoke_result_t<F&, Space&>> {
        using Result = std::invoke_result_t<F&, Space&>;
        auto task = std::make_shared<std::packaged_task<Result(Space&)>>(std::forward<F>(fn));
        std::future<Result> result = task->get_future();
        enqueue([task](Space& space) { (*task)(space); });  // the task keeps fn's exception
        return result;
    }

    // Simulated seconds per real second: below 1 slow motion, 0 a pause (the loop goes on
    // running posted functions and publishing, taking no step), above 1 faster than real
    // time (the update's step cap still drops what it cannot take). Reads blending by the
    // reader's clock move on at the same rate (PublishedTime::clock_rate). Any thread,
    // before or after start(); the loop's next iteration runs at it, and a function posted
    // after the call runs in an iteration whose update does: once its future is ready no
    // update at the old scale is left (after set_time_scale(0): no step). Throws spindle::Error
    // naming the value if it is NaN, infinite or negative (the scale is left as it was).
    void set_time_scale(double scale);
    double time_scale() const noexcept { return m_time_scale.load(std::memory_order_relaxed); }
    // Adds simulated seconds to the next update on top of the scaled clock: while paused,
    // advance(step duration) takes exactly one step. Any thread; never waits for the loop.
    // Throws spindle::Error naming the value if it is NaN, infinite or negative, or if the
    // time not yet taken would no longer be finite (nothing is added then).
    void advance(double seconds);

    // Totals and latencies so far. Any thread; reads only the runner's own copies, taken
    // by the loop under its stats lock (never the space, which the loop is changing).
    // Throws the loop's failure until stop().
    AsyncStats stats() const;

private:
    void enqueue(std::function<void(Space&)> fn);
    void run_posted(std::vector<std::function<void(Space&)>>& posted);
    void rethrow_failure() const;
    void loop(std::promise<void>* started);
    void record(double update_seconds, double lock_seconds, int steps, double dropped_steps);

    Space& m_space;
    AsyncRunnerOptions m_options;
    std::thread m_thread;
    std::atomic<std::thread::id> m_loop_thread{};  // while the loop runs
    std::atomic<bool> m_running{false};
    std::atomic<bool> m_stop{false};
    std::atomic<double> m_time_scale{1};
    std::atomic<double> m_advance{0};  // simulated seconds the next update takes besides the clock's

    // Posted functions (each wraps a packaged_task, so running one never throws), and
    // the exception that ended the loop, under one lock.
    mutable std::mutex m_posted_lock;
    std::vector<std::function<void(Space&)>> m_posted;
    std::exception_ptr m_failure;

    mutable std::mutex m_stats_lock;
    AsyncStats m_totals;
    std::vector<float> m_update_samples;  // ms, ring of the last kSamples
    std::vector<float> m_lock_samples;    // us
    std::size_t m_next_sample = 0;
    double m_dropped_steps = 0;  // each update's dropped time over the step duration it ran with
};

}  // namespace spindle
