// The blocks mapped for huge pages (huge_page_vector.hpp), and the list of them that says
// what the process holds there.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <new>
#include <vector>

#include "memory/huge_page_vector.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace spindle {

namespace {

struct Block {
    std::uintptr_t begin = 0;
    std::size_t bytes = 0;
};

// Every block mapped and not given back, under a lock: blocks come and go a few times a
// step at most.
class Blocks {
public:
    void add(void* p, std::size_t bytes) {
        const std::lock_guard lock(m_mutex);
        m_blocks.push_back(Block{reinterpret_cast<std::uintptr_t>(p), bytes});
    }
    void remove(void* p) noexcept {
        const std::lock_guard lock(m_mutex);
        const auto at = std::find_if(m_blocks.begin(), m_blocks.end(),
                                     [p](const Block& b) { return b.begin == reinterpret_cast<std::uintptr_t>(p); });
        if (at == m_blocks.end()) return;
        *at = m_blocks.back();
        m_blocks.pop_back();
    }
    std::size_t held() {
        constexpr std::size_t kPage = 4096;
        const std::lock_guard lock(m_mutex);
        std::size_t held = 0;
        std::vector<unsigned char> resident;
        for (const Block& b : m_blocks) {
#if defined(__linux__)
            resident.resize((b.bytes + kPage - 1) / kPage);
            if (mincore(reinterpret_cast<void*>(b.begin), b.bytes, resident.data()) != 0) continue;
            held += kPage * static_cast<std::size_t>(
                                std::count_if(resident.begin(), resident.end(), [](unsigned char r) { return r & 1; }));
#else
            held += b.bytes;
#endif
        }
        return held;
    }

private:
    std::mutex m_mutex;
    std::vector<Block> m_blocks;
};

// Never destroyed, as the medium block pool (medium_blocks.cpp), and not on the heap: a
// block whose place in the list cannot be had is given back through it.
Blocks& blocks() {
    alignas(Blocks) static unsigned char storage[sizeof(Blocks)];
    static Blocks* const instance = new (storage) Blocks;
    return *instance;
}

}  // namespace

void* map_huge_pages(std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // Over-map by a huge page, then give back the ends outside the aligned block.
    void* raw = mmap(nullptr, bytes + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const auto begin = reinterpret_cast<std::uintptr_t>(raw);
    const std::uintptr_t aligned = (begin + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
    if (aligned > begin) munmap(raw, aligned - begin);
    if (const std::uintptr_t tail = begin + kHugePageBytes - aligned; tail > 0)
        munmap(reinterpret_cast<void*>(aligned + bytes), tail);
    // The whole huge pages only: a small-page tail asked for them too would take on the
    // flag of a neighbour mapping merged with it.
    if (const std::size_t whole = bytes / kHugePageBytes * kHugePageBytes; whole > 0)
        madvise(reinterpret_cast<void*>(aligned), whole, MADV_HUGEPAGE);
    void* p = reinterpret_cast<void*>(aligned);
#else
    void* p = std::aligned_alloc(kHugePageBytes, (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes);
    if (p == nullptr) throw std::bad_alloc();
#endif
    try {
        blocks().add(p, bytes);
    } catch (...) {
        unmap_huge_pages(p, bytes);
        throw;
    }
    return p;
}

void unmap_huge_pages(void* p, std::size_t bytes) noexcept {
    blocks().remove(p);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    munmap(p, bytes);
#else
    (void)bytes;
    std::free(p);
#endif
}

bool move_huge_page(void* from, void* to) noexcept {
#if defined(__linux__) && defined(MREMAP_FIXED)
    // The page tables move, not the bytes: a huge page stays one.
    if (mremap(from, kHugePageBytes, kHugePageBytes, MREMAP_MAYMOVE | MREMAP_FIXED, to) == to) {
        blocks().remove(from);
        return true;
    }
    unmap_huge_pages(from, kHugePageBytes);
    return false;
#else
    (void)from, (void)to;
    return false;
#endif
}

std::size_t mapped_bytes_held() { return blocks().held(); }

}  // namespace spindle
