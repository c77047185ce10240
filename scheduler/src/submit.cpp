// WorkStealingJobSystem's submitted jobs: the pools of job records, submit and
// submit_pinned (per-worker mailboxes), running a record, and wait.
#include "worker.hpp"

#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace spindle {

using detail::JobRecord;
using detail::TaskHeader;
using detail::Worker;

void WorkStealingJobSystem::check_worker_exists(unsigned worker) const {
    if (worker >= m_workers.size()) {
        throw Error("submit_pinned: worker " + std::to_string(worker) + " does not exist (" +
                    std::to_string(m_workers.size()) + " workers)");
    }
}

JobRecord* WorkStealingJobSystem::acquire_record(Worker* self) {
    // A worker refills its own list a batch at a time; a non-worker thread (pinned
    // submits only) takes one record from the shared list.
    std::vector<JobRecord*>& from = self ? self->free_records : m_free_records;
    std::unique_lock guard(m_pool_lock, std::defer_lock);
    if (!self || from.empty()) {
        guard.lock();
        if (m_free_records.size() < kRecordBatch) {
            constexpr std::size_t kBlock = 1024;
            m_record_blocks.push_back(std::make_unique<JobRecord[]>(kBlock));
            for (std::size_t i = 0; i < kBlock; ++i) m_free_records.push_back(&m_record_blocks.back()[i]);
        }
        if (self) {
            from.insert(from.end(), m_free_records.end() - kRecordBatch, m_free_records.end());
            m_free_records.resize(m_free_records.size() - kRecordBatch);
        }
    }
    JobRecord* r = from.back();
    from.pop_back();
    return r;
}

void WorkStealingJobSystem::release_record(Worker& self, JobRecord* record) {
    self.free_records.push_back(record);
    // A thief frees records another worker took: hand a batch back once it holds too
    // many, so they do not pile up here while the submitter allocates new ones.
    if (self.free_records.size() > 2 * kRecordBatch) {
        std::scoped_lock guard(m_pool_lock);
        m_free_records.insert(m_free_records.end(), self.free_records.end() - kRecordBatch, self.free_records.end());
        self.free_records.resize(self.free_records.size() - kRecordBatch);
    }
}

void WorkStealingJobSystem::run_record(TaskHeader* header, std::uint64_t, Worker& self) {
    auto* record = static_cast<JobRecord*>(header);
    WorkStealingJobSystem& system = *self.system;
    const bool tracing = system.trace_enabled();
    const std::int64_t t0 = tracing ? now_nanoseconds() : 0;
    try {
        record->invoke(record->storage, self.index);
    } catch (...) {
        GroupAccess::fail(*record->group, std::current_exception());
    }
    if (tracing) self.record(record->name, "job", t0, now_nanoseconds());
    record->destroy(record->storage);
    // Counted down with the group's next jobs on this worker (see finished_group). A
    // job of another group may have run meanwhile inside this one (a nested wait).
    if (self.finished_group != record->group) self.flush_finished();
    self.finished_group = record->group;
    self.finished_count += 1;
    system.release_record(self, record);
    detail::bump(self.jobs_finished);
}

void WorkStealingJobSystem::submit_record(Worker& self, JobGroup& group, const char* name, JobRecord* record) {
    record->run = &WorkStealingJobSystem::run_record;
    record->group = &group;
    record->name = name;
    GroupAccess::add(group);
    detail::bump(self.jobs_submitted);
    if (!self.push(record, 0)) {  // full deque: run it now
        run_record(record, 0, self);
        self.flush_finished();  // the submitter may be a job that goes on for long
    }
}

void WorkStealingJobSystem::submit_pinned_record(unsigned worker, JobGroup& group, const char* name,
                                                 JobRecord* record) {
    record->run = &WorkStealingJobSystem::run_record;
    record->group = &group;
    record->name = name;
    GroupAccess::add(group);
    if (Worker* self = current_worker()) {
        detail::bump(self->jobs_submitted);
    } else {
        m_foreign_submitted.fetch_add(1, std::memory_order_acq_rel);
    }
    Worker& target = *m_workers[worker];
    {
        std::scoped_lock guard(target.mailbox_lock);
        target.mailbox.push_back(record);
        target.has_mail.store(true, std::memory_order_seq_cst);
    }
    wake_all();  // the target may be asleep; a targeted wake would need per-worker waits
}

void WorkStealingJobSystem::wait(JobGroup& group) {
    {
        const WorkerScope scope(*this);
        run_until(scope.worker, [&group] { return group.done(); });
    }
    if (std::exception_ptr e = GroupAccess::take_error(group)) std::rethrow_exception(e);
}

}  // namespace spindle
