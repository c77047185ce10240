// The medium block pool (memory/medium_blocks.hpp) and the huge page stock
// (memory/page_stock.hpp) are process-wide: jobs on every worker grow arrays and map their
// pages at once, and no two live blocks may share a byte. Under ThreadSanitizer (the
// threaded label) a pool or a stock without its lock is a race here even where no block
// overlaps.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <thread>
#include <vector>

#include "memory/huge_page_vector.hpp"
#include "memory/page_stock.hpp"

using namespace spindle;

namespace {

// Runs work(mark, &ok) on two threads at once, each with a mark of its own; whether each
// thread's work kept its ok.
struct BothOk {
    bool first = true, second = true;
};
template <typename Work>
BothOk on_two_threads(Work work) {
    BothOk ok;
    std::thread a(work, 0xa5, &ok.first);
    std::thread b(work, 0x5a, &ok.second);
    a.join();
    b.join();
    return ok;
}

}  // namespace

TEST(MediumBlocks, ThreadsAllocatingAtOnceGetBlocksOfTheirOwn) {
    constexpr int kRounds = 1000;
    constexpr std::size_t kPage = 4096;
    auto churn = [](unsigned char mark, bool* ok) {
        for (int r = 0; r < kRounds; ++r) {
            std::vector<HugePageVector<unsigned char>> live(4);
            for (int k = 0; k < 4; ++k) {
                // 64 KB to 512 KB and a little: every size the pool serves.
                live[k].reserve((std::size_t{64} << 10 << ((r + k) % 4)) + 100 * k);
                for (std::size_t i = 0; i < live[k].capacity(); i += kPage) live[k].data()[i] = mark;
            }
            std::this_thread::yield();
            for (const auto& v : live) {
                for (std::size_t i = 0; i < v.capacity(); i += kPage) *ok = *ok && v.data()[i] == mark;
            }
        }
    };
    const BothOk ok = on_two_threads(churn);
    EXPECT_TRUE(ok.first) << "a block of the first thread's was written by the second";
    EXPECT_TRUE(ok.second) << "a block of the second thread's was written by the first";
}

// map_room's jobs move stocked pages under their arrays at once: each page goes to one of them.
TEST(PageStock, ThreadsMovingStockedPagesAtOnceGetPagesOfTheirOwn) {
    constexpr int kPagesEach = 8;
    const std::size_t before = stocked_huge_pages();
    for (int i = 0; i < 2 * kPagesEach; ++i) stock_huge_page();
    auto move = [](unsigned char mark, bool* ok) {
        std::vector<unsigned char*> blocks;
        for (int i = 0; i < kPagesEach; ++i) {
            auto* block = static_cast<unsigned char*>(map_huge_pages(kHugePageBytes));
            *ok = move_stocked_huge_page_to(block) && *ok;
            std::memset(block, mark, kHugePageBytes);
            blocks.push_back(block);
            std::this_thread::yield();
        }
        for (unsigned char* block : blocks) {
            for (std::size_t i = 0; i < kHugePageBytes; i += 4096) *ok = *ok && block[i] == mark;
            unmap_huge_pages(block, kHugePageBytes);
        }
    };
    const BothOk ok = on_two_threads(move);
    EXPECT_TRUE(ok.first) << "the first thread's page was not moved, or was written by the second";
    EXPECT_TRUE(ok.second) << "the second thread's page was not moved, or was written by the first";
    EXPECT_EQ(stocked_huge_pages(), before);
}
