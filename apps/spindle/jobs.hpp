// The one place the program chooses its JobSystem (the scheduler that runs the
// engine's parallel stages), for a layout (run) or a worker count (bench).
#pragma once

#include <memory>

#include <spindle/platform/layout.hpp>
#include <spindle/scheduler/job_system.hpp>

namespace spindle::app {

// Workers pinned to mapping.worker_pus(), the physics loop thread being worker
// mapping.physics_worker when it has one.
std::unique_ptr<JobSystem> make_jobs(const LayoutMapping& mapping);
// `threads` workers, unpinned (bench).
std::unique_ptr<JobSystem> make_jobs(unsigned threads);

}  // namespace spindle::app
