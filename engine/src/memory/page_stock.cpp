#include "memory/page_stock.hpp"

#include <cstdint>
#include <mutex>
#include <new>
#include <vector>

#include "memory/huge_page_vector.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace spindle {

namespace {

class PageStock {
public:
    void add() {
        auto* const page = static_cast<unsigned char*>(map_huge_pages(kHugePageBytes));
        map_pages_now(page, kHugePageBytes);
        // A byte per small page as well, for the hypervisor's first write (stages/capacity.hpp).
        for (std::size_t b = 0; b < kHugePageBytes; b += 4096) *reinterpret_cast<volatile unsigned char*>(page + b) = 0;
        // A page that finds no room in the list is unmapped, never lost.
        try {
            const std::lock_guard lock(m_mutex);
            m_pages.push_back(reinterpret_cast<std::uintptr_t>(page));
        } catch (...) {
            unmap_huge_pages(page, kHugePageBytes);
            throw;
        }
    }

    void* take() noexcept {
        const std::lock_guard lock(m_mutex);
        if (m_pages.empty()) return nullptr;
        const std::uintptr_t page = m_pages.back();
        m_pages.pop_back();
        return reinterpret_cast<void*>(page);
    }

    std::size_t give_back(std::size_t pages) noexcept {
        std::size_t given = 0;
        for (; given < pages; ++given) {
            void* page = take();
            if (page == nullptr) break;
            unmap_huge_pages(page, kHugePageBytes);
        }
        return given;
    }

    std::size_t count() noexcept {
        const std::lock_guard lock(m_mutex);
        return m_pages.size();
    }

private:
    std::mutex m_mutex;
    std::vector<std::uintptr_t> m_pages;  // each a huge page's address, mapped and written
};

// Never destroyed, as the medium block pool (medium_blocks.cpp).
PageStock& stock() {
    static PageStock* const instance = new PageStock;
    return *instance;
}

}  // namespace

void stock_huge_page() { stock().add(); }

void* take_stocked_huge_page() noexcept { return stock().take(); }

bool move_stocked_huge_page_to(void* where) noexcept {
#if defined(__linux__) && defined(MREMAP_FIXED)
    void* page = stock().take();
    return page != nullptr && move_huge_page(page, where);
#else
    (void)where;
    return false;
#endif
}

std::size_t give_back_stocked_huge_pages(std::size_t pages) noexcept { return stock().give_back(pages); }

std::size_t stocked_huge_pages() noexcept { return stock().count(); }

}  // namespace spindle
