// Huge pages stocked ahead of a first step (memory/page_stock.hpp): Space::create_body
// stocks what the new bodies' first step will write, by the pairs their fat boxes make or the
// game's count of contacts, the step moves them under its arrays instead of faulting fresh
// ones, and the update after it gives back the rest.
#include <gtest/gtest.h>
#include <spindle/engine/space.hpp>
#include <spindle/scene/scene.hpp>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "api/memory_report.hpp"
#include "api/space_internals.hpp"
#include "huge_page_mode.hpp"
#include "memory/huge_page_vector.hpp"
#include "memory/medium_blocks.hpp"
#include "memory/page_stock.hpp"
#include "solver/constraints.hpp"
#include "solver/solver_body.hpp"
#include "stages/capacity.hpp"
#include "stages/stages.hpp"
#include "static_bodies.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#include <sys/resource.h>
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
// those come from the stock its bodies made; the update gives back what is left.
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

namespace {

// The page faults this process has taken (the kernel's minor faults: no disk).
[[maybe_unused]] long minor_faults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

// The fresh small pages a first step may write: its small lists' growth (many_pyramids':
// 122), far from the 336 of one array of a megabyte on the heap.
[[maybe_unused]] constexpr long kFewFreshPages = 300;

// A level of `count` boxes in a grid, `spacing` apart (2 m: none touches), above a floor.
// make_grid's floor: a static slab whose top is y = 0.
void make_floor(Space& space) { test::add_static_box(space, Vec3(1000, 1, 1000), Vec3(0, -1, 0)); }

void make_grid(Space& space, int count, Real spacing) {
    space.reserve_bodies(static_cast<std::size_t>(count) + 1);
    make_floor(space);
    for (int i = 0; i < count; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        d.position = Vec3(spacing * (i % 100), 5.0 + spacing * (i / 10000), spacing * ((i / 100) % 100));
        space.create_body(d);
    }
}

// Runs `level`'s first step in a process of its own (a death test's, re-run from the
// start: the medium block pool, process-wide, holds no chunk yet) and exits 0 when
// `check(world, taken)` holds after it, where `taken` is the stocked pages the step took.
// One page is stocked beyond the level's, so that a step needing more shows.
template <typename Level, typename Check>
void expect_first_step_alone(const SpaceSettings& settings, Level&& level, Check&& check) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(
        {
            Space space{settings};
            level(space);
            World& world = SpaceInternals::world(space);
            space.flush();
            stock_huge_page();
            const std::size_t ready = stocked_huge_pages();
            step(world, space.settings().time_step.duration);
            std::exit(check(world, ready - stocked_huge_pages()) ? 0 : 1);
        },
        ::testing::ExitedWithCode(0), "");
}

// The step took exactly the level's stock: the one page left shows it needed no more, none
// of the level's left that it needed no less. Else it says what it took on stderr.
template <typename Level>
void expect_first_step_takes_its_stock(const SpaceSettings& settings, Level&& level) {
    expect_first_step_alone(settings, level, [](const World& world, std::size_t taken) {
        std::fprintf(stderr, "stocked %zu, taken %zu with a page to spare\n", world.stocked_pages, taken);
        return world.stocked_pages > 0 && taken == world.stocked_pages;
    });
}

// The first step laid out each array of first_step_arrays (stages/capacity.hpp) as counted
// for its bodies and contacts: the mapped ones on as many huge pages, and the pool's blocks
// in use are those of the listed ones, size by size (the process had none before). Else it
// names what differs on stderr.
template <typename Level>
void expect_first_step_lays_out_its_arrays(const SpaceSettings& settings, Level&& level) {
    expect_first_step_alone(settings, level, [](const World& world, std::size_t) {
        const SolverScratch& solver = *world.solver;
        const auto pages_of = [](const auto& v) { return stocked_room_pages(v.capacity(), sizeof(v[0])); };
        const std::map<std::string, std::size_t> mapped_pages = {
            {"contact records", pages_of(world.contacts)},
            {"wide contacts", pages_of(solver.wide)},
            {"push anchors", pages_of(solver.push_anchors)},
            {"solver bodies", pages_of(solver.bodies)},
        };
        bool same = true;
        MediumBlockCounts counted;
        for (const FirstStepArray& array :
             first_step_arrays(world.first_step_bodies, world.contacts.size(), world.first_step_rolls)) {
            if (array.mapped && array.pages() != 0) {
                const auto it = mapped_pages.find(array.name);
                const std::size_t laid_out = it == mapped_pages.end() ? 0 : it->second;
                if (laid_out != array.pages()) {
                    std::fprintf(stderr, "%s: counted %zu pages, laid out on %zu\n", array.name, array.pages(),
                                 laid_out);
                    same = false;
                }
            }
            if (array.block_bytes() != 0) counted.blocks[medium_block_size_index(array.block_bytes())] += 1;
        }
        const MediumBlockCounts in_use = medium_block_counts();
        for (int k = 0; k < kMediumBlockSizes; ++k) {
            if (counted.blocks[k] == in_use.blocks[k]) continue;
            std::fprintf(stderr, "blocks of %zu KB: counted %zu, in use %zu\n",
                         (kMediumBlockMinBytes * static_cast<std::size_t>(k + 1)) >> 10, counted.blocks[k],
                         in_use.blocks[k]);
            same = false;
        }
        return same;
    });
}

}  // namespace

// A falling level (Box3D's rain, junkyard: bodies apart) makes few contacts in its first
// step: it stocks only the pages that step writes (its solver bodies', and the pool's
// chunk for its per-body lists), not pages for contacts it does not make.
TEST(PageStock, AFallingLevelStocksOnlyThePagesItsFirstStepTakes) {
    Space space;
    make_grid(space, 8000, 2);
    const World& world = SpaceInternals::world(space);
    EXPECT_EQ(world.first_step_contacts, 0u) << "boxes 1 m apart were counted as pairs";
    EXPECT_LE(world.stocked_pages, 2u) << "a level of boxes apart stocked pages for contacts it does not make";
    expect_first_step_takes_its_stock({}, [](Space& s) { make_grid(s, 8000, 2); });
}

// A floor made after the boxes resting on it brings their contacts: they are stocked for
// with it (8,000 contact records, 3.6 MB).
TEST(PageStock, AFloorMadeAfterItsBoxesStocksTheirContacts) {
    expect_first_step_takes_its_stock({}, [](Space& space) {
        for (int i = 0; i < 8000; ++i) {
            BodyDesc d;
            d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
            d.position = Vec3(2.0 * (i % 100), 0.5, 2.0 * (i / 100));
            space.create_body(d);
        }
        test::add_static_box(space, Vec3(1000, 1, 1000), Vec3(0, -1, 0));
    });
}

// What a level stocks is what its first step takes, no more and no less: a resting pyramid
// (Jolt's: contact records, wide contacts and pool chunks), many_pyramids by its counted
// pairs and by the game's count of its contacts (28,420). A list the first step adds on
// huge pages that first_step_arrays (stages/capacity.hpp) does not count fails here.
TEST(PageStock, AFirstStepTakesWhatItsLevelStocked) {
    const SceneDesc pyramid = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/pyramid.toml");
    expect_first_step_takes_its_stock(pyramid.settings, [&](Space& space) { build(pyramid, space); });
    const SceneDesc many = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/many_pyramids.toml");
    expect_first_step_takes_its_stock(many.settings, [&](Space& space) { build(many, space); });
    SpaceSettings told = many.settings;
    told.capacity.contact_count = 28420;
    expect_first_step_takes_its_stock(told, [&](Space& space) { build(many, space); });
}

// What a first step lays out is what first_step_arrays counts, array by array: a list
// left out or sized wrongly there fails here even where the pages it takes round the same.
// Jolt's pyramid, many_pyramids (28,420 contacts, 10,780 bodies), and a falling level
// whose solver bodies are a medium block.
TEST(PageStock, AFirstStepLaysOutTheArraysItsStockCounted) {
    const SceneDesc pyramid = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/pyramid.toml");
    expect_first_step_lays_out_its_arrays(pyramid.settings, [&](Space& space) { build(pyramid, space); });
    const SceneDesc many = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/many_pyramids.toml");
    expect_first_step_lays_out_its_arrays(many.settings, [&](Space& space) { build(many, space); });
    expect_first_step_lays_out_its_arrays({}, [](Space& space) { make_grid(space, 8000, 2); });
}

// A first step writes its arrays on pages stocked or mapped whole, not on fresh small pages
// of the heap: on a virtual machine each small page's first write is a fault of its own
// (15 us on the development VM, docs/benchmarks.md), and many_pyramids' first step once
// took 441 of them, 336 for the moving tree's float child boxes alone. A fresh process (a
// death test's), as a game's first level; sanitizers' heaps lay memory out otherwise.
TEST(PageStock, AFirstStepWritesFewFreshSmallPages) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || !defined(__GLIBC__)
    GTEST_SKIP() << "the heap is the sanitizer's, or not glibc's";
#else
    if (const std::string mode = test::huge_page_mode(); mode != "always" && mode != "madvise")
        GTEST_SKIP() << "the system gives no huge pages: every array faults small pages";
    const SceneDesc many = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/many_pyramids.toml");
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(
        {
            Space space{many.settings};
            build(many, space);
            World& world = SpaceInternals::world(space);
            space.flush();
            const long before = minor_faults();
            step(world, many.settings.time_step.duration);
            const long faults = minor_faults() - before;
            std::fprintf(stderr, "many_pyramids' first step: %ld page faults\n", faults);
            std::exit(faults <= kFewFreshPages ? 0 : 1);
        },
        ::testing::ExitedWithCode(0), "");
#endif
}

// The pairs counted as the bodies are made are the contacts their first step makes: Jolt's
// pyramid, boxes resting on each other.
TEST(PageStock, ThePairsCountedAsBodiesAreMadeAreTheFirstStepsContacts) {
    const SceneDesc scene = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/pyramid.toml");
    Space space{scene.settings};
    build(scene, space);
    World& world = SpaceInternals::world(space);
    const std::size_t counted = world.first_step_contacts;
    ASSERT_GT(counted, 0u);
    space.update();
    EXPECT_EQ(world.contacts.size(), counted);
}

namespace {

// `count` boxes resting on make_grid's floor, 2 m apart from x = `x` on, made one by one as
// a game spawns them (no reserve_bodies): each makes one contact, with the floor.
void spawn_resting_boxes(Space& space, int count, Real x) {
    for (int i = 0; i < count; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        d.position = Vec3(x + 2.0 * (i % 100), 0.5, 2.0 * (i / 100));
        space.create_body(d);
    }
}

}  // namespace

// A body spawned in a running game is not looked up in the trees, nor stocked for: its
// step grows its arrays as the game goes. Bodies made as a level (before the first update,
// or after reserve_bodies until the next) are.
TEST(PageStock, ABodySpawnedInARunningGameIsNotCounted) {
    Space space;
    make_grid(space, 0, 2);  // the floor
    space.update();
    World& world = SpaceInternals::world(space);
    spawn_resting_boxes(space, 8000, 0);
    EXPECT_EQ(world.first_step_contacts, 0u) << "a body spawned in a running game was looked up";
    EXPECT_EQ(world.first_step_bodies, 0u);
    EXPECT_EQ(world.stocked_pages, 0u);
    space.update();

    space.reserve_bodies(space.body_count() + 8000);  // a level's room: its bodies are counted
    spawn_resting_boxes(space, 8000, 300);
    EXPECT_EQ(world.first_step_contacts, 8000u);
    EXPECT_EQ(world.first_step_bodies, 8000u);
    EXPECT_GT(world.stocked_pages, 0u);
    space.update();
    EXPECT_EQ(world.stocked_pages, 0u);

    Space level;  // before the first update, without reserve_bodies
    make_floor(level);
    spawn_resting_boxes(level, 8000, 0);
    EXPECT_EQ(SpaceInternals::world(level).first_step_contacts, 8000u);
    EXPECT_GT(SpaceInternals::world(level).stocked_pages, 0u);
}

// The game's count of its level's first contacts (SpaceSettings::capacity) sizes the
// stock instead of the pairs counted, before the space's first step only: a level made
// after it (reserve_bodies) stocks by its own pairs again. memory_report shows the stock.
TEST(PageStock, TheGamesContactCountSizesTheFirstStepsStockOnly) {
    const std::size_t before = stocked_huge_pages();
    SpaceSettings settings;
    settings.capacity.contact_count = 60000;
    Space space{settings};
    make_grid(space, 100, 2);
    World& world = SpaceInternals::world(space);
    EXPECT_GT(world.stocked_pages, 20u) << "the game's 60,000 contacts were not stocked for";
    EXPECT_EQ(memory_report(space).page_stock, world.stocked_pages * kHugePageBytes);
    EXPECT_EQ(stocked_huge_pages(), before + world.stocked_pages);
    space.update();
    EXPECT_EQ(memory_report(space).page_stock, 0u);
    EXPECT_EQ(stocked_huge_pages(), before);
    make_grid(space, 100, 2);
    EXPECT_EQ(world.stocked_pages, 0u) << "the game's count was stocked for again after the first step";

    Space counted;  // the same level without the game's count
    make_grid(counted, 100, 2);
    EXPECT_EQ(SpaceInternals::world(counted).stocked_pages, 0u);
}
