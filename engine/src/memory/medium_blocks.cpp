#include "memory/medium_blocks.hpp"

#include <array>
#include <cstdint>
#include <mutex>
#include <new>
#include <vector>

#include "memory/huge_page_vector.hpp"
#include "memory/page_stock.hpp"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#define SPINDLE_POISON(p, n) ASAN_POISON_MEMORY_REGION(p, n)
#define SPINDLE_UNPOISON(p, n) ASAN_UNPOISON_MEMORY_REGION(p, n)
#else
#define SPINDLE_POISON(p, n) ((void)(p), (void)(n))
#define SPINDLE_UNPOISON(p, n) ((void)(p), (void)(n))
#endif

namespace spindle {

namespace {

static_assert(kHugePageBytes % kMediumBlockMinBytes == 0 && kMediumBlockEndBytes <= kHugePageBytes,
              "a chunk is one huge page of whole units");

// A chunk is kUnits units of kMediumBlockMinBytes, kept as one mask; a block is a run of
// free units, the first that fits, so blocks of every size share chunks and few chunks
// stand part-used: a chunk's huge page is all written, used or not.
constexpr std::uint32_t kUnits = kHugePageBytes / kMediumBlockMinBytes;
static_assert(kUnits == 32 && kMediumBlockEndBytes / kMediumBlockMinBytes < kUnits,
              "a bit per unit in a 32-bit mask, a block's run shorter than it");

struct Chunk {
    std::uintptr_t base = 0;
    std::uint32_t used = 0;  // a bit per unit
};

// Gives a chunk back to the system. ASan (of GCC 12) keeps a range's poison past munmap,
// so the chunk is unpoisoned first: the next mapping there may be anyone's.
void unmap_chunk(void* p) noexcept {
    SPINDLE_UNPOISON(p, kHugePageBytes);
    unmap_huge_pages(p, kHugePageBytes);
}

// The units of a block of `bytes`, under kUnits, and its run of them as a mask.
std::uint32_t units_of(std::size_t bytes) {
    return static_cast<std::uint32_t>(medium_block_bytes(bytes) / kMediumBlockMinBytes);
}
std::uint32_t mask_of(std::size_t bytes) { return (std::uint32_t{1} << units_of(bytes)) - 1; }

class MediumBlockPool {
public:
    void* allocate(std::size_t bytes) {
        const std::uint32_t units = units_of(bytes);
        const std::uint32_t mask = mask_of(bytes);
        const std::lock_guard lock(m_mutex);
        // First fit over the chunks in use, then an empty one, then a new one.
        for (const bool empty : {false, true}) {
            for (Chunk& chunk : m_chunks) {
                if ((chunk.used == 0) != empty) continue;
                for (std::uint32_t unit = 0; unit + units <= kUnits; ++unit) {
                    if (((chunk.used >> unit) & mask) != 0) continue;
                    if (chunk.used == 0) --m_empty;
                    return take(chunk, unit, mask, bytes);
                }
            }
        }
        // A stocked page is mapped and written already; else one call maps the chunk's huge
        // page (or its small pages where none is given).
        void* p = take_stocked_huge_page();
        if (p == nullptr) {
            p = map_huge_pages(kHugePageBytes);  // throws std::bad_alloc
            map_pages_now(p, kHugePageBytes);
        }
        SPINDLE_POISON(p, kHugePageBytes);
        try {
            m_chunks.push_back(Chunk{reinterpret_cast<std::uintptr_t>(p), 0});
        } catch (...) {
            unmap_chunk(p);
            throw;
        }
        return take(m_chunks.back(), 0, mask, bytes);
    }

    void free(void* p, std::size_t bytes) noexcept {
        const std::uint32_t mask = mask_of(bytes);
        const auto address = reinterpret_cast<std::uintptr_t>(p);
        const std::uintptr_t base = address & ~(std::uintptr_t{kHugePageBytes} - 1);
        const std::lock_guard lock(m_mutex);
        for (std::size_t i = 0; i < m_chunks.size(); ++i) {
            Chunk& chunk = m_chunks[i];
            if (chunk.base != base) continue;
            chunk.used &= ~(mask << ((address - base) / kMediumBlockMinBytes));
            m_blocks[medium_block_size_index(bytes)] -= 1;
            SPINDLE_POISON(p, medium_block_bytes(bytes));
            if (chunk.used != 0 || ++m_empty <= kKeptEmptyMediumChunks) return;
            unmap_chunk(reinterpret_cast<void*>(chunk.base));
            m_chunks[i] = m_chunks.back();
            m_chunks.pop_back();
            --m_empty;
            return;
        }
    }

    MediumBlockCounts counts() {
        const std::lock_guard lock(m_mutex);
        return MediumBlockCounts{m_chunks.size(), m_empty, m_blocks};
    }

private:
    void* take(Chunk& chunk, std::uint32_t unit, std::uint32_t mask, std::size_t bytes) {
        chunk.used |= mask << unit;
        m_blocks[medium_block_size_index(bytes)] += 1;
        void* p = reinterpret_cast<void*>(chunk.base + std::size_t{unit} * kMediumBlockMinBytes);
        SPINDLE_UNPOISON(p, bytes);  // the block's tail past `bytes` stays poisoned
        return p;
    }

    std::mutex m_mutex;
    std::vector<Chunk> m_chunks;
    std::size_t m_empty = 0;                                // chunks with no block in use
    std::array<std::size_t, kMediumBlockSizes> m_blocks{};  // blocks in use, by size
};

// Never destroyed: arrays of objects destroyed at exit may give their blocks back after
// any static pool would be gone.
MediumBlockPool& pool() {
    static MediumBlockPool* const instance = new MediumBlockPool;
    return *instance;
}

}  // namespace

void* allocate_medium_block(std::size_t bytes) { return pool().allocate(bytes); }

void free_medium_block(void* p, std::size_t bytes) noexcept { pool().free(p, bytes); }

MediumBlockCounts medium_block_counts() { return pool().counts(); }

}  // namespace spindle
