// map_room (stages/capacity.hpp): the room of a growing array mapped in jobs before its
// elements are made there; the array's block (memory/huge_page_vector.hpp) whole huge
// pages where the system gives them on request. Mapping is a hint: the elements and
// their count stay as they were. A smaller block of a few pages has its pages mapped by
// the allocation.
#include <spindle/scheduler/work_stealing.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#endif

#include "huge_page_mode.hpp"
#include "memory/huge_page_vector.hpp"
#include "memory/medium_blocks.hpp"
#include "stages/capacity.hpp"
#include "stages/contact_index.hpp"

using namespace spindle;

namespace {

constexpr std::size_t kRoomBytes = std::size_t{16} << 20;  // several whole huge pages, wherever it starts

using test::huge_page_mode;

// Kilobytes of huge pages in the mappings that hold any of [begin, end), from
// /proc/self/smaps.
std::uint64_t huge_page_kb_over(std::uintptr_t begin, std::uintptr_t end) {
    std::ifstream smaps("/proc/self/smaps");
    std::uint64_t kb = 0;
    bool inside = false;
    for (std::string line; std::getline(smaps, line);) {
        std::uintptr_t from = 0, to = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> from >> dash >> to && dash == '-') {
            inside = from < end && begin < to;
        } else if (inside && line.rfind("AnonHugePages:", 0) == 0) {
            kb += std::stoull(line.substr(line.find(':') + 1));
        }
    }
    return kb;
}

// Kilobytes of huge pages the whole process holds, from /proc/self/smaps_rollup.
std::uint64_t huge_page_kb_held() {
    std::ifstream rollup("/proc/self/smaps_rollup");
    for (std::string line; std::getline(rollup, line);) {
        if (line.rfind("AnonHugePages:", 0) == 0) return std::stoull(line.substr(line.find(':') + 1));
    }
    return 0;
}

// The process's resident bytes, from /proc/self/smaps_rollup.
std::int64_t resident_bytes() {
    std::ifstream rollup("/proc/self/smaps_rollup");
    for (std::string line; std::getline(rollup, line);) {
        if (line.rfind("Rss:", 0) == 0) return 1024 * std::stoll(line.substr(line.find(':') + 1));
    }
    return 0;
}

// Whether every whole page inside [begin, end) is mapped (mincore).
bool all_pages_mapped(std::uintptr_t begin, std::uintptr_t end) {
    const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
    const std::uintptr_t first = (begin + page - 1) / page * page;
    const std::uintptr_t last = end / page * page;
    std::vector<unsigned char> mapped((last - first) / page);
    if (mincore(reinterpret_cast<void*>(first), last - first, mapped.data()) != 0) return false;
    for (const unsigned char m : mapped) {
        if ((m & 1) == 0) return false;
    }
    return true;
}

}  // namespace

TEST(MapRoom, LeavesTheElementsAndTheirCountAsTheyWere) {
    const auto jobs = make_job_system({0, 0}, false);
    HugePageVector<std::uint64_t> v(1000);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = i * 7919;
    v.reserve(kRoomBytes / sizeof(std::uint64_t));
    map_room(*jobs, v, v.capacity());
    ASSERT_EQ(v.size(), 1000u);
    for (std::size_t i = 0; i < v.size(); ++i) ASSERT_EQ(v[i], i * 7919) << "element " << i;
    v.resize(v.capacity());  // the mapped room takes elements as any room does
    EXPECT_EQ(v.back(), 0u);
    EXPECT_EQ(v[999], 999u * 7919);
}

TEST(MapRoom, MapsTheRoomOnHugePages) {
    // Only where huge pages come on request does the request show: "always" gives them
    // unasked, "never" not at all.
    if (huge_page_mode() != "madvise") GTEST_SKIP() << "transparent huge pages are not given on request here";
    const auto jobs = make_job_system({0, 0}, false);
    HugePageVector<unsigned char> v;
    v.reserve(kRoomBytes);
    const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
    EXPECT_EQ(begin % kHugePageBytes, 0u) << "a block of huge pages starts on one";
    map_room(*jobs, v, v.capacity());
    // The request reached the kernel. How many of the room's huge pages it finds free
    // depends on the machine's memory at the time, so not all are asked for here: the
    // block's start on a huge page (above) is what leaves no small page at its ends.
    EXPECT_GT(huge_page_kb_over(begin, begin + v.capacity()), 0u);
}

TEST(HugePageVector, SmallBlocksAreOrdinaryOnes) {
    HugePageVector<double> v(1000);
    v.push_back(1);
    EXPECT_EQ(v.back(), 1);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % alignof(double), 0u);
    // Grown past a huge page and back: each block freed the way it was allocated (the
    // sanitizer builds check the pairing).
    v.resize(kHugePageBytes / sizeof(double) + 1, 2.0);
    EXPECT_EQ(v[999], 0);
    EXPECT_EQ(v[1000], 1);
    v.resize(10);
    v.shrink_to_fit();
    EXPECT_EQ(v.size(), 10u);
}

// mapped_bytes_held is what the process holds beyond the heap, as the system counts it: a
// block of a huge page and a tail of a few small pages, written whole, holds that huge page
// and those small pages (not two huge pages), and a medium block holds its chunk's whole
// huge page where it needed a new one; given back, nothing (bench_engine adds it to the
// heap's count for its bytes a body).
TEST(HugePageVector, BlocksBeyondTheHeapAreCountedAsTheProcessHoldsThem) {
    if (resident_bytes() == 0) GTEST_SKIP() << "no /proc/self/smaps_rollup here";
    constexpr std::size_t kTailBytes = std::size_t{300} << 10;
    const auto start = static_cast<std::int64_t>(mapped_bytes_held());
    const std::int64_t resident_start = resident_bytes();
    const auto held = [&] { return static_cast<std::int64_t>(mapped_bytes_held()) - start; };
    // What the process took since the start is the count's, give or take the heap's noise
    // (the streams' buffers, the list of blocks, the output: up to a few hundred KB seen),
    // while a count wrong by a chunk or by a huge page for a tail is wrong by 1 MB or more.
    // A sanitizer's shadow of the blocks is resident too: there only the count is checked.
    const auto as_resident = [&](const char* what) {
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
        constexpr std::int64_t kNoise = std::int64_t{512} << 10;
        const std::int64_t taken = resident_bytes() - resident_start;
        EXPECT_LT(std::abs(taken - held()), kNoise) << what << ": the process took " << taken;
#else
        (void)what, (void)resident_start;
#endif
    };
    {
        HugePageVector<unsigned char> v;
        v.reserve(kHugePageBytes + kTailBytes - 100);
        ASSERT_EQ(v.capacity(), kHugePageBytes + kTailBytes - 100);
        EXPECT_EQ(held(), 0) << "a block never written holds nothing";
        v.resize(v.capacity(), 1);
        EXPECT_EQ(held(), static_cast<std::int64_t>(kHugePageBytes + kTailBytes))
            << "the tail is not whole small pages";
        as_resident("a huge page and a tail");
        HugePageVector<unsigned char> m;
        m.resize(kMediumBlockMinBytes * 2, 2);
        as_resident("a medium block's chunk");
        EXPECT_EQ(v.back(), 1);
        EXPECT_EQ(m.back(), 2);
    }
    EXPECT_LE(held(), static_cast<std::int64_t>(kKeptEmptyMediumChunks * kHugePageBytes))
        << "a block given back is still counted (or more chunks are kept than the pool keeps)";
    as_resident("given back");
}

TEST(HugePageVector, ACountWhoseBytesWouldWrapIsRefusedForEveryKindOfBlock) {
    // 2^61 + k doubles are 8k bytes once multiplied out in 64 bits: a heap block and a
    // medium block's size if the count were not checked first.
    HugePageAllocator<double> allocator;
    const std::size_t wraps = (std::size_t{1} << 61) + 1;
    EXPECT_THROW((void)allocator.allocate(wraps), std::bad_array_new_length);
    EXPECT_THROW((void)allocator.allocate(wraps + kMediumBlockMinBytes / sizeof(double)), std::bad_array_new_length);
    EXPECT_THROW((void)allocator.allocate(HugePageAllocator<double>::max_size() + 1), std::bad_array_new_length);
    double* kept = allocator.allocate(8);
    kept[7] = 1;
    allocator.deallocate(kept, 8);
}

TEST(HugePageVector, MapsTheSmallPagesOfABlockOfAFewPagesAtOnce) {
    // Under kOnHugePagesBytes but over kMediumBlockMinBytes: a medium block, its pages
    // mapped before anything is written there.
    HugePageVector<unsigned char> v;
    v.reserve(kOnHugePagesBytes / 2);
    ASSERT_LT(v.capacity(), kOnHugePagesBytes);
    ASSERT_GE(v.capacity(), kMediumBlockMinBytes);
    const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
    EXPECT_TRUE(all_pages_mapped(begin, begin + v.capacity()));
}

TEST(MediumBlocks, ArraysOfAFewPagesShareAHugePage) {
    // A first step's dozen arrays of 64 KB to 1 MB each paid a fault per small page; on
    // whole huge pages of their own each would round up to 2 MB.
    if (huge_page_mode() != "madvise") GTEST_SKIP() << "transparent huge pages are not given on request here";
    constexpr std::size_t kBytes = std::size_t{200} << 10;
    const MediumBlockCounts before = medium_block_counts();
    ASSERT_EQ(before.chunks, before.empty_chunks) << "no medium block in use before";
    HugePageVector<unsigned char> a, b;
    a.reserve(kBytes);
    b.reserve(kBytes);
    const auto begin_a = reinterpret_cast<std::uintptr_t>(a.data());
    const auto begin_b = reinterpret_cast<std::uintptr_t>(b.data());
    EXPECT_EQ(begin_a / kHugePageBytes, begin_b / kHugePageBytes) << "both blocks in one huge page";
    EXPECT_NE(begin_a, begin_b);
    a.resize(kBytes, 1);
    b.resize(kBytes, 2);
    EXPECT_EQ(a.back(), 1);  // neither block overlaps the other
    EXPECT_EQ(b.front(), 2);
    // The kernel may have no huge page free: then the chunk is small pages, and this says so.
    EXPECT_GT(huge_page_kb_over(begin_a, begin_a + kBytes), 0u);
}

TEST(MediumBlocks, BlocksTakeTheirWholeUnitsNotAPowerOfTwo) {
    // Five arrays of 384 KB (six units each) fill 30 of a chunk's 32 units. Rounded up to
    // powers of two (512 KB) they took 2.5 MB, two chunks: the pyramid's nine blocks of
    // 1.63 MB took two chunks so (issue 19).
    constexpr std::size_t kBytes = std::size_t{384} << 10;
    const MediumBlockCounts before = medium_block_counts();
    ASSERT_EQ(before.chunks, before.empty_chunks) << "no medium block in use before";
    std::vector<HugePageVector<unsigned char>> arrays(5);
    for (auto& v : arrays) v.reserve(kBytes);
    const auto chunk_of = [](const HugePageVector<unsigned char>& v) {
        return reinterpret_cast<std::uintptr_t>(v.data()) / kHugePageBytes;
    };
    for (const auto& v : arrays) EXPECT_EQ(chunk_of(v), chunk_of(arrays[0])) << "five blocks of six units in one chunk";
    const MediumBlockCounts counts = medium_block_counts();
    EXPECT_EQ(counts.chunks - counts.empty_chunks, 1u);
    EXPECT_EQ(counts.blocks[medium_block_size_index(kBytes)], 5u);
    EXPECT_EQ(medium_block_size_index(kBytes), 5u);  // six units
}

TEST(MediumBlocks, AFreedBlockServesTheNextOfItsSize) {
    // An array that moves as it grows (fit_capacity, a vector's regrowth) takes memory
    // already written instead of fresh pages.
    constexpr std::size_t kBytes = std::size_t{300} << 10;
    std::uintptr_t first = 0;
    {
        HugePageVector<unsigned char> v;
        v.reserve(kBytes);
        first = reinterpret_cast<std::uintptr_t>(v.data());
    }
    HugePageVector<unsigned char> w;
    w.reserve(kBytes + 1000);  // another size, the same units
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(w.data()), first);
}

TEST(MediumBlocks, EmptyChunksBeyondAFewAreGivenBack) {
    // A pile that came apart leaves its arrays small again: the pool keeps a few empty huge
    // pages for the next blocks, not every one it ever held.
    const MediumBlockCounts before = medium_block_counts();
    {
        std::vector<HugePageVector<unsigned char>> arrays(40);
        for (auto& v : arrays) v.reserve(kOnHugePagesBytes - 1);  // two to a chunk: 20 chunks
        EXPECT_GE(medium_block_counts().chunks, 20u);
    }
    const MediumBlockCounts after = medium_block_counts();
    EXPECT_LE(after.empty_chunks, kKeptEmptyMediumChunks);
    EXPECT_LE(after.chunks, before.chunks - before.empty_chunks + kKeptEmptyMediumChunks);
}

TEST(MediumBlocks, AChunkGivenBackLeavesNoPoisonForTheNextMapping) {
    // Under ASan the pool poisons its free blocks. A chunk it gives back to the system must
    // not stay poisoned: the next mapping there (a huge-page array of its own, 2 MB aligned
    // like a chunk) was reported as used after poison, its first write in the broadphase's
    // pair list (Determinism.ContactsMadeAndLostByTheThousand..., session 28's CI).
#if defined(__SANITIZE_ADDRESS__)
    std::vector<std::uintptr_t> chunks;
    {
        std::vector<HugePageVector<unsigned char>> arrays(40);
        for (auto& v : arrays) {
            v.reserve(kOnHugePagesBytes - 1);  // two to a chunk: 20 chunks
            chunks.push_back(reinterpret_cast<std::uintptr_t>(v.data()) & ~(std::uintptr_t{kHugePageBytes} - 1));
        }
    }
    // Every chunk is empty now; the pool keeps a few (poisoned, its own) and gives back the rest.
    std::size_t poisoned = 0;
    std::sort(chunks.begin(), chunks.end());
    chunks.erase(std::unique(chunks.begin(), chunks.end()), chunks.end());
    for (const std::uintptr_t base : chunks) poisoned += __asan_address_is_poisoned(reinterpret_cast<void*>(base)) != 0;
    EXPECT_LE(poisoned, medium_block_counts().empty_chunks) << "of " << chunks.size() << " chunks";
#else
    GTEST_SKIP() << "poisoning is ASan's";
#endif
}

TEST(HugePageVector, PutsABlockJustUnderAHugePageOnOne) {
    // A 10k-body scene's solver bodies came to just under a huge page: on small pages,
    // each of their 500 pages paid a first write's fault.
    if (huge_page_mode() != "madvise") GTEST_SKIP() << "transparent huge pages are not given on request here";
    constexpr std::size_t kPage = 4096;
    constexpr std::size_t kBytes = kHugePageBytes - 16 * kPage;
    static_assert(kBytes >= kOnHugePagesBytes);
    HugePageVector<unsigned char> v;
    v.reserve(kBytes);
    const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
    EXPECT_EQ(begin % kHugePageBytes, 0u) << "a block of huge pages starts on one";
    v.resize(kBytes);
    for (std::size_t i = 0; i < kBytes; i += kPage) v[i] = 1;
    // One huge page, so any huge page seen is all of it (the kernel may have none free:
    // then the block is still whole small pages, and this check says so).
    EXPECT_GT(huge_page_kb_over(begin, begin + kBytes), 0u);
}

TEST(ContactIndex, KeepsItsSlotsOnHugePages) {
    // A first step's rehashes fill the slots from one thread: on small pages each page's
    // first write was a fault.
    if (huge_page_mode() != "madvise") GTEST_SKIP() << "transparent huge pages are not given on request here";
    const std::uint64_t before = huge_page_kb_held();
    ContactIndex index;
    index.reserve(kHugePageBytes / sizeof(std::uint64_t) / 2);  // a huge page of keys
    ASSERT_TRUE(index.insert(7, 1));
    EXPECT_GT(huge_page_kb_held(), before);
}
