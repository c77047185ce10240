// PhysicsProbe: what each physics update did, read where it is safe to read, and
// (optionally) the pace of the physics loop between steps.
// Space::last_update() belongs to the physics loop thread, so the probe reads it there:
// a function posted to the AsyncRunner runs before every update, reads the previous
// update's stats, and posts itself again. The game thread sees a few live values
// through atomics; the totals are read after AsyncRunner::stop() (which runs the last
// posted function, so the final update is counted too, and joins the thread).
// Pacing: a loop that never sleeps publishes hundreds of thousands of updates a second
// and burns a hardware thread; the same function can hold the loop to one update per
// `min_interval` (a few per frame are all interpolation needs). AsyncRunnerOptions has
// no such knob, so it lives here.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/stats.hpp>

namespace spindle::app {

// `run --idle poll` (and `view`): the physics loop updates at most this often between
// steps. A frame at 60 Hz then sees a publish at most 0.5 ms old (3% of the frame), for
// a few percent of a hardware thread instead of all of it.
inline constexpr double kPollInterval = 0.5e-3;

struct ProbeTotals {
    std::array<double, static_cast<int>(Stage::Count)> stage_seconds{};
    std::uint64_t updates = 0;
    std::uint64_t steps = 0;
    double dropped_seconds = 0;
};

class PhysicsProbe {
public:
    // Starts probing; call before runner.start(). The probe must outlive the runner's
    // loop. min_interval > 0: no update starts sooner than that after the previous one.
    void attach(AsyncRunner& runner, double min_interval = 0);

    // Any thread, while running.
    std::uint32_t awake_bodies() const noexcept { return m_awake.load(std::memory_order_relaxed); }
    std::uint32_t contacts() const noexcept { return m_contacts.load(std::memory_order_relaxed); }
    double last_step_update_ms() const noexcept { return m_update_ms.load(std::memory_order_relaxed); }
    // Milliseconds per step a stage took, over the last half second or so of updates
    // (a live panel's figure: one update's steps are too few to read).
    double recent_stage_ms(Stage stage) const noexcept {
        return m_recent_stage_ms[static_cast<std::size_t>(stage)].load(std::memory_order_relaxed);
    }

    // Counts an update the caller made itself, with the runner stopped (spindle view
    // steps the space on the game thread in slow motion). The thread that updates only.
    void add(const UpdateStats& stats) { sample(stats); }

    // After AsyncRunner::stop() only.
    const ProbeTotals& totals() const noexcept { return m_totals; }

private:
    void post(AsyncRunner& runner);
    void sample(const UpdateStats& stats);

    ProbeTotals m_totals;  // physics loop thread only, until stop()
    double m_min_interval = 0;
    std::int64_t m_last_ns = 0;  // when the previous update was let go
    std::atomic<std::uint32_t> m_awake{0};
    std::atomic<std::uint32_t> m_contacts{0};
    std::atomic<double> m_update_ms{0};
    // The window behind recent_stage_ms (the updating thread only), and its result.
    std::array<double, static_cast<int>(Stage::Count)> m_window_seconds{};
    std::uint64_t m_window_steps = 0;
    std::int64_t m_window_start_ns = 0;
    std::array<std::atomic<double>, static_cast<int>(Stage::Count)> m_recent_stage_ms{};
};

}  // namespace spindle::app
