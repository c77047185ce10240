// Internal declarations the work-stealing job system's files share: the Worker (deque,
// mailbox, record pool, trace events, counters), GroupAccess and run_until.
//
// WorkStealingJobSystem: Chase-Lev deques of small tasks (chase_lev_deque.hpp), binary
// range splitting for parallel_for on demand (chunk boundaries fixed by the grain;
// parallel_for.cpp), per-worker pools of job records for submit, per-worker mailboxes for
// pinned jobs (submit.cpp), and sleeping with C++20 atomic wait (scheduling_loop.cpp).
#pragma once

#include "chase_lev_deque.hpp"

#include <spindle/platform/spin.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <utility>
#include <vector>

namespace spindle {
namespace detail {

// Adds one to a counter only its worker writes: a plain store, no locked instruction.
inline void bump(std::atomic<std::uint64_t>& counter) {
    counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_release);
}

struct Worker {
    WorkStealingJobSystem* system = nullptr;
    unsigned index = 0;
    int pu = -1;
    std::uint64_t rng = 0;
    Deque deque;
    std::mutex mailbox_lock;  // pinned jobs for this worker only
    std::vector<JobRecord*> mailbox;
    std::atomic<bool> has_mail{false};
    std::vector<TraceEvent> events;        // written only by the thread acting as this worker
    std::vector<JobRecord*> free_records;  // this worker's record pool (see m_free_records)
    bool idle = false;                     // counted in the system's m_idle

    // Finished jobs of `finished_group` not yet taken off its pending count. Jobs of
    // one group run back to back are counted down in one atomic operation: while this
    // worker runs another job of the same group the group cannot be done anyway, so
    // the delay never holds up a waiter. Flushed before anything else runs or idles.
    JobGroup* finished_group = nullptr;
    std::int64_t finished_count = 0;

    // Submitted and finished jobs, each written only by this worker (no shared
    // counter bounces between cores per job); the destructor compares the sums.
    std::atomic<std::uint64_t> jobs_submitted{0};
    std::atomic<std::uint64_t> jobs_finished{0};

    // Pushes a task and wakes a sleeping worker to steal it.
    bool push(TaskHeader* task, std::uint64_t range);
    void flush_finished();
    void set_idle(bool now_idle);
    void record(const char* name, const char* stage, std::int64_t begin, std::int64_t end) {
        events.push_back(TraceEvent{name, stage, begin, end, index, pu >= 0 ? pu : current_cpu()});
    }

    unsigned next_victim(unsigned n) {
        rng ^= rng << 13;  // xorshift: cheap, per-worker, good enough to spread steals
        rng ^= rng >> 7;
        rng ^= rng << 17;
        return static_cast<unsigned>(rng % n);
    }
};

}  // namespace detail

// Job records a worker trades with the shared pool at once.
inline constexpr std::size_t kRecordBatch = 64;

// Group bookkeeping needs JobGroup's private members.
struct GroupAccess {
    static void fail(JobGroup& g, std::exception_ptr e) {
        std::scoped_lock guard(g.m_error_lock);
        if (!g.m_error) g.m_error = std::move(e);
    }
    static void done(JobGroup& g, std::int64_t jobs) { g.m_pending.fetch_sub(jobs, std::memory_order_acq_rel); }
    static void add(JobGroup& g) { g.m_pending.fetch_add(1, std::memory_order_relaxed); }
    static std::exception_ptr take_error(JobGroup& g) {
        std::scoped_lock guard(g.m_error_lock);
        return std::exchange(g.m_error, nullptr);
    }
};

// Runs jobs as `self` until done() holds, idle (spinning, counted in m_idle so that busy
// workers split their ranges for it) while it finds none. Returns no longer idle and
// holding no finished jobs back: the caller may go on with long work of its own.
template <typename Done>
void WorkStealingJobSystem::run_until(detail::Worker& self, Done done) {
    Backoff backoff;
    while (!done()) {
        if (run_one(self)) {
            backoff.reset();
        } else {
            backoff.spin();
        }
    }
    self.set_idle(false);
    self.flush_finished();
}

}  // namespace spindle
