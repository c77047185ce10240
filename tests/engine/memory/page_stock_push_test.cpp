// A page the stock maps is never lost when its address finds no room in the stock's list
// (memory/page_stock.cpp, PageStock::add): a program of its own, for it replaces the global
// operator new to make that list's growth fail.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdlib>
#include <fstream>
#include <new>

#include "memory/huge_page_vector.hpp"
#include "memory/page_stock.hpp"

namespace {

bool g_fail_allocations = false;  // this test's thread only sets it, around one call

}  // namespace

void* operator new(std::size_t bytes) {
    if (g_fail_allocations) throw std::bad_alloc();
    if (void* p = std::malloc(bytes == 0 ? 1 : bytes)) return p;
    throw std::bad_alloc();
}
// GCC takes the new it inlines into a caller for the standard one, whose memory free()
// must not get: this program's new is malloc().
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace {

// The bytes this process has mapped (/proc/self/statm), read with allocations allowed.
std::size_t mapped_bytes() {
    std::ifstream statm("/proc/self/statm");
    std::size_t pages = 0;
    statm >> pages;
    return pages * 4096;
}

}  // namespace

using namespace spindle;

#if defined(__linux__)
// Stocks pages until one's push must grow the list, with every allocation failing: that
// call throws, the stock is as it was, and the page it mapped and wrote is unmapped (the
// process maps no more than before, where a lost page would add 2 MB).
TEST(PageStock, APageWhoseAddressFindsNoRoomIsUnmapped) {
    const std::size_t before = stocked_huge_pages();
    std::size_t added = 0;
    bool thrown = false;
    for (int k = 0; k < 64 && !thrown; ++k) {
        const std::size_t mapped = mapped_bytes();
        g_fail_allocations = true;
        try {
            stock_huge_page();
            added += 1;
        } catch (const std::bad_alloc&) {
            thrown = true;
        }
        g_fail_allocations = false;
        if (!thrown) continue;
        EXPECT_EQ(stocked_huge_pages(), before + added);
        EXPECT_LT(mapped_bytes(), mapped + kHugePageBytes / 2) << "the page that found no room stays mapped";
    }
    EXPECT_TRUE(thrown) << "the stock's list never had to grow";
    EXPECT_EQ(give_back_stocked_huge_pages(added), added);
}
#endif
