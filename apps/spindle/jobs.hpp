// The one place the program chooses its JobSystem (the scheduler that runs the
// engine's parallel stages), for a layout (run) or a worker count (bench).
#pragma once

#include <memory>
#include <vector>

#include <spindle/platform/layout.hpp>
#include <spindle/scheduler/job_system.hpp>

namespace spindle::app {

// The real PUs of the scheduler's workers for a layout, worker 0 first. Worker 0 is
// the thread that calls update() (the physics loop), so it is the physics PU: the
// layout's physics worker when its hardware thread is in the worker list, otherwise an
// extra worker in front of the listed ones (the caller always runs jobs while it waits).
std::vector<unsigned> scheduler_pus(const LayoutMapping& mapping);

// A WorkStealingJobSystem with workers 1..n-1 pinned to scheduler_pus(mapping), also
// for one worker (then it starts no thread), so that `run --trace` always has the
// scheduler's trace.
std::unique_ptr<JobSystem> make_jobs(const LayoutMapping& mapping);
// `threads` workers, unpinned (bench): the single-threaded JobSystem for 1, work
// stealing otherwise (spindle::make_job_system).
std::unique_ptr<JobSystem> make_jobs(unsigned threads);

}  // namespace spindle::app
