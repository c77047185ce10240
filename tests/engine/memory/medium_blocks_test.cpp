// The medium block pool (memory/medium_blocks.hpp) is process-wide: jobs on every worker
// grow arrays at once, and no two live blocks may share a byte. Under ThreadSanitizer (the
// threaded label) a pool without its lock is a race here even where no block overlaps.
#include <gtest/gtest.h>

#include <cstddef>
#include <thread>
#include <vector>

#include "memory/huge_page_vector.hpp"

using namespace spindle;

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
    bool ok_a = true, ok_b = true;
    std::thread a(churn, 0xa5, &ok_a);
    std::thread b(churn, 0x5a, &ok_b);
    a.join();
    b.join();
    EXPECT_TRUE(ok_a) << "a block of the first thread's was written by the second";
    EXPECT_TRUE(ok_b) << "a block of the second thread's was written by the first";
}
