// JobSystem choice. For now both return the SingleThreadedJobSystem: the
// work-stealing scheduler lives on another branch, and when it lands these two
// functions (and nothing else in the program) switch to it.
#include "jobs.hpp"

#include <spindle/scheduler/single_threaded.hpp>

namespace spindle::app {

std::unique_ptr<JobSystem> make_jobs(const LayoutMapping& mapping) {
    static_cast<void>(mapping);  // TODO(scheduler): WorkStealingJobSystem pinned to mapping.worker_pus()
    return std::make_unique<SingleThreadedJobSystem>();
}

std::unique_ptr<JobSystem> make_jobs(unsigned threads) {
    static_cast<void>(threads);  // TODO(scheduler): WorkStealingJobSystem with `threads` workers
    return std::make_unique<SingleThreadedJobSystem>();
}

}  // namespace spindle::app
