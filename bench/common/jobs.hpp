// The one place the benchmarks get a JobSystem from, so switching every bench to the
// work-stealing scheduler is a one-line change here.
#pragma once

#include <memory>

#include <spindle/scheduler/job_system.hpp>
#include <spindle/scheduler/single_threaded.hpp>

namespace spindle::bench {

// A job system with `threads` workers (the caller of Space::update counts as one).
// For now every count gives the single-threaded system: the work-stealing scheduler is
// not merged yet, so "threads:2" results equal "threads:1" until this returns it.
inline std::unique_ptr<JobSystem> make_bench_jobs(unsigned threads) {
    (void)threads;
    return std::make_unique<SingleThreadedJobSystem>();
}

}  // namespace spindle::bench
