// ContactIndex: pair key -> position in World::contacts, an open-addressing table (linear
// probing, keys and positions in flat arrays). A first step makes tens of thousands of
// contacts: a node-based map allocated one node per contact and took twice the memory.
// Never iterated, so its order cannot reach results. Its arrays are on the huge-page
// allocator: a first step's rehashes fill megabytes of fresh memory from one thread.
// Besides one key at a time, it takes many distinct keys from jobs: claims by
// compare-and-swap (a linear-probing table holds the same keys whatever the order of
// their inserts) and erases split by the runs of full slots (an erase shifts keys only
// inside its key's run). Which slot a key lands in may then depend on the jobs' timing,
// which nothing reads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "memory/huge_page_vector.hpp"

namespace spindle {

class JobSystem;

class ContactIndex {
public:
    // The position stored for key, or null.
    std::uint32_t* find(std::uint64_t key) noexcept {
        if (m_keys.empty()) return nullptr;
        for (std::size_t i = home(key);; i = next(i)) {
            if (m_keys[i] == key) return &m_positions[i];
            if (m_keys[i] == kEmpty) return nullptr;
        }
    }
    bool contains(std::uint64_t key) noexcept { return find(key) != nullptr; }

    // Stores key -> position unless key is there already; whether it stored.
    bool insert(std::uint64_t key, std::uint32_t position) {
        if (2 * (m_size + 1) > m_keys.size()) rehash(m_keys.empty() ? kMinSlots : 2 * m_keys.size());
        std::size_t i = home(key);
        for (; m_keys[i] != kEmpty; i = next(i)) {
            if (m_keys[i] == key) return false;
        }
        m_keys[i] = key;
        m_positions[i] = position;
        ++m_size;
        return true;
    }

    // Removes key if present. Later keys of its run shift back into the hole (no
    // tombstones: lookups stay as short as the load allows).
    void erase(std::uint64_t key) noexcept {
        if (m_keys.empty()) return;
        if (erase_in_run(key)) --m_size;
    }

    // Room for `count` keys without growing (at most half the slots full). With `jobs`, a
    // rehash fills the new slots and moves the keys in jobs.
    void reserve(std::size_t count, JobSystem* jobs = nullptr) {
        const std::size_t slots = slots_for(count);
        if (slots > m_keys.size()) rehash(slots, jobs);
    }
    // The slots an empty index reserves for `count` keys (a first step's: stages/capacity.hpp).
    static constexpr std::size_t slots_for(std::size_t count) {
        std::size_t slots = kMinSlots;
        while (slots < 2 * count) slots *= 2;
        return slots;
    }

    // Many distinct keys from jobs: reserve() room for them first; then claim() each, from
    // any number of jobs at once (nothing else may touch the index meanwhile): the key's
    // slot, or kNotClaimed when the key is there already. Then, after those jobs, on one
    // thread, add_claimed(how many were claimed); and give each claimed slot its position
    // (set_position_at, from jobs: one slot each) before the next find().
    static constexpr std::uint32_t kNotClaimed = ~std::uint32_t{0};
    std::uint32_t claim(std::uint64_t key) noexcept;
    void add_claimed(std::size_t count) noexcept { m_size += count; }
    void set_position_at(std::uint32_t slot, std::uint32_t position) noexcept { m_positions[slot] = position; }

    // Erases keys[p] for each p in positions (the keys distinct, each in the index), in jobs:
    // the slots are cut at empty slots into ranges, each range's keys erased by one job.
    void erase_at(JobSystem& jobs, std::span<const std::uint32_t> positions, std::span<const std::uint64_t> keys);

    std::size_t size() const noexcept { return m_size; }
    std::size_t heap_bytes() const noexcept {
        return m_keys.capacity() * sizeof(std::uint64_t) + m_positions.capacity() * sizeof(std::uint32_t);
    }

private:
    // No pair key is all ones: its two slots differ.
    static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
    static constexpr std::size_t kMinSlots = 64;

    // Fibonacci hashing: the top bits of key times 2^64 / phi spread neighbouring slots' keys.
    std::size_t home(std::uint64_t key) const noexcept {
        return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ull) >> m_shift);
    }
    std::size_t next(std::size_t i) const noexcept { return (i + 1) & (m_keys.size() - 1); }

    // Erases key, if there, without counting: reads and writes only the run of full slots
    // holding the key's home, so erases in different runs may run at once.
    bool erase_in_run(std::uint64_t key) noexcept {
        std::size_t hole = home(key);
        for (; m_keys[hole] != key; hole = next(hole)) {
            if (m_keys[hole] == kEmpty) return false;
        }
        for (std::size_t i = next(hole); m_keys[i] != kEmpty; i = next(i)) {
            // The key at i may fill the hole unless its home lies cyclically in (hole, i].
            const std::size_t h = home(m_keys[i]);
            const bool stays = hole < i ? (hole < h && h <= i) : (hole < h || h <= i);
            if (stays) continue;
            m_keys[hole] = m_keys[i];
            m_positions[hole] = m_positions[i];
            hole = i;
        }
        m_keys[hole] = kEmpty;
        return true;
    }

    // Raw room: the keys are filled with kEmpty here (in jobs when given), and a position
    // is read only where a key is.
    void rehash(std::size_t slots, JobSystem* jobs = nullptr);

    RawRoomVector<std::uint64_t> m_keys;  // kEmpty where free; a power of two long
    RawRoomVector<std::uint32_t> m_positions;
    std::size_t m_size = 0;
    int m_shift = 64;
};

}  // namespace spindle
