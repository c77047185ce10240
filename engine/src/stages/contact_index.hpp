// ContactIndex: pair key -> position in World::contacts, an open-addressing table (linear
// probing, keys and positions in flat arrays). A first step makes tens of thousands of
// contacts: a node-based map allocated one node per contact and took twice the memory.
// Never iterated, so its order cannot reach results. Its arrays are on the huge-page
// allocator: a first step's rehashes fill megabytes of fresh memory from one thread.
#pragma once

#include <cstddef>
#include <cstdint>

#include "memory/huge_page_vector.hpp"

namespace spindle {

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
        std::size_t hole = home(key);
        for (; m_keys[hole] != key; hole = next(hole)) {
            if (m_keys[hole] == kEmpty) return;
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
        --m_size;
    }

    // Room for `count` keys without growing (at most half the slots full).
    void reserve(std::size_t count) {
        std::size_t slots = m_keys.empty() ? kMinSlots : m_keys.size();
        while (slots < 2 * count) slots *= 2;
        if (slots > m_keys.size()) rehash(slots);
    }

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

    void rehash(std::size_t slots) {
        HugePageVector<std::uint64_t> keys(slots, kEmpty);
        HugePageVector<std::uint32_t> positions(slots);
        keys.swap(m_keys);
        positions.swap(m_positions);
        m_shift = 64;
        for (std::size_t s = slots; s > 1; s /= 2) --m_shift;
        m_size = 0;
        for (std::size_t i = 0; i < keys.size(); ++i) {
            if (keys[i] != kEmpty) insert(keys[i], positions[i]);
        }
    }

    HugePageVector<std::uint64_t> m_keys;  // kEmpty where free; a power of two long
    HugePageVector<std::uint32_t> m_positions;
    std::size_t m_size = 0;
    int m_shift = 64;
};

}  // namespace spindle
