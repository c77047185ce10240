// PhysicsProbe: per-update stats gathered on the physics loop thread.
#include "physics_probe.hpp"

#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>

#include <chrono>
#include <thread>

namespace spindle::app {

void PhysicsProbe::attach(AsyncRunner& runner, double min_interval) {
    m_min_interval = min_interval;
    post(runner);
}

void PhysicsProbe::post(AsyncRunner& runner) {
    // Re-posting from inside a posted function is safe: the loop runs posted functions
    // after taking them out of the runner's queue, without holding its lock.
    runner.post([this, &runner](Space& space) {
        sample(space.last_update());
        if (m_min_interval > 0 && runner.running()) {
            const double wait = m_min_interval - static_cast<double>(now_nanoseconds() - m_last_ns) * 1e-9;
            if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
            m_last_ns = now_nanoseconds();
        }
        post(runner);
    });
}

void PhysicsProbe::sample(const UpdateStats& stats) {
    double seconds = 0;
    for (std::size_t i = 0; i < stats.stage_seconds.size(); ++i) {
        m_totals.stage_seconds[i] += stats.stage_seconds[i];
        m_window_seconds[i] += stats.stage_seconds[i];
        seconds += stats.stage_seconds[i];
    }
    m_window_steps += static_cast<std::uint64_t>(stats.steps);
    constexpr std::int64_t kWindowNs = 500'000'000;
    const std::int64_t now = now_nanoseconds();
    if (now - m_window_start_ns >= kWindowNs && m_window_steps > 0) {
        for (std::size_t i = 0; i < m_window_seconds.size(); ++i) {
            m_recent_stage_ms[i].store(m_window_seconds[i] * 1e3 / static_cast<double>(m_window_steps),
                                       std::memory_order_relaxed);
            m_window_seconds[i] = 0;
        }
        m_window_steps = 0;
        m_window_start_ns = now;
    }
    m_totals.updates += 1;
    m_totals.steps += static_cast<std::uint64_t>(stats.steps);
    m_totals.dropped_seconds += stats.dropped_seconds;
    m_awake.store(stats.awake_bodies, std::memory_order_relaxed);
    if (stats.steps > 0) {  // contacts are counted by steps; an update without one reports none
        m_contacts.store(stats.contacts, std::memory_order_relaxed);
        m_update_ms.store(seconds * 1e3, std::memory_order_relaxed);
    }
}

}  // namespace spindle::app
