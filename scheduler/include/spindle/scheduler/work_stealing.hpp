// WorkStealingJobSystem: workers pinned to hardware threads, one Chase-Lev deque
// each, random-victim stealing, idle workers that spin briefly and then sleep. The
// thread that calls parallel_for/wait is worker 0 for the duration of the call and
// runs jobs while it waits (design.md section 5).
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <new>
#include <cstddef>
#include <vector>

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
};

// A submitted job: the callable lives inline (no heap allocation per job).
struct JobRecord : TaskHeader {
    alignas(std::max_align_t) unsigned char storage[48];
    void (*invoke)(void* storage, unsigned worker) = nullptr;
    void (*destroy)(void* storage) = nullptr;
    JobGroup* group = nullptr;
    const char* name = "";
    int pinned = -1;
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
    template <typename F>
    void submit(JobGroup& group, const char* name, F&& fn) {
        submit_record(group, name, make_record(std::forward<F>(fn)), -1);
    }
    // As submit, but the job runs only on `worker` (its PU). Any thread. Deadlock: a
    // pinned job for worker 0 runs only while some thread waits as worker 0.
    template <typename F>
    void submit_pinned(unsigned worker, JobGroup& group, const char* name, F&& fn) {
        submit_record(group, name, make_record(std::forward<F>(fn)), static_cast<int>(worker));
    }
    // Runs jobs until every job of the group finished; rethrows the first exception.
    // Who may call: any thread (a non-worker becomes worker 0 meanwhile); from inside a
    // job too (it keeps running other jobs, never idles while work is queued).
    void wait(JobGroup& group);
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

private:
    friend struct detail::Worker;
    detail::JobRecord* make_record_raw();
    template <typename F>
    detail::JobRecord* make_record(F&& fn);
    void submit_record(JobGroup& group, const char* name, detail::JobRecord* record, int pinned);
    void release_record(detail::JobRecord* record);
    static void run_record(detail::TaskHeader* header, std::uint64_t range, detail::Worker& self);
    bool run_one(detail::Worker& self);
    bool any_work() const;
    void worker_main(unsigned index);
    void wake_one_if_sleeping();
    void wake_all();
    detail::Worker& enter(bool& entered);
    void leave(bool entered);

    Options m_options;
    std::vector<std::unique_ptr<detail::Worker>> m_workers;
    std::vector<std::thread> m_threads;
    std::atomic<bool> m_stop{false};
    std::atomic<std::uint32_t> m_wake{0};        // bumped when work arrives (sleepers wait on it)
    std::atomic<std::int32_t> m_sleeping{0};
    std::atomic<std::int64_t> m_outstanding{0};  // submitted jobs not yet finished
    std::mutex m_external;                        // one external thread acts as worker 0 at a time
    std::atomic<bool> m_trace_on{false};
    mutable std::mutex m_stage_lock;              // stage spans (a few per step) from the owner thread
    std::vector<TraceEvent> m_stage_events;
    std::vector<std::pair<const char*, std::int64_t>> m_open_stages;

    // Pool of job records for submit(): a free list under a small lock.
    std::mutex m_pool_lock;
    std::vector<detail::JobRecord*> m_free_records;
    std::vector<std::unique_ptr<detail::JobRecord[]>> m_record_blocks;
};

template <typename F>
detail::JobRecord* WorkStealingJobSystem::make_record(F&& fn) {
    using Callable = std::decay_t<F>;
    static_assert(sizeof(Callable) <= kInlineBytes, "job callable too large: capture less or capture a pointer");
    static_assert(alignof(Callable) <= alignof(std::max_align_t), "job callable over-aligned");
    detail::JobRecord* record = make_record_raw();
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
