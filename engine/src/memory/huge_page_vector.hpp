// Arrays that grow to megabytes with the scene's contacts (contact records, wide contacts,
// their push-out anchors, solver bodies, the broadphase's pair lists) are placed on huge
// pages. A first step fills tens of megabytes of them, and on virtual machines a small
// page's first touch costs microseconds (the guest's fault and the hypervisor's): 512 of
// them per 2 MB where a huge page takes one, and mapping the small pages at once in one
// madvise still leaves each first write the hypervisor's fault (docs/benchmarks.md).
// Blocks of half a huge page or more are allocated aligned to it, on whole huge pages; a
// tail of less than half a huge page past the last whole one is small pages instead (a
// few hundred faults rather than up to 2 MB held for nothing), so a block holds at most
// half a huge page more than its bytes, or twice them. Blocks of a few pages up to that
// share huge pages (medium_blocks.hpp). Smaller blocks are ordinary ones.
#pragma once

#include <cstddef>
#include <cstdint>
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
// From here a block goes on huge pages (huge_block_bytes). Rounding up to them holds at
// most twice the block's bytes, while its small pages would each cost a first write's
// fault: a block just under a huge page (a 10k-body scene's solver bodies) paid 500 of them.
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

// The bytes a block of `bytes` (kOnHugePagesBytes or more) is mapped as: its whole huge
// pages, and a tail of less than half a huge page as whole small pages, or one more huge
// page for a longer tail.
constexpr std::size_t huge_block_bytes(std::size_t bytes) {
    constexpr std::size_t kSmallPage = 4096;
    const std::size_t whole = bytes / kHugePageBytes * kHugePageBytes;
    const std::size_t tail = bytes - whole;
    if (tail >= kHugePageBytes / 2) return whole + kHugePageBytes;
    return whole + (tail + kSmallPage - 1) / kSmallPage * kSmallPage;
}

// The whole huge pages of a block of `bytes` mapped as huge_block_bytes(bytes).
constexpr std::size_t whole_huge_pages(std::size_t bytes) { return huge_block_bytes(bytes) / kHugePageBytes; }

// A block of `bytes` (huge_block_bytes: whole huge pages, then whole small pages) starting
// on a huge page, its whole huge pages asked for as transparent huge pages. On Linux a
// mapping of its own, not the heap's: heap memory a program freed before keeps the small
// pages it was written on, and asking for huge pages does not replace those, so a block
// from it paid the small pages' faults again wherever the heap had been used. A hint:
// where the system gives no huge pages on request, the block stays small pages. Throws
// std::bad_alloc. Any thread.
void* map_huge_pages(std::size_t bytes);

// Gives back a block of map_huge_pages(bytes), the same `bytes`.
void unmap_huge_pages(void* p, std::size_t bytes) noexcept;

// Moves the huge page mapped at `from` (a block of map_huge_pages(kHugePageBytes)) onto
// the huge page at `to`, inside another block, by its page tables: whatever lay at `to` is
// replaced, and `from` is no longer mapped. False where the move failed (then `from` is
// given back and `to` is as it was) or the system has no such call.
bool move_huge_page(void* from, void* to) noexcept;

// The bytes the process holds in every block map_huge_pages mapped and has not given back
// (arrays on huge pages, the medium block pool's chunks, stocked pages): the pages of them
// in memory, as the system counts them (mincore), so a huge page written anywhere is 2 MB,
// a small page 4 KB, and a page never written nothing. Memory a count of the heap does not
// see. Any thread; walks every block: for tests and benchmarks.
std::size_t mapped_bytes_held();

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
    // The count is checked before it is turned into bytes, for every kind of block: a count
    // whose bytes wrap would otherwise ask for a small block.
    static constexpr std::size_t max_size() noexcept { return static_cast<std::size_t>(-1) / 2 / sizeof(T); }
    T* allocate(std::size_t n) {
        if (n > max_size()) throw std::bad_array_new_length();
        return allocate_in(tier(n * sizeof(T)), n * sizeof(T));
    }
    void deallocate(T* p, std::size_t n) noexcept { deallocate_in(tier(n * sizeof(T)), p, n * sizeof(T)); }
    // A block of `bytes` of a kind, and its giving back: for allocators that choose the kind
    // their own way (WholeHugePageAllocator).
    static T* allocate_in(Tier kind, std::size_t bytes) {
        switch (kind) {
            case Tier::kHeap: return static_cast<T*>(::operator new (bytes, std::align_val_t{alignof(T)}));
            case Tier::kMedium: return static_cast<T*>(allocate_medium_block(bytes));
            case Tier::kHugePages: return static_cast<T*>(map_huge_pages(huge_block_bytes(bytes)));
        }
        return nullptr;
    }
    static void deallocate_in(Tier kind, T* p, std::size_t bytes) noexcept {
        switch (kind) {
            case Tier::kHeap: ::operator delete (p, std::align_val_t{alignof(T)}); return;
            case Tier::kMedium: free_medium_block(p, bytes); return;
            case Tier::kHugePages: unmap_huge_pages(p, huge_block_bytes(bytes)); return;
        }
    }

    template <typename U>
    bool operator==(const HugePageAllocator<U>&) const noexcept {
        return true;
    }
};

template <typename T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

// HugePageAllocator without its medium blocks: whole huge pages from kOnHugePagesBytes, the
// heap below. For an array a step makes whole at once, which for a large level is a
// megabyte or more: on the heap that is a mapping of fresh small pages (glibc maps such
// blocks apart), each first write a fault, where whole huge pages fault once per 2 MB.
// Below, the heap: a medium block would share the pool's chunks with the first step's
// lists, whose small levels fill one (Jolt's pyramid's took a second 2 MB chunk for its
// tree's 159 KB of child boxes).
template <typename T>
struct WholeHugePageAllocator : HugePageAllocator<T> {
    using value_type = T;

    WholeHugePageAllocator() = default;
    template <typename U>
    WholeHugePageAllocator(const WholeHugePageAllocator<U>&) noexcept {}

    using Tier = typename HugePageAllocator<T>::Tier;
    static Tier tier(std::size_t bytes) { return bytes >= kOnHugePagesBytes ? Tier::kHugePages : Tier::kHeap; }
    T* allocate(std::size_t n) {
        if (n > HugePageAllocator<T>::max_size()) throw std::bad_array_new_length();
        return HugePageAllocator<T>::allocate_in(tier(n * sizeof(T)), n * sizeof(T));
    }
    void deallocate(T* p, std::size_t n) noexcept {
        HugePageAllocator<T>::deallocate_in(tier(n * sizeof(T)), p, n * sizeof(T));
    }

    template <typename U>
    bool operator==(const WholeHugePageAllocator<U>&) const noexcept {
        return true;
    }
};

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
