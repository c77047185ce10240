// WorkStealingJobSystem's life and scheduling loop: construction, draining destruction, worker 0,
// finding and stealing work, idling, sleeping and waking, the worker threads; make_job_system.
#include "worker.hpp"

#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/spin.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/scheduler/single_threaded.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace spindle {
namespace detail {

thread_local Worker* tls_worker = nullptr;

}  // namespace detail

// How long an idle worker spins before it sleeps.
constexpr std::int64_t kSpinBeforeSleepNs = 200'000;

using detail::TaskHeader;
using detail::Worker;

namespace detail {

bool Worker::push(TaskHeader* task, std::uint64_t range) {
    if (!deque.push(task, range)) return false;
    system->wake_one_if_sleeping();
    return true;
}

void Worker::flush_finished() {
    // After the decrement the group may be gone (its waiter returns): forget it first.
    JobGroup* const group = std::exchange(finished_group, nullptr);
    if (finished_count > 0) GroupAccess::done(*group, std::exchange(finished_count, 0));
}

void Worker::set_idle(bool now_idle) {
    if (idle == now_idle) return;  // the shared counter changes only on a transition
    idle = now_idle;
    system->m_idle.value.fetch_add(now_idle ? 1 : -1, std::memory_order_relaxed);
}

}  // namespace detail

// ---- construction ----

WorkStealingJobSystem::WorkStealingJobSystem(Options options) : m_options(std::move(options)) {
    if (m_options.worker_pus.empty()) throw Error("WorkStealingJobSystem: at least one worker is needed");
    for (unsigned i = 0; i < m_options.worker_pus.size(); ++i) {
        auto w = std::make_unique<Worker>();
        w->system = this;
        w->index = i;
        w->pu = i == 0 ? -1 : static_cast<int>(m_options.worker_pus[i]);  // worker 0 is whoever calls
        w->rng = 0x9E3779B97F4A7C15ull * (i + 1);
        w->free_records.reserve(2 * kRecordBatch + 1);  // release_record never grows it further
        m_workers.push_back(std::move(w));
    }
    for (unsigned i = 1; i < m_workers.size(); ++i) m_threads.emplace_back([this, i] { worker_main(i); });
}

WorkStealingJobSystem::~WorkStealingJobSystem() {
    // Drain: queued and pinned jobs all run (worker 0's share on this thread) before
    // the workers are told to stop.
    {
        const WorkerScope scope(*this);
        run_until(scope.worker, [this] { return !any_job_unfinished(); });
    }
    m_stop.store(true, std::memory_order_seq_cst);
    wake_all();
    for (std::thread& t : m_threads) t.join();
}

// ---- worker 0: the calling thread ----

Worker* WorkStealingJobSystem::current_worker() const noexcept {
    return detail::tls_worker && detail::tls_worker->system == this ? detail::tls_worker : nullptr;
}

Worker& WorkStealingJobSystem::enter(bool& entered) {
    if (Worker* self = current_worker()) {
        entered = false;
        return *self;
    }
    m_external.lock();  // one external thread acts as worker 0 at a time
    entered = true;
    detail::tls_worker = m_workers[0].get();
    m_workers[0]->pu = current_cpu();
    return *m_workers[0];
}

void WorkStealingJobSystem::leave(bool entered) {
    if (!entered) return;
    detail::tls_worker = nullptr;
    m_external.unlock();
}

// ---- finding and running work ----

bool WorkStealingJobSystem::run_one(Worker& self) {
    TaskHeader* task = nullptr;
    std::uint64_t range = 0;
    if (self.has_mail.load(std::memory_order_acquire)) {
        std::scoped_lock guard(self.mailbox_lock);
        if (!self.mailbox.empty()) {
            task = self.mailbox.back();
            self.mailbox.pop_back();
            self.has_mail.store(!self.mailbox.empty(), std::memory_order_release);
        }
    }
    bool found = task != nullptr || self.deque.pop(task, range);
    if (!found) {
        const auto n = static_cast<unsigned>(m_workers.size());
        const unsigned start = n > 1 ? self.next_victim(n) : 0;
        for (unsigned k = 0; k < n && !found; ++k) {
            const unsigned v = (start + k) % n;
            if (v != self.index) found = m_workers[v]->deque.steal(task, range);
        }
    }
    if (!found) {
        self.flush_finished();
        self.set_idle(true);
        return false;
    }
    self.set_idle(false);
    if (task->group != self.finished_group) self.flush_finished();
    task->run(task, range, self);
    return true;
}

bool WorkStealingJobSystem::any_work() const {
    for (const auto& w : m_workers) {
        if (w->deque.maybe_nonempty() || w->has_mail.load(std::memory_order_acquire)) return true;
    }
    return false;
}

bool WorkStealingJobSystem::any_job_unfinished() const {
    // Finished counts first: a job seen finished was submitted before, so its submit is
    // then seen too, and the difference never under-counts.
    std::uint64_t finished = 0;
    for (const auto& w : m_workers) finished += w->jobs_finished.load(std::memory_order_acquire);
    std::uint64_t submitted = m_foreign_submitted.load(std::memory_order_acquire);
    for (const auto& w : m_workers) submitted += w->jobs_submitted.load(std::memory_order_acquire);
    return submitted > finished;
}

void WorkStealingJobSystem::wake_one_if_sleeping() {
    if (m_sleeping.value.load(std::memory_order_seq_cst) > 0) {
        m_wake.value.fetch_add(1, std::memory_order_seq_cst);
        m_wake.value.notify_all();
    }
}

void WorkStealingJobSystem::wake_all() {
    m_wake.value.fetch_add(1, std::memory_order_seq_cst);
    m_wake.value.notify_all();
}

void WorkStealingJobSystem::worker_main(unsigned index) {
    Worker& self = *m_workers[index];
    detail::tls_worker = &self;
    set_current_thread_name(m_options.name_prefix + "-" + std::to_string(index));
    if (m_options.pin) pin_current_thread(m_options.worker_pus[index]);
    Backoff backoff;
    std::int64_t idle_since = 0;
    for (;;) {
        if (run_one(self)) {
            backoff.reset();
            idle_since = 0;
            continue;
        }
        if (m_stop.load(std::memory_order_acquire) && !any_work()) break;
        // Spin (pause, then yield) for a while before sleeping: a step issues a
        // parallel_for every few tens of microseconds, and a futex wake-up costs more.
        const std::int64_t now = now_nanoseconds();
        if (idle_since == 0) idle_since = now;
        if (now - idle_since < kSpinBeforeSleepNs) {
            backoff.spin();
            continue;
        }
        // Sleep until work arrives. A sleeper stays idle, so a worker with a range splits
        // it and the push wakes the sleeper. Announcing the sleep before the last look
        // for work pairs with push's check of m_sleeping, so no wake-up is missed.
        const std::uint32_t epoch = m_wake.value.load(std::memory_order_seq_cst);
        m_sleeping.value.fetch_add(1, std::memory_order_seq_cst);
        if (!any_work() && !m_stop.load(std::memory_order_seq_cst)) {
            m_wake.value.wait(epoch, std::memory_order_seq_cst);
        }
        m_sleeping.value.fetch_sub(1, std::memory_order_seq_cst);
        backoff.reset();
        idle_since = 0;
    }
    self.set_idle(false);
    detail::tls_worker = nullptr;
}

std::unique_ptr<JobSystem> make_job_system(const std::vector<unsigned>& worker_pus, bool pin) {
    if (worker_pus.size() <= 1) return std::make_unique<SingleThreadedJobSystem>();
    return std::make_unique<WorkStealingJobSystem>(WorkStealingJobSystem::Options{worker_pus, pin, "spindle-worker"});
}

}  // namespace spindle
