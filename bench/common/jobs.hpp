// The one place the benchmarks get a JobSystem from.
#pragma once

#include <memory>
#include <vector>

#include <spindle/platform/topology.hpp>
#include <spindle/scheduler/work_stealing.hpp>

namespace spindle::bench {

// A job system with `threads` workers (the caller of Space::update is worker 0),
// placed on the machine's PUs in order; single-threaded for one.
inline std::unique_ptr<JobSystem> make_bench_jobs(unsigned threads) {
    const Topology machine = Topology::from_system();
    std::vector<unsigned> pus;
    for (unsigned i = 0; i < threads; ++i) pus.push_back(machine.pus()[i % machine.pus().size()].os_index);
    return make_job_system(pus, threads <= machine.pus().size());
}

}  // namespace spindle::bench
