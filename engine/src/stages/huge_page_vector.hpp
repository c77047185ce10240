// Arrays that grow to megabytes with the scene's contacts (contact records, wide contacts,
// their push-out anchors, solver bodies) are placed on whole huge pages. A first step
// fills tens of megabytes of them, and on virtual machines a small page's first touch
// costs microseconds (the guest's fault and the hypervisor's): 512 of them per 2 MB
// where a huge page takes one. Blocks of a huge page or more are allocated aligned to it
// and rounded up to whole huge pages, so no small page is left at either end, and the
// whole block is asked for as transparent huge pages. Smaller blocks are ordinary ones.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace spindle {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

template <typename T>
struct HugePageAllocator {
    using value_type = T;

    HugePageAllocator() = default;
    template <typename U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

    static bool on_huge_pages(std::size_t n) { return n * sizeof(T) >= kHugePageBytes; }
    static std::size_t rounded_bytes(std::size_t n) {
        return (n * sizeof(T) + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
    }

    T* allocate(std::size_t n) {
        if (!on_huge_pages(n)) return static_cast<T*>(::operator new (n * sizeof(T), std::align_val_t{alignof(T)}));
        if (n > static_cast<std::size_t>(-1) / 2 / sizeof(T)) throw std::bad_array_new_length();
        void* p = std::aligned_alloc(kHugePageBytes, rounded_bytes(n));
        if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        // A hint: where the system gives no huge pages on request, the block stays small pages.
        madvise(p, rounded_bytes(n), MADV_HUGEPAGE);
#endif
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) noexcept {
        if (!on_huge_pages(n)) {
            ::operator delete (p, std::align_val_t{alignof(T)});
        } else {
            std::free(p);
        }
    }

    template <typename U>
    bool operator==(const HugePageAllocator<U>&) const noexcept {
        return true;
    }
};

template <typename T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace spindle
