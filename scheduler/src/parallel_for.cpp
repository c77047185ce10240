// WorkStealingJobSystem::parallel_for: a range of chunks on the caller's stack, split
// in halves on demand while some worker is idle (run_for).
#include "worker.hpp"

#include <spindle/platform/clock.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>

namespace spindle {
namespace detail {

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

inline std::uint64_t pack(std::uint32_t first, std::uint32_t last) { return (std::uint64_t{first} << 32) | last; }

}  // namespace detail

using detail::ForContext;
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
    // Each chunk's span begins where the one before it ended: taking the next chunk (and
    // splitting the range for an idle worker) is this worker's own work, not a wait, and one
    // clock read a chunk, not two, keeps the trace's own cost out of the gaps between them.
    std::int64_t traced_from = tracing ? now_nanoseconds() : 0;
    std::uint32_t ran = 0;
    while (first < last) {
        if (last - first > 1 && self.system->has_idle_worker() && self.deque.looks_empty()) {
            const std::uint32_t mid = first + (last - first) / 2;
            if (self.push(ctx, detail::pack(mid, last))) last = mid;  // full deque: run it all here
        }
        const std::uint32_t lo = ctx->begin + first * ctx->grain;
        const std::uint32_t hi = ctx->end - lo > ctx->grain ? lo + ctx->grain : ctx->end;
        if (!ctx->failed.load(std::memory_order_relaxed)) {
            try {
                ctx->fn(lo, hi, self.index);
            } catch (...) {
                std::scoped_lock guard(ctx->error_lock);
                if (!ctx->error) ctx->error = std::current_exception();
                ctx->failed.store(true, std::memory_order_relaxed);
            }
            if (tracing) {
                const std::int64_t traced_to = now_nanoseconds();
                self.record(ctx->name, "parallel_for", traced_from, traced_to);
                traced_from = traced_to;
            }
        }
        ++first;
        ++ran;
    }
    // One decrement for the chunks run here (those split off count themselves); after
    // it the context may be gone, as the caller returns once `remaining` is zero.
    ctx->remaining.fetch_sub(ran, std::memory_order_acq_rel);
}

}  // namespace

void WorkStealingJobSystem::parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                                         RangeFn fn) {
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

}  // namespace spindle
