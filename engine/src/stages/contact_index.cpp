// ContactIndex's work in jobs: the rehash's fill and moves, claims of many keys at once,
// and erases split by runs of full slots.
#include "stages/contact_index.hpp"

#include <spindle/scheduler/job_system.hpp>

#include <algorithm>
#include <atomic>
#include <vector>

namespace spindle {
namespace {

// Slots per job when a rehash fills or moves them.
constexpr std::uint32_t kIndexSlotGrain = 16384;
// Below this many slots a rehash runs on the calling thread (no job pays for itself).
constexpr std::size_t kIndexJobSlots = 65536;
// Erases run on the calling thread below this many keys or slots.
constexpr std::size_t kEraseJobKeys = 512;
// Ranges of slots the erases are split into, each one job's. The result does not depend on
// it: a key is erased from the same run, and only its slot's place may differ.
constexpr std::uint32_t kEraseRanges = 8;

}  // namespace

std::uint32_t ContactIndex::claim(std::uint64_t key) noexcept {
    for (std::size_t i = home(key);; i = next(i)) {
        std::atomic_ref<std::uint64_t> slot(m_keys[i]);
        std::uint64_t seen = slot.load(std::memory_order_relaxed);
        // Relaxed: the jobs' join orders these writes before anything reads the slots.
        while (seen == kEmpty && !slot.compare_exchange_weak(seen, key, std::memory_order_relaxed)) {
        }
        if (seen == kEmpty) return static_cast<std::uint32_t>(i);
        if (seen == key) return kNotClaimed;
    }
}

void ContactIndex::rehash(std::size_t slots, JobSystem* jobs) {
    RawRoomVector<std::uint64_t> keys(slots);
    RawRoomVector<std::uint32_t> positions(slots);
    keys.swap(m_keys);
    positions.swap(m_positions);
    m_shift = 64;
    for (std::size_t s = slots; s > 1; s /= 2) --m_shift;
    // The old keys are distinct, so claims may move them in any order.
    const auto move_keys = [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t i = lo; i < hi; ++i) {
            if (keys[i] != kEmpty) m_positions[claim(keys[i])] = positions[i];
        }
    };
    const auto fill = [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        std::fill(m_keys.begin() + lo, m_keys.begin() + hi, kEmpty);
    };
    if (jobs == nullptr || slots < kIndexJobSlots) {
        fill(0, static_cast<std::uint32_t>(slots), 0);
        move_keys(0, static_cast<std::uint32_t>(keys.size()), 0);
        return;
    }
    jobs->parallel_for("IndexFill", 0, static_cast<std::uint32_t>(slots), kIndexSlotGrain, fill);
    if (m_size > 0)
        jobs->parallel_for("IndexMove", 0, static_cast<std::uint32_t>(keys.size()), kIndexSlotGrain, move_keys);
}

void ContactIndex::erase_at(JobSystem& jobs, std::span<const std::uint32_t> positions,
                            std::span<const std::uint64_t> keys) {
    if (positions.empty() || m_keys.empty()) return;
    const std::size_t slots = m_keys.size();
    if (positions.size() < kEraseJobKeys || slots < kIndexJobSlots) {
        for (const std::uint32_t p : positions) erase(keys[p]);
        return;
    }
    // Slots counted from the first empty one (at most half are full: there is one), so that
    // a run that wraps past the last slot is one range of these counts. The ranges start at
    // empty slots, so every run of full slots, and every erase's shifts, lie inside one.
    std::size_t first_empty = 0;
    while (m_keys[first_empty] != kEmpty) ++first_empty;
    const std::size_t mask = slots - 1;
    std::size_t starts[kEraseRanges + 1];
    starts[0] = first_empty;
    for (std::uint32_t r = 1; r < kEraseRanges; ++r) {
        std::size_t s = std::max(starts[r - 1], first_empty + r * (slots / kEraseRanges));
        while (s < first_empty + slots && m_keys[s & mask] != kEmpty) ++s;
        starts[r] = s;
    }
    starts[kEraseRanges] = first_empty + slots;
    std::atomic<std::size_t> erased{0};
    jobs.parallel_for("IndexErase", 0, kEraseRanges, 1, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        std::size_t count = 0;
        for (const std::uint32_t p : positions) {
            const std::uint64_t key = keys[p];
            const std::size_t h = home(key);
            const std::size_t counted = h < first_empty ? h + slots : h;
            if (counted < starts[lo] || counted >= starts[hi]) continue;
            count += erase_in_run(key) ? 1u : 0u;
        }
        erased.fetch_add(count, std::memory_order_relaxed);
    });
    m_size -= erased.load(std::memory_order_relaxed);
}

}  // namespace spindle
