// The Chase-Lev work-stealing deque each worker owns: the owner pushes and pops at the
// bottom, thieves steal from the top.
#pragma once

#include <spindle/platform/spin.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <atomic>
#include <cstdint>

namespace spindle::detail {

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

}  // namespace spindle::detail
