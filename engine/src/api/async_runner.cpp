// AsyncRunner: the physics loop thread, its clean stop, and its statistics.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/thread.hpp>

#include <algorithm>
#include <chrono>

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
    if (m_thread.joinable()) stop();
}

void AsyncRunner::start() {
    if (m_thread.joinable()) throw Error("AsyncRunner::start: already running");
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
    if (!m_thread.joinable()) return;
    m_stop.store(true, std::memory_order_release);
    m_thread.join();
    m_running.store(false, std::memory_order_release);
    // The loop is gone: this thread may now update. Run what was posted, then apply
    // and publish the writes that arrived after the loop's last update.
    std::vector<std::function<void(Space&)>> posted;
    {
        std::scoped_lock guard(m_posted_lock);
        posted.swap(m_posted);
    }
    for (auto& fn : posted) fn(m_space);
    m_space.flush();
}

void AsyncRunner::post(std::function<void(Space&)> fn) {
    std::scoped_lock guard(m_posted_lock);
    m_posted.push_back(std::move(fn));
}

void AsyncRunner::loop(std::promise<void>* started) {
    try {
        set_current_thread_name(m_options.thread_name);
        if (m_options.physics_pu) pin_current_thread(*m_options.physics_pu);
    } catch (...) {
        started->set_exception(std::current_exception());
        return;
    }
    m_running.store(true, std::memory_order_release);
    started->set_value();

    std::vector<std::function<void(Space&)>> posted;
    Stopwatch since_last;  // the time at the start of each iteration, as the seed asks
    const Stopwatch total;
    while (!m_stop.load(std::memory_order_acquire)) {
        const double dt = since_last.lap();
        {
            std::scoped_lock guard(m_posted_lock);
            posted.swap(m_posted);
        }
        for (auto& fn : posted) fn(m_space);
        posted.clear();

        const std::int64_t begin = now_nanoseconds();
        m_space.update(dt);
        const double update_seconds = static_cast<double>(now_nanoseconds() - begin) * 1e-9;
        const UpdateStats& u = m_space.last_update();
        record(update_seconds, u.flip_lock_seconds, u.steps, u.dropped_seconds);
        {
            std::scoped_lock guard(m_stats_lock);
            m_totals.seconds = total.elapsed_seconds();
        }

        const TimeStepSettings& ts = m_space.settings().time_step;
        if (m_options.sleep_when_idle && ts.use_internal_time_stepping) {
            // Sleep until the next step is due (what is banked subtracts from it).
            const double due = ts.duration - m_space.accumulated_time() - since_last.elapsed_seconds();
            if (due > 0) std::this_thread::sleep_for(std::chrono::duration<double>(due));
        }
    }
}

void AsyncRunner::record(double update_seconds, double lock_seconds, int steps, double dropped_seconds) {
    std::scoped_lock guard(m_stats_lock);
    m_totals.updates += 1;
    m_totals.steps += static_cast<std::uint64_t>(steps);
    m_dropped_seconds += dropped_seconds;
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
    std::vector<float> updates, locks;
    AsyncStats s;
    {
        std::scoped_lock guard(m_stats_lock);
        s = m_totals;
        updates = m_update_samples;
        locks = m_lock_samples;
        s.steps_dropped = static_cast<std::uint64_t>(m_dropped_seconds / m_space.settings().time_step.duration + 0.5);
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
