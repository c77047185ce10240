// Huge pages stocked ahead of a first step (memory/page_stock.hpp): Space::reserve_bodies
// stocks them, the step moves them under its arrays instead of faulting fresh ones, and the
// update after it gives back the rest.
#include <gtest/gtest.h>
#include <spindle/engine/space.hpp>
#include <spindle/scene/scene.hpp>

#include <cstddef>
#include <string>
#include <vector>

#include "api/space_internals.hpp"
#include "memory/huge_page_vector.hpp"
#include "memory/medium_blocks.hpp"
#include "memory/page_stock.hpp"
#include "stages/stages.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

using namespace spindle;

#if defined(__linux__) && defined(MREMAP_FIXED)
// A stocked page is moved, not copied nor faulted again: the huge page it lands on is
// resident before anything touches it, and the one beside it is not.
TEST(PageStock, AMovedPageIsInPlaceBeforeItsFirstTouch) {
    const std::size_t before = stocked_huge_pages();
    stock_huge_page();
    ASSERT_EQ(stocked_huge_pages(), before + 1);
    void* block = map_huge_pages(2 * kHugePageBytes);
    auto* second = static_cast<unsigned char*>(block) + kHugePageBytes;
    ASSERT_TRUE(move_stocked_huge_page_to(block));
    EXPECT_EQ(stocked_huge_pages(), before);
    constexpr std::size_t kPages = kHugePageBytes / 4096;
    std::vector<unsigned char> resident(kPages);
    const auto resident_pages = [&](void* page) {
        EXPECT_EQ(mincore(page, kHugePageBytes, resident.data()), 0);
        std::size_t count = 0;
        for (const unsigned char r : resident) count += r & 1u;
        return count;
    };
    EXPECT_EQ(resident_pages(block), kPages) << "the moved page's small pages are not all resident";
    EXPECT_EQ(resident_pages(second), 0u) << "the untouched page beside it is resident";
    static_cast<unsigned char*>(block)[123] = 7;  // the block is ours to write
    EXPECT_EQ(static_cast<unsigned char*>(block)[123], 7);
    unmap_huge_pages(block, 2 * kHugePageBytes);
}
#endif

// Jolt's pyramid (1240 boxes): the first step's contact records fill whole huge pages, and
// those come from the stock reserve_bodies made; the update gives back what is left.
TEST(PageStock, AFirstStepTakesItsPagesFromTheStockItsBodiesReserved) {
    const std::size_t before = stocked_huge_pages();
    const SceneDesc scene = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/pyramid.toml");
    Space space{scene.settings};
    build(scene, space);
    World& world = SpaceInternals::world(space);
    ASSERT_GT(world.stocked_pages, 0u) << "reserve_bodies stocked nothing";
    const std::size_t ready = stocked_huge_pages();
    EXPECT_EQ(ready, before + world.stocked_pages);

    // The step alone, as update takes it after ApplyWrites (flush), so that the stock is
    // seen before the update gives it back. The medium block pool takes a stocked page for
    // each new chunk; the rest went under arrays.
    space.flush();
    const std::size_t chunks = medium_block_counts().chunks;
    step(world, scene.settings.time_step.duration);
    const std::size_t new_chunks = medium_block_counts().chunks - chunks;
    const std::size_t taken = ready - stocked_huge_pages() - new_chunks;
    const std::size_t contact_bytes = world.contacts.size() * sizeof(Contact);
    ASSERT_GE(contact_bytes, kOnHugePagesBytes) << "the test needs contact records on whole huge pages";
    const std::size_t contact_pages = (contact_bytes + kHugePageBytes - 1) / kHugePageBytes;
    EXPECT_GE(taken, contact_pages) << "the contact records' pages were not the stock's";

    space.update();
    EXPECT_EQ(world.stocked_pages, 0u);
    EXPECT_EQ(stocked_huge_pages(), before) << "the pages the step did not take were not given back";
}
