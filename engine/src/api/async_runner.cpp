// AsyncRunner: the physics loop thread, its clean stop, what it does with exceptions,
// and its statistics.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/assert.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/thread.hpp>

#include "world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace spindle {
namespace {

constexpr std::size_t kSamples = 1 << 14;

double percentile(std::vector<float> values, double p) {
    if (values.empty()) return 0;
    const auto k = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    return values[k];
}

}  // namespace

AsyncRunner::AsyncRunner(Space& space, AsyncRunnerOptions options) : m_space(space), m_options(std::move(options)) {
    m_update_samples.reserve(kSamples);
    m_lock_samples.reserve(kSamples);
}

AsyncRunner::~AsyncRunner() {
    if (!m_thread.joinable()) return;
    std::string why = "AsyncRunner::stop failed";
    try {
        stop();
    } catch (const std::exception& e) {
        why = e.what();
    } catch (...) {
    }
    // stop() returns with the thread still running only where stopping would deadlock
    // (see stop()); a destructor cannot throw, and a joinable std::thread would
    // terminate without a word, so say why.
    if (m_thread.joinable())
        assert_failed("AsyncRunner destroyed while it could not stop", why.c_str(), __FILE__, __LINE__);
}

void AsyncRunner::start() {
    if (m_thread.joinable()) throw Error("AsyncRunner::start: already started (call stop() first)");
    m_stop.store(false);
    std::promise<void> started;
    std::future<void> ready = started.get_future();
    m_thread = std::thread([this, &started] { loop(&started); });
    try {
        ready.get();  // rethrows a pinning error from the loop thread
    } catch (...) {
        m_thread.join();
        throw;
    }
}

void AsyncRunner::stop() {
    // Checked before anything changes, so the runner keeps running after these errors.
    if (m_loop_thread.load(std::memory_order_acquire) == std::this_thread::get_id()) {
        throw Error("AsyncRunner::stop: called on the physics loop thread (from a posted function); "
                    "it would wait for itself");
    }
    if (!m_thread.joinable()) return;
    if (m_space.motion_states().lock().held_by_this_thread()) {
        throw Error("AsyncRunner::stop: this thread holds the motion-state lock, which the loop's flip waits for; "
                    "release it first");
    }
    m_stop.store(true, std::memory_order_release);
    m_thread.join();
    m_running.store(false, std::memory_order_release);
    // The loop is gone: this thread may now update. Run what was posted, then apply
    // and publish the writes that arrived after the loop's last update; the loop's
    // failure, if any, after that, so no write is lost to it.
    std::vector<std::function<void(Space&)>> posted;
    std::exception_ptr failure;
    {
        std::scoped_lock guard(m_posted_lock);
        posted.swap(m_posted);
        failure = std::exchange(m_failure, nullptr);
    }
    run_posted(posted);
    try {
        m_space.flush();
    } catch (...) {
        if (!failure) throw;  // the loop's failure came first; report that one
    }
    if (failure) std::rethrow_exception(failure);
}

void AsyncRunner::set_time_scale(double scale) {
    if (!std::isfinite(scale) || scale < 0) {
        throw Error("AsyncRunner::set_time_scale: the scale must be finite and >= 0, got " + std::to_string(scale));
    }
    m_time_scale.store(scale, std::memory_order_relaxed);
}

void AsyncRunner::advance(double seconds) {
    if (!std::isfinite(seconds) || seconds < 0) {
        throw Error("AsyncRunner::advance: the time must be finite and >= 0 seconds, got " + std::to_string(seconds));
    }
    double pending = m_advance.load(std::memory_order_relaxed);
    do {
        if (!std::isfinite(pending + seconds)) {
            throw Error("AsyncRunner::advance: " + std::to_string(seconds) +
                        " s more would make the time not yet taken infinite");
        }
    } while (!m_advance.compare_exchange_weak(pending, pending + seconds, std::memory_order_relaxed));
}

void AsyncRunner::enqueue(std::function<void(Space&)> fn) {
    std::scoped_lock guard(m_posted_lock);
    if (m_failure) std::rethrow_exception(m_failure);
    m_posted.push_back(std::move(fn));
}

// Each posted function wraps a packaged_task, which keeps fn's exception for its future.
void AsyncRunner::run_posted(std::vector<std::function<void(Space&)>>& posted) {
    for (auto& fn : posted) fn(m_space);
    posted.clear();
}

void AsyncRunner::rethrow_failure() const {
    std::scoped_lock guard(m_posted_lock);
    if (m_failure) std::rethrow_exception(m_failure);
}

void AsyncRunner::loop(std::promise<void>* started) {
    try {
        set_current_thread_name(m_options.thread_name);
        if (m_options.physics_pu) pin_current_thread(*m_options.physics_pu);
    } catch (...) {
        started->set_exception(std::current_exception());
        return;
    }
    m_loop_thread.store(std::this_thread::get_id(), std::memory_order_release);
    // From here to the loop's end, structural calls from other threads throw (post them).
    m_space.m_world->gate.claim(std::this_thread::get_id());
    m_running.store(true, std::memory_order_release);
    started->set_value();

    std::vector<std::function<void(Space&)>> posted;
    Stopwatch since_last;  // the time at the start of each iteration, as the seed asks
    const Stopwatch total;
    try {
        while (!m_stop.load(std::memory_order_acquire)) {
            const double elapsed = since_last.lap();
            // The instant dt runs to: the banked time's clock, for reads that blend by theirs.
            m_space.m_world->update_clock_ns = since_last.started_nanoseconds();
            m_space.m_world->read_blend = m_options.blend_clock;
            {
                std::scoped_lock guard(m_posted_lock);
                posted.swap(m_posted);
            }
            run_posted(posted);
            // The scale is read after the posted functions: one posted after set_time_scale
            // runs in an iteration whose update already takes the new scale.
            const double scale = m_time_scale.load(std::memory_order_relaxed);
            // Each term is finite (set_time_scale and advance check theirs), their sum need
            // not be: saturated as update() saturates its accumulator, a sum past the
            // largest double is just "too much" (the step cap drops it), not a failure.
            const double dt = std::min(elapsed * scale + m_advance.exchange(0, std::memory_order_relaxed), kHuge);
            m_space.m_world->update_clock_rate = scale;

            const std::int64_t begin = now_nanoseconds();
            m_space.update(dt);
            const double update_seconds = static_cast<double>(now_nanoseconds() - begin) * 1e-9;
            // The settings are read here, on the loop thread that changes them, never by stats().
            const TimeStepSettings& ts = m_space.settings().time_step;
            const UpdateStats& u = m_space.last_update();
            record(update_seconds, u.flip_lock_seconds, u.steps, u.dropped_seconds / ts.duration);
            {
                std::scoped_lock guard(m_stats_lock);
                m_totals.seconds = total.elapsed_seconds();
            }

            if (m_options.sleep_when_idle && ts.use_internal_time_stepping) {
                // Sleep until the next step is due (what is banked subtracts from it), on
                // the scaled clock; at most a step's real time, so that posted functions and
                // advance() wait no longer in slow motion or a pause than at full speed.
                const double banked = ts.duration - m_space.accumulated_time();
                const double due = std::min(scale > 0 ? banked / scale : ts.duration, ts.duration) -
                                   since_last.elapsed_seconds();
                if (due > 0) std::this_thread::sleep_for(std::chrono::duration<double>(due));
            }
        }
    } catch (...) {
        // An update failed: end the loop and keep the exception for the game's next
        // stats(), post() or stop(). Buffered writes not yet applied stay in the buffer.
        std::scoped_lock guard(m_posted_lock);
        m_failure = std::current_exception();
    }
    m_space.m_world->gate.claim(std::thread::id{});
    // Later updates (stop's flush, the game's own) follow no clock.
    m_space.m_world->update_clock_ns = 0;
    m_space.m_world->update_clock_rate = 1;
    m_space.m_world->read_blend = BlendClock::Update;
    m_running.store(false, std::memory_order_release);
    m_loop_thread.store(std::thread::id{}, std::memory_order_release);
}

void AsyncRunner::record(double update_seconds, double lock_seconds, int steps, double dropped_steps) {
    std::scoped_lock guard(m_stats_lock);
    m_totals.updates += 1;
    m_totals.steps += static_cast<std::uint64_t>(steps);
    m_dropped_steps += dropped_steps;
    const auto ms = static_cast<float>(update_seconds * 1e3);
    const auto us = static_cast<float>(lock_seconds * 1e6);
    if (steps > 0) {
        if (m_update_samples.size() < kSamples) {
            m_update_samples.push_back(ms);
            m_lock_samples.push_back(us);
        } else {
            m_update_samples[m_next_sample] = ms;
            m_lock_samples[m_next_sample] = us;
            m_next_sample = (m_next_sample + 1) % kSamples;
        }
    }
}

AsyncStats AsyncRunner::stats() const {
    rethrow_failure();
    std::vector<float> updates, locks;
    AsyncStats s;
    {
        std::scoped_lock guard(m_stats_lock);
        s = m_totals;
        updates = m_update_samples;
        locks = m_lock_samples;
        // Saturated: a huge time scale or advance drops more steps than 64 bits count.
        constexpr double kCountable = 18446744073709551616.0;  // 2^64
        s.steps_dropped = m_dropped_steps >= kCountable ? std::numeric_limits<std::uint64_t>::max()
                                                        : static_cast<std::uint64_t>(std::round(m_dropped_steps));
    }
    s.steps_per_second = s.seconds > 0 ? static_cast<double>(s.steps) / s.seconds : 0;
    s.update_ms_p50 = percentile(updates, 0.5);
    s.update_ms_p99 = percentile(updates, 0.99);
    s.update_ms_max = updates.empty() ? 0 : *std::max_element(updates.begin(), updates.end());
    s.lock_us_p50 = percentile(locks, 0.5);
    s.lock_us_p99 = percentile(locks, 0.99);
    s.lock_us_max = locks.empty() ? 0 : *std::max_element(locks.begin(), locks.end());
    return s;
}

}  // namespace spindle
