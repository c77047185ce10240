// The work-stealing job systems the determinism tests compare with the single-threaded one.
#pragma once

#include <spindle/platform/topology.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <memory>

namespace spindle {

// `workers` workers on the machine's PUs, round robin; pinned only when each has a PU
// of its own. Work stealing for every count, one worker included: the reference is the
// single-threaded job system, so "1 worker" is not the reference compared with itself.
inline std::unique_ptr<JobSystem> jobs_for(unsigned workers) {
    const Topology machine = Topology::from_system();
    WorkStealingJobSystem::Options options;
    for (unsigned i = 0; i < workers; ++i)
        options.worker_pus.push_back(machine.pus()[i % machine.pus().size()].os_index);
    options.pin = workers <= machine.pus().size();
    return std::make_unique<WorkStealingJobSystem>(options);
}

}  // namespace spindle
