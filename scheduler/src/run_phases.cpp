// WorkStealingJobSystem::run_phases: one participant per worker runs every phase, each
// phase's items in shares and blocks, with a spinning barrier between phases (one after a
// run of phases that fit in one block each): each participant publishes the blocks it
// finished, the others add them up.
#include "worker.hpp"

#include <spindle/platform/clock.hpp>
#include <spindle/platform/spin.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <span>
#include <thread>

namespace spindle {

using detail::Worker;

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

// A phase whose items fit in one block. Consecutive ones run as one round: the participant
// that claims the first runs them all back to back, in order, and everyone meets at one
// barrier after the last. Split, they would leave all but one participant idle anyway, and
// each barrier between them costs a round trip between cores.
bool one_block(const Phase& phase) { return phase.count <= std::max<std::uint32_t>(phase.grain, 1); }

// One run_phases call, on the caller's stack. Each phase is cut into one share per
// participant and each share into blocks. claimed[r % 2][j] counts the blocks taken from
// share j over every other round so far (r counts the rounds with items), finished[j] the
// blocks participant j has run: a phase is over when the finished blocks add up to the
// blocks of all phases up to it. No counter is reset between phases, so a participant that
// starts late just walks past the phases that are over. A round of one-block phases is one
// block of share 0.
//
// Two claim counters a share, a round's and the next's: whoever finishes its own share first
// takes the other's counter to its core, claiming what is left of it, so the owner's first
// claim of the next round would fetch it back (one transfer between cores as every round
// begins, on its critical path). While a round runs nobody touches the next round's
// counters, so each participant fetches its own for writing at the start of a round
// (a prefetch: it waits for nothing) and finds it in its cache when the next one begins.
//
// Each participant writes only its own finished count (a plain store), and the others
// read it: the last to finish a phase does not first take a shared counter from the
// cores that wait on it (a locked add), so they see its count one cache-line transfer
// after it is done, while it reads theirs. A participant that claimed no block of the
// phase is not waited for (it may be descheduled, or not started: the same thread may
// run two participants one after the other).
struct PhaseRun {
    std::span<const Phase> phases;
    PhaseFn fn;
    const char* name;
    unsigned participants;
    CacheLinePadded<std::atomic<std::uint32_t>> claimed[2][WorkStealingJobSystem::kMaxPhaseWorkers];
    CacheLinePadded<std::atomic<std::uint64_t>> finished[WorkStealingJobSystem::kMaxPhaseWorkers];
    std::uint64_t phases_run = 0;  // phases with items and rounds, counted by participant 0,
    std::uint64_t barriers = 0;    // which walks every round
};

// Waits until the blocks finished by all participants add up to `target`, this one's
// being `mine`.
void wait_for_blocks(PhaseRun& run, unsigned me, std::uint64_t mine, std::uint64_t target) noexcept {
    for (int spins = 0;; ++spins) {
        std::uint64_t sum = mine;
        for (unsigned j = 0; j < run.participants; ++j) {
            if (j != me) sum += run.finished[j].value.load(std::memory_order_acquire);
        }
        if (sum >= target) return;
        if (spins < kSpinsBeforeYield) {
            cpu_pause();
        } else {
            std::this_thread::yield();
        }
    }
}

// Participant `me`'s part of a round of one-block phases [p, end): the whole round if it
// claims it (from the round's counter of share 0). Returns the blocks it ran (0 or 1).
std::uint64_t run_one_block_round(PhaseRun& run, std::uint32_t p, std::uint32_t end, std::uint32_t share_end,
                                  unsigned parity, unsigned worker, Worker& self) noexcept {
    std::atomic<std::uint32_t>& claimed = run.claimed[parity][0].value;
    std::uint32_t seen = claimed.load(std::memory_order_relaxed);
    while (seen < share_end) {
        if (!claimed.compare_exchange_weak(seen, seen + 1, std::memory_order_relaxed)) continue;
        const bool tracing = self.system->trace_enabled();
        std::int64_t traced_from = tracing ? now_nanoseconds() : 0;  // each phase's span begins where the last ended
        for (std::uint32_t q = p; q < end; ++q) {
            const Phase& phase = run.phases[q];
            if (phase.count == 0) continue;
            run.fn(q, 0, phase.count, worker);
            if (!tracing) continue;
            const std::int64_t traced_to = now_nanoseconds();
            self.record(phase.name, run.name, traced_from, traced_to);
            traced_from = traced_to;
        }
        return 1;
    }
    return 0;
}

// Participant `me`: for each round (a phase, or consecutive one-block phases), its own
// share first, then what is left of the others'; then the barrier.
void take_part(PhaseRun& run, unsigned me, unsigned worker, Worker& self) noexcept {
    const unsigned n = run.participants;
    // claimed[r % 2][j] when round r began, and r % 2 (flipped as each round begins)
    std::uint32_t taken_before[2][WorkStealingJobSystem::kMaxPhaseWorkers] = {};
    unsigned parity = 1;
    std::uint64_t done_target = 0;  // blocks of the rounds so far
    std::uint64_t mine = 0;         // blocks this participant ran, as in finished[me]
    const bool tracing = self.system->trace_enabled();
    const auto phase_count = static_cast<std::uint32_t>(run.phases.size());
    for (std::uint32_t p = 0, end = 0; p < phase_count; p = end) {
        const Phase& phase = run.phases[p];
        end = p + 1;
        if (phase.count == 0) continue;
        if (me == 0) {
            ++run.phases_run;
            ++run.barriers;
        }
        std::uint64_t ran = 0;
        parity ^= 1;
        __builtin_prefetch(&run.claimed[parity ^ 1][me].value, 1);  // for writing, next round
        std::int64_t traced_from = 0;  // when this participant claimed its first block of a split phase
        if (one_block(phase)) {
            while (end < phase_count && one_block(run.phases[end])) {
                if (me == 0 && run.phases[end].count > 0) ++run.phases_run;
                ++end;
            }
            done_target += 1;
            taken_before[parity][0] += 1;
            ran = run_one_block_round(run, p, end, taken_before[parity][0], parity, worker, self);
        } else {
            const std::uint32_t grain = std::max<std::uint32_t>(phase.grain, 1);
            for (unsigned step = 0; step < n; ++step) {
                const unsigned j = (me + step) % n;
                const auto first = static_cast<std::uint32_t>(std::uint64_t{phase.count} * j / n);
                const auto items = static_cast<std::uint32_t>(std::uint64_t{phase.count} * (j + 1) / n) - first;
                const std::uint32_t blocks = share_blocks(items, grain);
                done_target += blocks;
                const std::uint32_t share_end = taken_before[parity][j] + blocks;
                std::atomic<std::uint32_t>& claimed = run.claimed[parity][j].value;
                std::uint32_t seen = claimed.load(std::memory_order_relaxed);
                while (seen < share_end) {
                    if (!claimed.compare_exchange_weak(seen, seen + 1, std::memory_order_relaxed)) continue;
                    std::uint32_t lo = 0, hi = 0;
                    share_block(items, grain, seen - taken_before[parity][j], lo, hi);
                    if (tracing && ran == 0) traced_from = now_nanoseconds();
                    run.fn(p, first + lo, first + hi, worker);
                    ++ran;
                    ++seen;
                }
                taken_before[parity][j] = share_end;
            }
        }
        // Publish this round's blocks at once (one store per round, not per block).
        if (ran > 0) {
            mine += ran;
            run.finished[me].value.store(mine, std::memory_order_release);
        }
        // One span per participant and phase, from its first block to the end of its last:
        // between its blocks it claims the next one, which is its own work, not a wait, so
        // only the barrier below is left out of it (and a block costs no clock reads). Taken
        // after the blocks are published: the clock read and the record would otherwise hold
        // up every participant waiting for them, in a traced run only.
        if (tracing && ran > 0 && !one_block(phase)) self.record(phase.name, run.name, traced_from, now_nanoseconds());
        wait_for_blocks(run, me, mine, done_target);
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
    m_phases_run.fetch_add(run.phases_run, std::memory_order_relaxed);
    m_phase_barriers.fetch_add(run.barriers, std::memory_order_relaxed);
}

}  // namespace spindle
