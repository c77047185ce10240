// StepClock: wall and process-CPU time over a loop of steps. On a shared machine the CPU
// rate is the steadier number for single-threaded runs; the wall rate is what a game sees.
#pragma once

#include <chrono>
#include <cstdint>
#include <ctime>

namespace spindle::bench {

class StepClock {
public:
    StepClock() : m_wall(std::chrono::steady_clock::now()), m_cpu(process_cpu_seconds()) {}

    double wall_seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_wall).count();
    }
    // CPU time of every thread of the process since construction.
    double cpu_seconds() const { return process_cpu_seconds() - m_cpu; }

    static double process_cpu_seconds() {
        timespec t{};
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
        return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
    }

private:
    std::chrono::steady_clock::time_point m_wall;
    double m_cpu;
};

}  // namespace spindle::bench
