// Arrays that grow to megabytes with the scene's contacts (contact records, wide contacts,
// their push-out anchors, solver bodies, the broadphase's pair lists) are placed on huge
// pages. A first step fills tens of megabytes of them, and on virtual machines a small
// page's first touch costs microseconds (the guest's fault and the hypervisor's): 512 of
// them per 2 MB where a huge page takes one, and mapping the small pages at once in one
// madvise still leaves each first write the hypervisor's fault (docs/benchmarks.md).
// Blocks of half a huge page or more are allocated aligned to it and rounded up to whole
// huge pages, so no small page is left at either end, and the whole block is asked for as
// transparent huge pages. Blocks of a few pages up to that share huge pages
// (medium_blocks.hpp). Smaller blocks are ordinary ones.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "memory/medium_blocks.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace spindle {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;
// From here a block goes on whole huge pages. Rounding up to them holds at most twice
// the block's bytes, while its small pages would each cost a first write's fault: a
// block just under a huge page (a 10k-body scene's solver bodies) paid 500 of them.
inline constexpr std::size_t kOnHugePagesBytes = kHugePageBytes / 2;
// Blocks from kMediumBlockMinBytes up to this share huge pages; smaller ones mostly come
// from heap memory already mapped.
static_assert(kOnHugePagesBytes == kMediumBlockEndBytes, "medium blocks end where whole huge pages begin");

// Maps the whole small pages inside [p, p + bytes) now, for writing, without changing
// their contents. A hint: where the call is missing, the pages fault on first touch.
inline void map_pages_now(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    constexpr std::uintptr_t kPage = 4096;
    const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(p) + kPage - 1) / kPage * kPage;
    const std::uintptr_t last = (reinterpret_cast<std::uintptr_t>(p) + bytes) / kPage * kPage;
    if (first < last) madvise(reinterpret_cast<void*>(first), last - first, MADV_POPULATE_WRITE);
#else
    (void)p, (void)bytes;
#endif
}

// A block of `bytes` (whole huge pages) starting on a huge page. On Linux a mapping of
// its own, not the heap's: heap memory a program freed before keeps the small pages it
// was written on, and asking for huge pages does not replace those, so a block from it
// paid the small pages' faults again wherever the heap had been used. A hint: where the
// system gives no huge pages on request, the block stays small pages.
inline void* map_huge_pages(std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // Over-map by a huge page, then give back the ends outside the aligned block.
    void* raw = mmap(nullptr, bytes + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const auto begin = reinterpret_cast<std::uintptr_t>(raw);
    const std::uintptr_t aligned = (begin + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
    if (aligned > begin) munmap(raw, aligned - begin);
    if (const std::uintptr_t tail = begin + kHugePageBytes - aligned; tail > 0)
        munmap(reinterpret_cast<void*>(aligned + bytes), tail);
    madvise(reinterpret_cast<void*>(aligned), bytes, MADV_HUGEPAGE);
    return reinterpret_cast<void*>(aligned);
#else
    void* p = std::aligned_alloc(kHugePageBytes, bytes);
    if (p == nullptr) throw std::bad_alloc();
    return p;
#endif
}

inline void unmap_huge_pages(void* p, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    munmap(p, bytes);
#else
    (void)bytes;
    std::free(p);
#endif
}

// The bytes of the arrays HugePageAllocator holds on huge pages and medium blocks (each at
// the size it takes there), process-wide: memory a count of the heap does not see. The
// chunks and stocked pages not under an array are not in it.
inline std::atomic<std::int64_t> g_huge_array_bytes{0};
inline std::int64_t huge_array_bytes() noexcept { return g_huge_array_bytes.load(std::memory_order_relaxed); }

template <typename T>
struct HugePageAllocator {
    using value_type = T;

    HugePageAllocator() = default;
    template <typename U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

    // The three kinds of block (this file's head): ordinary heap blocks, medium blocks sharing
    // huge pages, whole huge pages.
    enum class Tier { kHeap, kMedium, kHugePages };
    static Tier tier(std::size_t bytes) {
        if (bytes >= kOnHugePagesBytes) return Tier::kHugePages;
        return bytes >= kMediumBlockMinBytes ? Tier::kMedium : Tier::kHeap;
    }
    static std::size_t rounded_bytes(std::size_t bytes) {
        return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
    }
    // What a block of `bytes` takes beyond the heap: its medium block or its huge pages.
    static std::int64_t held_bytes(std::size_t bytes) {
        const Tier t = tier(bytes);
        return static_cast<std::int64_t>(t == Tier::kHeap     ? 0
                                         : t == Tier::kMedium ? medium_block_bytes(bytes)
                                                              : rounded_bytes(bytes));
    }

    // The count is checked before it is turned into bytes, for every kind of block: a count
    // whose bytes wrap would otherwise ask for a small block.
    static constexpr std::size_t max_size() noexcept { return static_cast<std::size_t>(-1) / 2 / sizeof(T); }
    T* allocate(std::size_t n) {
        if (n > max_size()) throw std::bad_array_new_length();
        const std::size_t bytes = n * sizeof(T);
        void* p = nullptr;
        switch (tier(bytes)) {
            case Tier::kHeap: return static_cast<T*>(::operator new (bytes, std::align_val_t{alignof(T)}));
            case Tier::kMedium: p = allocate_medium_block(bytes); break;
            case Tier::kHugePages: p = map_huge_pages(rounded_bytes(bytes)); break;
        }
        g_huge_array_bytes.fetch_add(held_bytes(bytes), std::memory_order_relaxed);  // once it is held
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) noexcept {
        const std::size_t bytes = n * sizeof(T);
        g_huge_array_bytes.fetch_sub(held_bytes(bytes), std::memory_order_relaxed);
        switch (tier(bytes)) {
            case Tier::kHeap: ::operator delete (p, std::align_val_t{alignof(T)}); return;
            case Tier::kMedium: free_medium_block(p, bytes); return;
            case Tier::kHugePages: unmap_huge_pages(p, rounded_bytes(bytes)); return;
        }
    }

    template <typename U>
    bool operator==(const HugePageAllocator<U>&) const noexcept {
        return true;
    }
};

template <typename T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

// HugePageAllocator whose resize leaves the new elements unconstructed: the code after
// each growing resize must construct every new element in place (placement new) before
// anything else touches the array, so that jobs construct a first step's records instead
// of the resizing thread (World::contacts, create_contacts). Copies, moves and shrinking
// resizes are as usual.
template <typename T>
struct PlacedByCallerAllocator : HugePageAllocator<T> {
    PlacedByCallerAllocator() = default;
    template <typename U>
    PlacedByCallerAllocator(const PlacedByCallerAllocator<U>&) noexcept {}

    template <typename U>
    void construct(U*) noexcept {}
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

// HugePageAllocator whose resize leaves the new elements' bytes as they are: for arrays
// that the code after each resize writes whole, element by element, before anything
// reads them (the solver's per-step arrays, the broadphase's pair lists). A first
// step's megabytes are then first written by the jobs that fill them, split over the
// workers, instead of zeroed by the resizing thread first. Only for types with nothing
// to destroy, so that an element never written is harmless.
template <typename T>
struct RawRoomAllocator : PlacedByCallerAllocator<T> {
    RawRoomAllocator() = default;
    template <typename U>
    RawRoomAllocator(const RawRoomAllocator<U>&) noexcept {}

    using PlacedByCallerAllocator<T>::construct;
    template <typename U>
    void construct(U*) noexcept {
        static_assert(std::is_trivially_destructible_v<U>, "raw room holds no object that needs destroying");
    }
};

template <typename T>
using RawRoomVector = std::vector<T, RawRoomAllocator<T>>;

}  // namespace spindle
