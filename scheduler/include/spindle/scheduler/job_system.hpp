// JobSystem: the small interface the engine uses to run work in parallel. Two
// implementations: WorkStealingJobSystem (workers pinned per layout) and
// SingleThreadedJobSystem (runs everything on the caller, in order; for tests and
// workers = 1).
#pragma once

#include <cstdint>

#include <spindle/scheduler/function_ref.hpp>

namespace spindle {

// Body of a range job: items [begin, end), and the index of the worker running it.
// The worker index is for per-worker scratch buffers only, never for results.
using RangeFn = FunctionRef<void(std::uint32_t begin, std::uint32_t end, unsigned worker)>;

class JobSystem {
public:
    virtual ~JobSystem() = default;

    // Number of workers (threads that run jobs, the caller of parallel_for included).
    virtual unsigned worker_count() const noexcept = 0;

    // Runs fn over [begin, end) in chunks [begin + i*grain, min(end, begin + (i+1)*grain)):
    // chunk boundaries depend only on the range and grain, never on the worker count.
    // Blocks until every chunk ran; the calling thread runs chunks meanwhile. An
    // exception thrown by fn is rethrown here after all chunks finished. Zero items
    // spawn nothing. May be called from inside a job (nested).
    // Who may call: any thread. Deadlock: none, the caller never waits idle for work.
    virtual void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                              RangeFn fn) = 0;

    // Marks a named stage (e.g. "Broadphase") on the calling thread in the trace.
    // Near-free when tracing is off. Calls nest; each begin has one end.
    virtual void trace_begin(const char* stage) noexcept = 0;
    virtual void trace_end() noexcept = 0;
};

// A stage span for the trace, begun in the constructor and ended in the destructor.
class StageScope {
public:
    StageScope(JobSystem& jobs, const char* stage) noexcept : m_jobs(jobs) { m_jobs.trace_begin(stage); }
    ~StageScope() { m_jobs.trace_end(); }
    StageScope(const StageScope&) = delete;
    StageScope& operator=(const StageScope&) = delete;

private:
    JobSystem& m_jobs;
};

}  // namespace spindle
