// JobSystem: the small interface the engine uses to run work in parallel. Two
// implementations: WorkStealingJobSystem (workers pinned per layout) and
// SingleThreadedJobSystem (runs everything on the caller, in order; for tests and
// workers = 1).
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <span>
#include <vector>

#include <spindle/scheduler/function_ref.hpp>

namespace spindle {

struct GroupAccess;

// Body of a range job: items [begin, end), and the index of the worker running it.
// The worker index is for per-worker scratch buffers only, never for results.
using RangeFn = FunctionRef<void(std::uint32_t begin, std::uint32_t end, unsigned worker)>;

// One phase of run_phases: `count` items, run in blocks of at least `grain` items.
struct Phase {
    const char* name = "";
    std::uint32_t count = 0;
    std::uint32_t grain = 1;
};

// Body of a block of run_phases: items [begin, end) of phase `phase`.
using PhaseFn = FunctionRef<void(std::uint32_t phase, std::uint32_t begin, std::uint32_t end, unsigned worker)>;

// A set of submitted jobs to wait for together. Lives on the waiter's stack; must not
// be destroyed while jobs of it are pending (wait() first).
class JobGroup {
public:
    JobGroup() = default;
    JobGroup(const JobGroup&) = delete;
    JobGroup& operator=(const JobGroup&) = delete;
    bool done() const noexcept { return m_pending.load(std::memory_order_acquire) == 0; }

private:
    friend class WorkStealingJobSystem;
    friend class SingleThreadedJobSystem;
    friend struct GroupAccess;
    std::atomic<std::int64_t> m_pending{0};
    std::mutex m_error_lock;
    std::exception_ptr m_error;
};

// A DAG of jobs: add nodes, then edges (a -> b: b runs after a), then run it.
// Dependencies are data: each node keeps the count of nodes it still waits for.
class StageGraph {
public:
    using Fn = FunctionRef<void(unsigned worker)>;
    // The callable must outlive run_graph(). Returns the node's index.
    std::uint32_t add(const char* name, Fn fn);
    void depends_on(std::uint32_t node, std::uint32_t prerequisite);
    std::size_t size() const noexcept { return m_nodes.size(); }

private:
    friend class WorkStealingJobSystem;
    friend class SingleThreadedJobSystem;
    struct Node {
        const char* name;
        Fn fn;
        std::vector<std::uint32_t> dependents;
        std::uint32_t prerequisites = 0;        // how many nodes must finish first
        std::atomic<std::uint32_t> waiting{0};  // counts down while running
        Node(const char* n, Fn f) : name(n), fn(f) {}
        Node(Node&& o) noexcept
            : name(o.name), fn(o.fn), dependents(std::move(o.dependents)), prerequisites(o.prerequisites) {}
    };
    std::vector<Node> m_nodes;
};

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

    // Runs phases in order: every item of a phase finishes before any item of the next
    // starts; within a phase, blocks of items run in parallel. Unlike parallel_for's
    // chunks, block boundaries may depend on the worker count: use it only where the
    // result does not depend on how a phase is split (constraints of one colour, one
    // body each). Made for many short phases (the solver's colour passes): one job per
    // worker walks the whole list, claiming blocks and meeting the others at a spin
    // barrier after each phase, so a phase costs a few cache-line transfers instead of a
    // fork and a join. Each worker's share is cut into blocks of halving size, which
    // suits items of similar cost; for very uneven items (collision pairs of different
    // shapes) parallel_for, which splits a busy range on demand, balances better. fn must not throw (std::terminate)
    // nor wait for other jobs (no parallel_for or wait inside it: the waiting thread could pick up a participant that
    // then waits at a barrier for the block below it). Who may call: any thread, not from inside a phase. Deadlock:
    // none otherwise; a worker that never joins leaves its blocks to the others.
    virtual void run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) = 0;

    // Runs a stage graph to completion: each node after its prerequisites, nodes in
    // parallel where the graph allows; rethrows the first exception. Who may call: any
    // thread; the caller runs nodes while it waits.
    virtual void run_graph(StageGraph& graph) = 0;

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
