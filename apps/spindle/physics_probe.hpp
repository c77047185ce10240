// PhysicsProbe: what each physics update did, read where it is safe to read.
// Space::last_update() belongs to the physics loop thread, so the probe reads it there:
// a function posted to the AsyncRunner runs before every update, reads the previous
// update's stats, and posts itself again. The game thread sees a few live values
// through atomics; the totals are read after AsyncRunner::stop() (which runs the last
// posted function, so the final update is counted too, and joins the thread).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/stats.hpp>

namespace spindle::app {

struct ProbeTotals {
    std::array<double, static_cast<int>(Stage::Count)> stage_seconds{};
    std::uint64_t updates = 0;
    std::uint64_t steps = 0;
    double dropped_seconds = 0;
};

class PhysicsProbe {
public:
    // Starts probing; call before runner.start(). The probe must outlive the runner's loop.
    void attach(AsyncRunner& runner);

    // Any thread, while running.
    std::uint32_t awake_bodies() const noexcept { return m_awake.load(std::memory_order_relaxed); }
    std::uint32_t contacts() const noexcept { return m_contacts.load(std::memory_order_relaxed); }
    double last_step_update_ms() const noexcept { return m_update_ms.load(std::memory_order_relaxed); }

    // After AsyncRunner::stop() only.
    const ProbeTotals& totals() const noexcept { return m_totals; }

private:
    void sample(const UpdateStats& stats);

    ProbeTotals m_totals;  // physics loop thread only, until stop()
    std::atomic<std::uint32_t> m_awake{0};
    std::atomic<std::uint32_t> m_contacts{0};
    std::atomic<double> m_update_ms{0};
};

}  // namespace spindle::app
