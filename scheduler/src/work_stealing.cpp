// WorkStealingJobSystem: Chase-Lev deques of small tasks, binary range splitting for
// parallel_for on demand (chunk boundaries fixed by the grain), per-worker pools of job
// records for submit, per-worker mailboxes for pinned jobs, and sleeping with C++20
// atomic wait.
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/spin.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/scheduler/single_threaded.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <algorithm>
#include <fstream>
#include <ostream>

namespace spindle {
namespace detail {

// Chase-Lev work-stealing deque (Le et al., "Correct and efficient work-stealing for
// weak memory models", 2013) with sequentially consistent top/bottom operations in
// place of fences, which ThreadSanitizer understands. Slots are atomics so a thief's
// read racing with the owner is defined; a thief keeps what it read only if its CAS
// on top succeeds. Fixed capacity: a full deque makes the pusher run the task itself.
class Deque {
public:
    static constexpr std::int64_t kCapacity = 4096;

    bool push(TaskHeader* task, std::uint64_t range) {
        const std::int64_t b = m_bottom.load(std::memory_order_relaxed);
        // Top only grows, so a stale copy can only under-report the free room: read the
        // thieves' cache line only when the copy says the deque may be full.
        if (b - m_top_seen >= kCapacity) {
            m_top_seen = m_top.load(std::memory_order_acquire);
            if (b - m_top_seen >= kCapacity) return false;
        }
        Slot& s = m_slots[b & (kCapacity - 1)];
        s.task.store(task, std::memory_order_relaxed);
        s.range.store(range, std::memory_order_relaxed);
        m_bottom.store(b + 1, std::memory_order_seq_cst);
        return true;
    }

    bool pop(TaskHeader*& task, std::uint64_t& range) {
        const std::int64_t b = m_bottom.load(std::memory_order_relaxed) - 1;
        m_bottom.store(b, std::memory_order_seq_cst);
        std::int64_t t = m_top.load(std::memory_order_seq_cst);
        if (t > b) {
            m_bottom.store(b + 1, std::memory_order_relaxed);
            return false;
        }
        const Slot& s = m_slots[b & (kCapacity - 1)];
        task = s.task.load(std::memory_order_relaxed);
        range = s.range.load(std::memory_order_relaxed);
        if (t == b) {  // the last one: race thieves for it
            const bool won = m_top.compare_exchange_strong(t, t + 1, std::memory_order_seq_cst);
            m_bottom.store(b + 1, std::memory_order_relaxed);
            return won;
        }
        return true;
    }

    bool steal(TaskHeader*& task, std::uint64_t& range) {
        std::int64_t t = m_top.load(std::memory_order_seq_cst);
        const std::int64_t b = m_bottom.load(std::memory_order_seq_cst);
        if (t >= b) return false;
        const Slot& s = m_slots[t & (kCapacity - 1)];
        task = s.task.load(std::memory_order_relaxed);
        range = s.range.load(std::memory_order_relaxed);
        return m_top.compare_exchange_strong(t, t + 1, std::memory_order_seq_cst);
    }

    // The owner's cheap look: a hint, exact only when no thief is stealing.
    bool looks_empty() const {
        return m_top.load(std::memory_order_relaxed) >= m_bottom.load(std::memory_order_relaxed);
    }

    bool maybe_nonempty() const {
        return m_top.load(std::memory_order_seq_cst) < m_bottom.load(std::memory_order_seq_cst);
    }

private:
    struct Slot {
        std::atomic<TaskHeader*> task{nullptr};
        std::atomic<std::uint64_t> range{0};
    };
    alignas(cache_line_size) std::atomic<std::int64_t> m_top{0};
    alignas(cache_line_size) std::atomic<std::int64_t> m_bottom{0};
    std::int64_t m_top_seen = 0;  // the owner's last look at m_top
    Slot m_slots[kCapacity];
};

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
    std::vector<TraceEvent> events;  // written only by the thread acting as this worker
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

// One parallel_for call, on the caller's stack.
struct ForContext : TaskHeader {
    RangeFn fn;
    const char* name;
    std::uint32_t begin, end, grain;
    std::atomic<std::uint32_t> remaining;  // chunks not yet finished
    std::atomic<bool> failed{false};
    std::mutex error_lock;
    std::exception_ptr error;
    ForContext(RangeFn f, const char* n, std::uint32_t b, std::uint32_t e, std::uint32_t g, std::uint32_t chunks)
        : fn(f), name(n), begin(b), end(e), grain(g), remaining(chunks) {}
};

thread_local Worker* tls_worker = nullptr;

inline std::uint64_t pack(std::uint32_t first, std::uint32_t last) { return (std::uint64_t{first} << 32) | last; }

}  // namespace detail

// How long an idle worker spins before it sleeps.
constexpr std::int64_t kSpinBeforeSleepNs = 200'000;
// Job records a worker trades with the shared pool at once.
constexpr std::size_t kRecordBatch = 64;

using detail::ForContext;
using detail::JobRecord;
using detail::TaskHeader;
using detail::Worker;


namespace {

// Runs chunks [first, last) of a parallel_for one at a time. While some worker is
// idle and nothing is left in our deque for it, it splits off the upper half for it to
// steal (so a thief takes a big piece); otherwise it just runs on, without touching the
// deque: the split is only on demand, like TBB's auto partitioner, yet each chunk is
// still [begin + i*grain, ...), so which worker runs it never changes what it computes.
// The empty-deque condition leaves at most one piece (and one wake-up) waiting.
void run_for(TaskHeader* header, std::uint64_t range, Worker& self) {
    auto* ctx = static_cast<ForContext*>(header);
    auto first = static_cast<std::uint32_t>(range >> 32);
    auto last = static_cast<std::uint32_t>(range & 0xffffffffu);
    const bool tracing = self.system->trace_enabled();
    std::uint32_t ran = 0;
    while (first < last) {
        if (last - first > 1 && self.system->has_idle_worker() && self.deque.looks_empty()) {
            const std::uint32_t mid = first + (last - first) / 2;
            if (self.push(ctx, detail::pack(mid, last))) last = mid;  // full deque: run it all here
        }
        const std::uint32_t lo = ctx->begin + first * ctx->grain;
        const std::uint32_t hi = ctx->end - lo > ctx->grain ? lo + ctx->grain : ctx->end;
        if (!ctx->failed.load(std::memory_order_relaxed)) {
            const std::int64_t t0 = tracing ? now_nanoseconds() : 0;
            try {
                ctx->fn(lo, hi, self.index);
            } catch (...) {
                std::scoped_lock guard(ctx->error_lock);
                if (!ctx->error) ctx->error = std::current_exception();
                ctx->failed.store(true, std::memory_order_relaxed);
            }
            if (tracing) self.record(ctx->name, "parallel_for", t0, now_nanoseconds());
        }
        ++first;
        ++ran;
    }
    // One decrement for the chunks run here (those split off count themselves); after
    // it the context may be gone, as the caller returns once `remaining` is zero.
    ctx->remaining.fetch_sub(ran, std::memory_order_acq_rel);
}

}  // namespace

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

// Runs jobs as `self` until done() holds, idle (spinning, counted in m_idle so that busy
// workers split their ranges for it) while it finds none. Returns no longer idle and
// holding no finished jobs back: the caller may go on with long work of its own.
template <typename Done>
void WorkStealingJobSystem::run_until(Worker& self, Done done) {
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

// ---- parallel_for ----

void WorkStealingJobSystem::parallel_for(const char* name, std::uint32_t begin, std::uint32_t end,
                                         std::uint32_t grain, RangeFn fn) {
    if (end <= begin) return;  // zero items spawn nothing
    if (grain == 0) grain = 1;
    const std::uint32_t chunks = (end - begin - 1) / grain + 1;
    const WorkerScope scope(*this);
    Worker& self = scope.worker;
    ForContext ctx(fn, name, begin, end, grain, chunks);
    ctx.run = &run_for;
    // Offer the upper half at once, whether or not a worker is idle yet: the push wakes
    // sleeping workers, and one spinning between two calls steals it without waiting for
    // the caller to notice it. Splitting after that is on demand (run_for).
    std::uint32_t mine = chunks;
    if (chunks > 1 && worker_count() > 1 && self.push(&ctx, detail::pack(chunks / 2, chunks))) mine = chunks / 2;
    run_for(&ctx, detail::pack(0, mine), self);
    // Our share is done; help with anything (thieves hold the rest of ours) until every
    // chunk finished. The context lives on this stack, so we must not return earlier.
    run_until(self, [&ctx] { return ctx.remaining.load(std::memory_order_acquire) == 0; });
    if (ctx.error) std::rethrow_exception(ctx.error);
}

// ---- submit / wait ----

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

// ---- phases ----

namespace {

// Pauses at a phase barrier before each wait also yields the CPU.
constexpr int kSpinsBeforeYield = 4096;

// Blocks of one participant's share of a phase: each takes half of what is left of the
// share (at least `grain` items), so the first blocks are long and claims are few, and
// the last ones are short, so whoever runs out of its own work first finds little
// left to wait for: the other's last block is one grain.
std::uint32_t block_size(std::uint32_t left, std::uint32_t grain) {
    return left <= grain ? left : std::max(grain, left / 2);
}
std::uint32_t share_blocks(std::uint32_t items, std::uint32_t grain) {
    std::uint32_t blocks = 0;
    for (std::uint32_t left = items; left > 0; left -= block_size(left, grain)) ++blocks;
    return blocks;
}
// Items [lo, hi) of block b of a share of `items`, relative to the share's start.
void share_block(std::uint32_t items, std::uint32_t grain, std::uint32_t b, std::uint32_t& lo, std::uint32_t& hi) {
    std::uint32_t left = items;
    for (std::uint32_t k = 0; k < b; ++k) left -= block_size(left, grain);
    lo = items - left;
    hi = lo + block_size(left, grain);
}

// One run_phases call, on the caller's stack. Each phase is cut into one share per
// participant and each share into blocks. claimed[j] counts the blocks taken from share
// j over every phase so far, done the blocks finished: a phase is over when done
// reaches the blocks of all phases up to it. No counter is reset between phases, so
// a participant that starts late just walks past the phases that are over.
struct PhaseRun {
    std::span<const Phase> phases;
    PhaseFn fn;
    const char* name;
    unsigned participants;
    CacheLinePadded<std::atomic<std::uint32_t>> claimed[WorkStealingJobSystem::kMaxPhaseWorkers];
    CacheLinePadded<std::atomic<std::uint64_t>> done;
};

// Participant `me`: for each phase, its own share first, then what is left of the
// others'; then the barrier.
void take_part(PhaseRun& run, unsigned me, unsigned worker, Worker& self) noexcept {
    const unsigned n = run.participants;
    std::uint32_t taken_before[WorkStealingJobSystem::kMaxPhaseWorkers] = {};  // claimed[j] when the phase began
    std::uint64_t done_target = 0;
    const bool tracing = self.system->trace_enabled();
    for (std::uint32_t p = 0; p < run.phases.size(); ++p) {
        const Phase& phase = run.phases[p];
        if (phase.count == 0) continue;
        const std::uint32_t grain = std::max<std::uint32_t>(phase.grain, 1);
        std::uint64_t ran = 0;
        for (unsigned step = 0; step < n; ++step) {
            const unsigned j = (me + step) % n;
            const auto first = static_cast<std::uint32_t>(std::uint64_t{phase.count} * j / n);
            const auto items = static_cast<std::uint32_t>(std::uint64_t{phase.count} * (j + 1) / n) - first;
            const std::uint32_t blocks = share_blocks(items, grain);
            done_target += blocks;
            const std::uint32_t share_end = taken_before[j] + blocks;
            std::atomic<std::uint32_t>& claimed = run.claimed[j].value;
            std::uint32_t seen = claimed.load(std::memory_order_relaxed);
            while (seen < share_end) {
                if (!claimed.compare_exchange_weak(seen, seen + 1, std::memory_order_relaxed)) continue;
                std::uint32_t lo = 0, hi = 0;
                share_block(items, grain, seen - taken_before[j], lo, hi);
                const std::int64_t t0 = tracing ? now_nanoseconds() : 0;
                run.fn(p, first + lo, first + hi, worker);
                if (tracing) self.record(phase.name, run.name, t0, now_nanoseconds());
                ++ran;
                ++seen;
            }
            taken_before[j] = share_end;
        }
        // Publish this phase's blocks at once (one shared write per phase, not per block).
        if (ran > 0) run.done.value.fetch_add(ran, std::memory_order_release);
        for (int spins = 0; run.done.value.load(std::memory_order_acquire) < done_target; ++spins) {
            if (spins < kSpinsBeforeYield) {
                cpu_pause();
            } else {
                std::this_thread::yield();
            }
        }
    }
}

}  // namespace

void WorkStealingJobSystem::run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) {
    PhaseRun run{phases, fn, name, std::min(worker_count(), kMaxPhaseWorkers), {}, {}};
    // One chunk per participant: the caller takes the first, idle workers steal the rest.
    // A participant waits only for blocks another one has claimed and is running, so
    // it does not matter which worker runs which participant, or whether one runs two.
    parallel_for(name, 0, run.participants, 1, [&run, this](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
        for (std::uint32_t me = lo; me < hi; ++me) take_part(run, me, worker, *m_workers[worker]);
    });
}

// ---- stage graph ----

void WorkStealingJobSystem::run_graph(StageGraph& graph) {
    JobGroup group;
    struct Launch {
        WorkStealingJobSystem* system;
        StageGraph* graph;
        JobGroup* group;
        void start(std::uint32_t node) const {
            StageGraph::Node& n = graph->m_nodes[node];
            const Launch self = *this;
            system->submit(*group, n.name, [self, node](unsigned worker) {
                StageGraph::Node& me = self.graph->m_nodes[node];
                me.fn(worker);
                // Each dependent waits for `prerequisites` nodes; the last one to finish starts it.
                for (std::uint32_t d : me.dependents) {
                    if (self.graph->m_nodes[d].waiting.fetch_sub(1, std::memory_order_acq_rel) == 1) self.start(d);
                }
            });
        }
    };
    const Launch launch{this, &graph, &group};
    for (StageGraph::Node& n : graph.m_nodes) n.waiting.store(n.prerequisites, std::memory_order_relaxed);
    for (std::uint32_t i = 0; i < graph.m_nodes.size(); ++i) {
        if (graph.m_nodes[i].prerequisites == 0) launch.start(i);
    }
    wait(group);
}

std::uint32_t StageGraph::add(const char* name, Fn fn) {
    m_nodes.emplace_back(name, fn);
    return static_cast<std::uint32_t>(m_nodes.size() - 1);
}

void StageGraph::depends_on(std::uint32_t node, std::uint32_t prerequisite) {
    if (node >= m_nodes.size() || prerequisite >= m_nodes.size() || node == prerequisite) {
        throw Error("StageGraph::depends_on: bad node index");
    }
    m_nodes[prerequisite].dependents.push_back(node);
    m_nodes[node].prerequisites += 1;
}

// ---- trace ----

void WorkStealingJobSystem::trace_begin(const char* stage) noexcept {
    if (!trace_enabled()) return;
    std::scoped_lock guard(m_stage_lock);
    m_open_stages.emplace_back(stage, now_nanoseconds());
}

void WorkStealingJobSystem::trace_end() noexcept {
    if (!trace_enabled()) return;
    std::scoped_lock guard(m_stage_lock);
    if (m_open_stages.empty()) return;
    const auto [stage, begin] = m_open_stages.back();
    m_open_stages.pop_back();
    m_stage_events.push_back(TraceEvent{stage, "stage", begin, now_nanoseconds(), 0, current_cpu()});
}

std::vector<TraceEvent> WorkStealingJobSystem::trace_events() const {
    std::vector<TraceEvent> all;
    {
        std::scoped_lock guard(m_stage_lock);
        all = m_stage_events;
    }
    for (const auto& w : m_workers) all.insert(all.end(), w->events.begin(), w->events.end());
    std::sort(all.begin(), all.end(), [](const TraceEvent& a, const TraceEvent& b) { return a.begin_ns < b.begin_ns; });
    return all;
}

void WorkStealingJobSystem::clear_trace() {
    std::scoped_lock guard(m_stage_lock);
    m_stage_events.clear();
    for (auto& w : m_workers) w->events.clear();
}

void write_chrome_trace(std::ostream& out, const std::vector<TraceEvent>& events) {
    out << "{\"traceEvents\":[";
    const std::int64_t origin = events.empty() ? 0 : events.front().begin_ns;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const TraceEvent& e = events[i];
        // Stage spans on their own row (tid 1000) so they frame the job rows.
        const unsigned tid = std::string_view(e.stage) == "stage" ? 1000u : e.worker;
        out << (i ? ",\n" : "\n") << "{\"name\":\"" << e.name << "\",\"cat\":\"" << e.stage
            << "\",\"ph\":\"X\",\"pid\":1,\"tid\":" << tid << ",\"ts\":" << static_cast<double>(e.begin_ns - origin) / 1e3
            << ",\"dur\":" << static_cast<double>(e.end_ns - e.begin_ns) / 1e3 << ",\"args\":{\"worker\":" << e.worker
            << ",\"pu\":" << e.pu << "}}";
    }
    out << "\n],\"displayTimeUnit\":\"ms\"}\n";
}

void WorkStealingJobSystem::write_trace(std::ostream& out) const { write_chrome_trace(out, trace_events()); }

void WorkStealingJobSystem::write_trace(const std::string& path) const {
    std::ofstream out(path);
    if (!out) throw Error(path + ": cannot write the trace");
    write_trace(out);
}

std::unique_ptr<JobSystem> make_job_system(const std::vector<unsigned>& worker_pus, bool pin) {
    if (worker_pus.size() <= 1) return std::make_unique<SingleThreadedJobSystem>();
    return std::make_unique<WorkStealingJobSystem>(WorkStealingJobSystem::Options{worker_pus, pin, "spindle-worker"});
}

}  // namespace spindle
