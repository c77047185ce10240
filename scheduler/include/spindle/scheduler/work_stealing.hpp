// WorkStealingJobSystem: workers pinned to hardware threads, one Chase-Lev deque
// each, random-victim stealing, idle workers that spin briefly and then sleep. The
// thread that calls parallel_for/wait is worker 0 for the duration of the call and
// runs jobs while it waits (design.md section 5).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include <spindle/platform/spin.hpp>
#include <spindle/scheduler/job_system.hpp>

namespace spindle {

class JobGroup;
struct GroupAccess;

namespace detail {
struct Worker;

// What a deque slot points at: a parallel_for's context or a submitted job's record.
// `range` packs the chunks [first, last) for a parallel_for (unused by jobs).
struct TaskHeader {
    void (*run)(TaskHeader* self, std::uint64_t range, Worker& worker) = nullptr;
    JobGroup* group = nullptr;  // the job's group; null for a parallel_for
};

// A submitted job: the callable lives inline (no heap allocation per job).
struct JobRecord : TaskHeader {
    alignas(std::max_align_t) unsigned char storage[48];
    void (*invoke)(void* storage, unsigned worker) = nullptr;
    void (*destroy)(void* storage) = nullptr;
    const char* name = "";
};
}  // namespace detail

struct TraceEvent {
    const char* name = "";
    const char* stage = "";
    std::int64_t begin_ns = 0;
    std::int64_t end_ns = 0;
    unsigned worker = 0;
    int pu = -1;
};

class WorkStealingJobSystem final : public JobSystem {
public:
    struct Options {
        // Real PUs (OS indices) of the workers, in worker order. Worker 0 is the thread
        // that calls parallel_for/wait (the physics loop, pinned by its owner); threads
        // are started for workers 1..n-1 and pinned to their PUs.
        std::vector<unsigned> worker_pus;
        bool pin = true;  // false: leave the worker threads unpinned (tests with more workers than PUs)
        std::string name_prefix = "spindle-worker";
    };

    explicit WorkStealingJobSystem(Options options);
    // Runs every job still queued (none is lost), then stops and joins the workers.
    // Who may call: the owner, with no parallel_for/wait running on other threads.
    ~WorkStealingJobSystem() override;

    unsigned worker_count() const noexcept override { return static_cast<unsigned>(m_workers.size()); }

    // See JobSystem. Callers that are not worker threads are serialised: one external
    // thread at a time acts as worker 0 (the physics loop is the only one in practice).
    void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                      RangeFn fn) override;

    // Submits fn into group. The callable is copied into a pooled job record (at most
    // kInlineBytes; no heap allocation). Any thread.
    // A non-worker thread acts as worker 0 for the call (see parallel_for).
    template <typename F>
    void submit(JobGroup& group, const char* name, F&& fn) {
        const WorkerScope scope(*this);
        submit_record(scope.worker, group, name, make_record(&scope.worker, std::forward<F>(fn)));
    }
    // As submit, but the job runs only on `worker` (its PU). Any thread; a non-worker
    // thread does not become worker 0 (it never blocks on the one that is). Deadlock: a
    // pinned job for worker 0 runs only while some thread waits as worker 0.
    template <typename F>
    void submit_pinned(unsigned worker, JobGroup& group, const char* name, F&& fn) {
        check_worker_exists(worker);
        submit_pinned_record(worker, group, name, make_record(current_worker(), std::forward<F>(fn)));
    }
    // Runs jobs until every job of the group finished; rethrows the first exception.
    // Who may call: any thread (a non-worker becomes worker 0 meanwhile); from inside a
    // job too (it keeps running other jobs, never idles while work is queued).
    void wait(JobGroup& group);
    // See JobSystem: one job per worker (at most kMaxPhaseWorkers) runs every phase.
    // Consecutive phases that fit in one block each (count <= grain) are one round: the
    // worker that claims the first runs them all back to back, in order, with one
    // barrier after the last (a split would leave the others idle at each barrier).
    void run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) override;
    static constexpr unsigned kMaxPhaseWorkers = 16;
    // Phases with items that run_phases calls have run so far, and the barriers they met:
    // one per such phase, except that consecutive phases of one block each share one.
    // Any thread.
    std::uint64_t phases_run() const noexcept { return m_phases_run.load(std::memory_order_relaxed); }
    std::uint64_t phase_barriers() const noexcept { return m_phase_barriers.load(std::memory_order_relaxed); }
    // Runs a stage graph to completion (nodes in dependency order, in parallel where
    // allowed); rethrows the first exception after every runnable node finished.
    void run_graph(StageGraph& graph) override;

    // Tracing: off by default; when off, each job pays one relaxed load.
    void enable_trace(bool on) noexcept { m_trace_on.store(on, std::memory_order_relaxed); }
    bool trace_enabled() const noexcept { return m_trace_on.load(std::memory_order_relaxed); }
    void trace_begin(const char* stage) noexcept override;
    void trace_end() noexcept override;
    // Every recorded event (jobs and stages), merged; the owner thread, between updates.
    std::vector<TraceEvent> trace_events() const;
    void clear_trace();
    // Chrome trace-event JSON (loads in Perfetto and chrome://tracing).
    void write_trace(std::ostream& out) const;
    void write_trace(const std::string& path) const;

    static constexpr std::size_t kInlineBytes = sizeof(detail::JobRecord::storage);

    // True while some worker looks for work and finds none, or sleeps for want of it:
    // a worker running a parallel_for range then splits it so the idle one can steal
    // half (the push wakes a sleeper). Any thread.
    bool has_idle_worker() const noexcept { return m_idle.value.load(std::memory_order_relaxed) > 0; }

private:
    friend struct detail::Worker;

    // The calling thread's worker for the scope: its own if it is one of ours, else
    // worker 0 (taking the external lock, see parallel_for).
    struct WorkerScope {
        explicit WorkerScope(WorkStealingJobSystem& owner) : system(owner), worker(owner.enter(entered)) {}
        ~WorkerScope() { system.leave(entered); }
        WorkerScope(const WorkerScope&) = delete;
        WorkerScope& operator=(const WorkerScope&) = delete;
        WorkStealingJobSystem& system;
        bool entered = false;
        detail::Worker& worker;
    };

    detail::Worker* current_worker() const noexcept;
    void check_worker_exists(unsigned worker) const;
    detail::JobRecord* acquire_record(detail::Worker* self);
    template <typename F>
    detail::JobRecord* make_record(detail::Worker* self, F&& fn);
    void submit_record(detail::Worker& self, JobGroup& group, const char* name, detail::JobRecord* record);
    void submit_pinned_record(unsigned worker, JobGroup& group, const char* name, detail::JobRecord* record);
    void release_record(detail::Worker& self, detail::JobRecord* record);
    static void run_record(detail::TaskHeader* header, std::uint64_t range, detail::Worker& self);
    bool run_one(detail::Worker& self);
    template <typename Done>
    void run_until(detail::Worker& self, Done done);
    bool any_work() const;
    bool any_job_unfinished() const;
    void worker_main(unsigned index);
    void wake_one_if_sleeping();
    void wake_all();
    detail::Worker& enter(bool& entered);
    void leave(bool entered);

    Options m_options;
    std::vector<std::unique_ptr<detail::Worker>> m_workers;
    std::vector<std::thread> m_threads;
    std::atomic<bool> m_stop{false};
    // Each hot counter on its own cache line: m_idle is read per parallel_for chunk and
    // m_sleeping per push, while the others change; sharing a line would make every
    // read a miss.
    CacheLinePadded<std::atomic<std::uint32_t>> m_wake;  // bumped when work arrives (sleepers wait on it)
    CacheLinePadded<std::atomic<std::int32_t>> m_sleeping;
    CacheLinePadded<std::atomic<std::int32_t>> m_idle;  // workers looking for work or asleep
    std::atomic<std::uint64_t> m_foreign_submitted{0};  // pinned jobs submitted by non-worker threads
    // Own cache lines: the external thread locks m_external once per submit, and every
    // job reads m_trace_on; on one line each lock would take the line from the workers.
    alignas(cache_line_size) std::mutex m_external;  // one external thread acts as worker 0 at a time
    alignas(cache_line_size) std::atomic<bool> m_trace_on{false};
    std::atomic<std::uint64_t> m_phases_run{0};  // both added to once per run_phases call
    std::atomic<std::uint64_t> m_phase_barriers{0};
    mutable std::mutex m_stage_lock;  // stage spans (a few per step) from the owner thread
    std::vector<TraceEvent> m_stage_events;
    std::vector<std::pair<const char*, std::int64_t>> m_open_stages;

    // Job records for submit(): each worker keeps its own free list and trades batches
    // with this shared one under the lock, so the lock is taken once per batch, not
    // per job (a job stolen by another worker is freed into the thief's list).
    std::mutex m_pool_lock;
    std::vector<detail::JobRecord*> m_free_records;
    std::vector<std::unique_ptr<detail::JobRecord[]>> m_record_blocks;
};

template <typename F>
detail::JobRecord* WorkStealingJobSystem::make_record(detail::Worker* self, F&& fn) {
    using Callable = std::decay_t<F>;
    static_assert(sizeof(Callable) <= kInlineBytes, "job callable too large: capture less or capture a pointer");
    static_assert(alignof(Callable) <= alignof(std::max_align_t), "job callable over-aligned");
    detail::JobRecord* record = acquire_record(self);
    new (record->storage) Callable(std::forward<F>(fn));
    record->invoke = [](void* storage, unsigned worker) {
        Callable& c = *static_cast<Callable*>(storage);
        if constexpr (std::is_invocable_v<Callable&, unsigned>) {
            c(worker);
        } else {
            c();
        }
    };
    record->destroy = [](void* storage) { static_cast<Callable*>(storage)->~Callable(); };
    return record;
}

// Writes events as Chrome trace-event JSON.
void write_chrome_trace(std::ostream& out, const std::vector<TraceEvent>& events);

// Chooses the implementation: single-threaded for one worker, work stealing otherwise.
std::unique_ptr<JobSystem> make_job_system(const std::vector<unsigned>& worker_pus, bool pin = true);

}  // namespace spindle
