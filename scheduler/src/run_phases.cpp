// WorkStealingJobSystem::run_phases: one participant per worker runs every phase, each
// phase's items in shares and blocks, with a spinning barrier between phases.
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
        std::int64_t traced_from = 0;  // when this participant claimed its first block of the phase
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
                if (tracing && ran == 0) traced_from = now_nanoseconds();
                run.fn(p, first + lo, first + hi, worker);
                ++ran;
                ++seen;
            }
            taken_before[j] = share_end;
        }
        // One span per participant and phase, from its first block to the end of its last:
        // between its blocks it claims the next one, which is its own work, not a wait, so
        // only the barrier below is left out of it (and a block costs no clock reads).
        if (tracing && ran > 0) self.record(phase.name, run.name, traced_from, now_nanoseconds());
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

}  // namespace spindle
