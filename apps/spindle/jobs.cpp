// JobSystem choice: the work-stealing scheduler, placed per layout.
#include "jobs.hpp"

#include <spindle/scheduler/work_stealing.hpp>

namespace spindle::app {

std::vector<unsigned> scheduler_pus(const LayoutMapping& mapping) {
    const std::vector<unsigned> listed = mapping.worker_pus();
    std::vector<unsigned> pus;
    if (mapping.physics_worker) {
        pus.push_back(listed[*mapping.physics_worker]);
        for (unsigned i = 0; i < listed.size(); ++i) {
            if (i != *mapping.physics_worker) pus.push_back(listed[i]);
        }
    } else {
        pus.push_back(mapping.physics.real_pu);
        pus.insert(pus.end(), listed.begin(), listed.end());
    }
    return pus;
}

std::unique_ptr<JobSystem> make_jobs(const LayoutMapping& mapping) {
    WorkStealingJobSystem::Options options;
    options.worker_pus = scheduler_pus(mapping);
    return std::make_unique<WorkStealingJobSystem>(std::move(options));
}

std::unique_ptr<JobSystem> make_jobs(unsigned threads) {
    std::vector<unsigned> pus(threads);
    for (unsigned i = 0; i < threads; ++i) pus[i] = i;  // unpinned: only named in a trace
    return make_job_system(pus, /*pin=*/false);
}

}  // namespace spindle::app
