// Monotonic time for the physics loop and for measurements.
#pragma once

#include <chrono>
#include <cstdint>

namespace spindle {

using Clock = std::chrono::steady_clock;

// Seconds on the monotonic clock since an arbitrary fixed point.
inline double now_seconds() noexcept { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

inline std::int64_t now_nanoseconds() noexcept {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// Measures elapsed time from construction or the last restart()/lap().
class Stopwatch {
public:
    Stopwatch() noexcept : m_start(Clock::now()) {}
    void restart() noexcept { m_start = Clock::now(); }
    double elapsed_seconds() const noexcept { return std::chrono::duration<double>(Clock::now() - m_start).count(); }
    std::int64_t elapsed_nanoseconds() const noexcept {
        return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - m_start).count();
    }
    // When it started (or last restarted or lapped), on now_nanoseconds()'s scale.
    std::int64_t started_nanoseconds() const noexcept {
        return std::chrono::duration_cast<std::chrono::nanoseconds>(m_start.time_since_epoch()).count();
    }
    // Elapsed seconds, and restart: the physics loop's "time since last iteration".
    double lap() noexcept {
        const auto now = Clock::now();
        const double elapsed = std::chrono::duration<double>(now - m_start).count();
        m_start = now;
        return elapsed;
    }

private:
    Clock::time_point m_start;
};

}  // namespace spindle
