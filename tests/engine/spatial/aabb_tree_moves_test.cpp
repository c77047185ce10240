// DynamicAabbTree moves in place and rebuild_enlarged: queries exact before and after the
// rebuild, fat boxes and ids kept, flags kept consistent through inserts, removals and
// rotations, the tree as good as a full rebuild; and the engine's two users (the
// broadphase, the query scenes) leaving no flagged node behind after a step.
#include "spatial/aabb_tree.hpp"

#include <spindle/engine/space.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "api/space_internals.hpp"
#include "query/query_scene.hpp"
#include "spatial/proxy_trees.hpp"
#include "stages/broadphase_state.hpp"
#include "test_job_systems.hpp"
#include "tree_test_support.hpp"
#include "world.hpp"

namespace spindle {
namespace {

using namespace test;

struct Snapshot {
    std::vector<Aabb> boxes;
    std::vector<std::uint64_t> users;
};

Snapshot snapshot(const DynamicAabbTree& tree, const std::vector<std::int32_t>& live) {
    Snapshot s;
    for (const std::int32_t id : live) {
        s.boxes.push_back(tree.fat_aabb(id));
        s.users.push_back(tree.user(id));
    }
    return s;
}

void expect_same_proxies(const DynamicAabbTree& tree, const std::vector<std::int32_t>& live, const Snapshot& before) {
    ASSERT_EQ(tree.proxy_count(), static_cast<std::int32_t>(live.size()));
    for (std::size_t i = 0; i < live.size(); ++i) {
        ASSERT_TRUE(tree.is_proxy(live[i]));
        ASSERT_EQ(tree.user(live[i]), before.users[i]);
        ASSERT_TRUE(tree.fat_aabb(live[i]).min == before.boxes[i].min &&
                    tree.fat_aabb(live[i]).max == before.boxes[i].max)
            << "proxy " << live[i];
    }
}

// Moves every proxy by a random step; about a third leave their fat boxes.
int move_all(DynamicAabbTree& tree, const std::vector<std::int32_t>& live, Rng& rng, Real step) {
    int moved = 0;
    for (const std::int32_t id : live) {
        const Aabb fat = tree.fat_aabb(id);
        const Vec3 d = rng.vec(-step, step);
        const Vec3 half = Vec3::Constant(0.5);
        moved += tree.move_proxy(id, Aabb::from_center_extents(fat.center() + d, half), d) ? 1 : 0;
    }
    return moved;
}

TEST(AabbTreeMoves, MovesInPlace_QueriesExactBeforeAndAfterRebuild_FatBoxesKept) {
    Rng rng(11);
    DynamicAabbTree tree;
    std::vector<std::int32_t> live;
    const int n = 300 * kScale;
    for (int i = 0; i < n; ++i) {
        live.push_back(tree.create_proxy(Aabb::from_center_extents(rng.vec(-40, 40), Vec3::Constant(0.5)), i));
    }
    const std::size_t capacity = tree.node_capacity();
    int moved_total = 0;
    for (int round = 0; round < 20; ++round) {
        const int moved = move_all(tree, live, rng, 0.3);
        moved_total += moved;
        // Loose but valid before the rebuild: every ancestor holds its leaves' new boxes.
        tree.validate();
        if (moved > 0) {
            EXPECT_GT(tree.enlarged_node_count(), 0);
        }
        for (int q = 0; q < 20; ++q) {
            const Aabb box = rng.box(40, 6);
            ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box)) << "round " << round << " before";
        }
        const Snapshot before = snapshot(tree, live);
        tree.rebuild_enlarged();
        tree.validate();
        EXPECT_EQ(tree.enlarged_node_count(), 0);
        expect_same_proxies(tree, live, before);
        for (int q = 0; q < 20; ++q) {
            const Aabb box = rng.box(40, 6);
            ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box)) << "round " << round << " after";
        }
        EXPECT_LE(tree.height(), height_limit(tree.proxy_count())) << "round " << round;
    }
    EXPECT_GT(moved_total, n);                  // the moves left fat boxes, not only stayed inside
    EXPECT_EQ(tree.node_capacity(), capacity);  // the rebuild reuses the nodes it frees
}

// Proxies drift across the world as a shear flow, the tree rebuilt where they moved each
// round: its SAH cost stays near a full rebuild's, while the same moves without the
// rebuilds leave a tree of ancestors stretched over the whole path.
TEST(AabbTreeMoves, RebuildEnlarged_KeepsTheTreeAsGoodAsAFullRebuild) {
    Rng rng(12);
    DynamicAabbTree tree;
    std::vector<std::int32_t> live;
    std::vector<Vec3> centers;
    const int n = 250 * kScale;
    for (int i = 0; i < n; ++i) {
        centers.push_back(rng.vec(-30, 30));
        live.push_back(tree.create_proxy(Aabb::from_center_extents(centers.back(), Vec3::Constant(0.5)), i));
    }
    DynamicAabbTree loose = tree;
    for (int round = 0; round < 60; ++round) {
        for (std::size_t k = 0; k < live.size(); ++k) {
            const Vec3 d(Real(0.05) * centers[k].y(), Real(0.05) * centers[k].z(), Real(0.05) * -centers[k].y());
            centers[k] += d;
            const Aabb tight = Aabb::from_center_extents(centers[k], Vec3::Constant(0.5));
            tree.move_proxy(live[k], tight, d);
            loose.move_proxy(live[k], tight, d);
        }
        tree.rebuild_enlarged();
    }
    tree.validate();
    loose.validate();
    DynamicAabbTree full = tree;
    full.rebuild();
    EXPECT_LE(tree.area_cost(), full.area_cost() * 1.25);
    EXPECT_LE(tree.height(), height_limit(n));
    EXPECT_GT(loose.area_cost(), full.area_cost() * 3);  // the scenario needs the rebuild
}

TEST(AabbTreeMoves, OneMove_FlagsOnlyItsPathAndTheRebuildClearsIt) {
    Rng rng(13);
    DynamicAabbTree tree;
    std::vector<std::int32_t> live;
    for (int i = 0; i < 100 * kScale; ++i) live.push_back(tree.create_proxy(rng.box(30, 1), i));
    tree.rebuild();
    const std::int32_t id = live[7];
    const Aabb fat = tree.fat_aabb(id);
    const Vec3 d(3, 0, 0);
    ASSERT_TRUE(tree.move_proxy(id, {fat.min + d, fat.max + d}, d));
    EXPECT_GE(tree.enlarged_node_count(), 1);
    EXPECT_LE(tree.enlarged_node_count(), tree.height());  // the leaf's ancestors, no more
    tree.validate();
    const Snapshot before = snapshot(tree, live);
    tree.rebuild_enlarged();
    tree.validate();
    EXPECT_EQ(tree.enlarged_node_count(), 0);
    expect_same_proxies(tree, live, before);
    // Nothing flagged: the rebuild is a no-op, and the query order (the tree's shape) stays.
    std::vector<std::int32_t> order_before, order_after;
    const Aabb all = Aabb::from_center_extents(Vec3::Zero(), Vec3::Constant(100));
    tree.query(all, [&](std::int32_t p) { return order_before.push_back(p), true; });
    tree.rebuild_enlarged();
    tree.query(all, [&](std::int32_t p) { return order_after.push_back(p), true; });
    EXPECT_EQ(order_before, order_after);
}

// A fast proxy's long box shrinks back when it stops: the ancestors that held the long box
// are flagged too, and the rebuild fits them to what is left.
TEST(AabbTreeMoves, ShrunkFatBox_RebuildRefitsTheAncestors) {
    Rng rng(14);
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0.1, .displacement_multiplier = 2});
    std::vector<std::int32_t> live;
    for (int i = 0; i < 100 * kScale; ++i) {
        live.push_back(tree.create_proxy(Aabb::from_center_extents(rng.vec(-10, 10), Vec3::Constant(0.5)), i));
    }
    const Real start_cost = tree.area_cost();
    const std::int32_t id = live[3];
    const Aabb tight = Aabb::from_center_extents(tree.fat_aabb(id).center() + Vec3(1, 0, 0), Vec3::Constant(0.5));
    const Vec3 fast(400, 0, 0);  // a box stretched 800 m ahead
    ASSERT_TRUE(tree.move_proxy(id, tight, fast));
    tree.rebuild_enlarged();
    const Real stretched_cost = tree.area_cost();
    ASSERT_TRUE(tree.move_proxy(id, tight, Vec3::Zero()));  // stopped: far too big, shrunk
    tree.validate();
    tree.rebuild_enlarged();
    tree.validate();
    EXPECT_LT(tree.area_cost(), start_cost * 1.2);
    EXPECT_GT(stretched_cost, start_cost * 1.5);  // what ancestors left unfitted would keep
}

// Creations, destructions (inserts and removals with rotations) and moves interleaved,
// every operation validated: the flags stay a tree from the root down through them all.
TEST(AabbTreeMoves, Churn_FlagsStayConsistentThroughInsertsRemovalsAndRotations) {
    Rng rng(15);
    DynamicAabbTree tree(AabbTreeSettings{.validate_after_changes = true});
    std::vector<std::int32_t> live;
    const int target = 60 * kScale;
    for (int op = 0; op < 1500 * kScale; ++op) {
        const int kind = rng.index(12);
        if (live.size() < 4 || (kind < 3 && static_cast<int>(live.size()) < target)) {
            live.push_back(tree.create_proxy(rng.box(20, 1.5), std::uint64_t(op)));
        } else if (kind < 5) {
            const auto i = static_cast<std::size_t>(rng.index(static_cast<int>(live.size())));
            tree.destroy_proxy(live[i]);
            live[i] = live.back();
            live.pop_back();
        } else if (kind < 11) {
            const std::int32_t id = live[static_cast<std::size_t>(rng.index(static_cast<int>(live.size())))];
            const Vec3 d = rng.vec(-2, 2);
            tree.move_proxy(id, Aabb::from_center_extents(tree.fat_aabb(id).center() + d, rng.vec(0.1, 1.5)), d);
        } else {
            const Snapshot before = snapshot(tree, live);
            tree.rebuild_enlarged();
            ASSERT_EQ(tree.enlarged_node_count(), 0);
            expect_same_proxies(tree, live, before);
        }
        if (op % 100 == 0) {
            const Aabb box = rng.box(20, 5);
            ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box)) << "after " << op << " operations";
        }
    }
}

namespace {

// Moves every proxy of two copies of one tree of `proxies` five times, rebuilding one on
// the calling thread alone and the other on three threads that run chunks in reverse
// order: the trees must come out the same (the same walk order, the same cost to the bit)
// and valid. Proxies moving `together` take one step (the rebuild keeps the refit), else
// each its own. Returns the fewest flagged nodes a rebuild saw and the refits kept.
std::pair<std::int32_t, std::int64_t> expect_rebuild_in_jobs_same_as_on_one_thread(int proxies, std::uint64_t seed,
                                                                                   bool together = false) {
    Rng rng(seed);
    DynamicAabbTree serial;
    std::vector<std::int32_t> live;
    for (int i = 0; i < proxies; ++i) {
        live.push_back(serial.create_proxy(Aabb::from_center_extents(rng.vec(-50, 50), Vec3::Constant(0.5)), i));
    }
    DynamicAabbTree parallel = serial;
    test::ReverseThreadedJobSystem jobs(3);
    std::int32_t fewest_flagged = std::numeric_limits<std::int32_t>::max();
    for (int round = 0; round < 5; ++round) {
        std::vector<Vec3> steps;
        const Vec3 common = rng.vec(-1.5, 1.5);
        for (std::size_t k = 0; k < live.size(); ++k) steps.push_back(together ? common : rng.vec(-1.5, 1.5));
        for (DynamicAabbTree* tree : {&serial, &parallel}) {
            for (std::size_t k = 0; k < live.size(); ++k) {
                const Aabb tight = Aabb::from_center_extents(tree->fat_aabb(live[k]).center() + steps[k],
                                                             Vec3::Constant(0.5));
                tree->move_proxy(live[k], tight, steps[k]);
            }
        }
        fewest_flagged = std::min(fewest_flagged, parallel.enlarged_node_count());
        serial.rebuild_enlarged();
        parallel.rebuild_enlarged(&jobs);
        parallel.validate();
        EXPECT_EQ(parallel.enlarged_node_count(), 0);
        EXPECT_EQ(walk_order(parallel), walk_order(serial)) << "round " << round;
        EXPECT_EQ(parallel.area_cost(), serial.area_cost());
        EXPECT_EQ(parallel.height(), serial.height());
        for (int q = 0; q < 20; ++q) {
            const Aabb box = rng.box(50, 6);
            EXPECT_EQ(query_sorted(parallel, box), brute_sorted(parallel, live, box));
        }
    }
    return {fewest_flagged, parallel.refit_count()};
}

}  // namespace

// The lower parts of a big rebuild are built as jobs: the same tree as on one thread.
TEST(AabbTreeMoves, RebuildEnlargedInJobs_SameTreeAsOnOneThread) {
    // Enough to be split into jobs (ranges of up to 256 leaves): 800 proxies in the
    // sanitizer builds (kScale), 3200 in Release.
    EXPECT_GT(expect_rebuild_in_jobs_same_as_on_one_thread(400 * kScale, 18).first, 2 * 256);
}

// With 2,048 flagged nodes or more, the walk over them is split too: the subtrees below its
// top are walked and refitted in jobs, their lists spliced into the walk's order: the same
// tree whether it is then built again (proxies scattered) or the refit is kept (moving together).
TEST(AabbTreeMoves, RebuildEnlargedWalkInJobs_SameTreeAsOnOneThread) {
    const auto [flagged, refits] = expect_rebuild_in_jobs_same_as_on_one_thread(2400, 20);
    EXPECT_GE(flagged, 2048);
    EXPECT_LT(refits, 5) << "scattered proxies should be built again";
    const auto [together_flagged, together_refits] = expect_rebuild_in_jobs_same_as_on_one_thread(2400, 21, true);
    EXPECT_GE(together_flagged, 2048);
    EXPECT_GT(together_refits, 0) << "proxies moving together should keep the refit";
}

// The broadphase's moves: set_fat_box gives the leaf its box and only flags the ancestors
// (their boxes stay short until the rebuild, which validate() allows for); the rebuild then
// gives the very tree move_proxy's grown ancestors give (the same walk order and cost).
TEST(AabbTreeMoves, SetFatBox_RebuildGivesTheTreeMoveProxyGives) {
    Rng rng(19);
    DynamicAabbTree grown;
    std::vector<std::int32_t> live;
    for (int i = 0; i < 300 * kScale; ++i) {
        live.push_back(grown.create_proxy(Aabb::from_center_extents(rng.vec(-40, 40), Vec3::Constant(0.5)), i));
    }
    DynamicAabbTree flagged = grown;
    for (int round = 0; round < 10; ++round) {
        int moved = 0;
        for (const std::int32_t id : live) {
            const Vec3 d = rng.vec(-0.4, 0.4);
            const Aabb tight = Aabb::from_center_extents(grown.fat_aabb(id).center() + d, Vec3::Constant(0.5));
            const bool moves = flagged.needs_move(id, tight, d);
            ASSERT_EQ(grown.move_proxy(id, tight, d), moves);
            if (!moves) continue;
            const Aabb fat = flagged.fat_box(tight, d);
            ASSERT_TRUE(fat.min == grown.fat_aabb(id).min && fat.max == grown.fat_aabb(id).max);
            flagged.set_fat_box(id, fat);
            ++moved;
        }
        ASSERT_GT(moved, 0);
        EXPECT_EQ(flagged.enlarged_node_count(), grown.enlarged_node_count()) << "round " << round;
        EXPECT_LT(flagged.area_cost(), grown.area_cost()) << "round " << round;  // no ancestor grown
        flagged.validate();
        grown.rebuild_enlarged();
        flagged.rebuild_enlarged();
        flagged.validate();
        ASSERT_EQ(walk_order(flagged), walk_order(grown)) << "round " << round;
        ASSERT_EQ(flagged.area_cost(), grown.area_cost());
        for (int q = 0; q < 20; ++q) {
            const Aabb box = rng.box(40, 6);
            ASSERT_EQ(query_sorted(flagged, box), brute_sorted(flagged, live, box));
        }
    }
}

// Sets every proxy's fat box to its tight box moved by `step[k]`, as the broadphase does.
// Without `stretch`, the fat box is not stretched along the step (a teleport).
void set_all(DynamicAabbTree& tree, const std::vector<std::int32_t>& live, const std::vector<Vec3>& step,
             bool stretch = true) {
    for (std::size_t k = 0; k < live.size(); ++k) {
        const Aabb fat = tree.fat_aabb(live[k]);
        const Aabb tight = Aabb::from_center_extents(fat.center() + step[k], Vec3::Constant(0.5));
        tree.set_fat_box(live[k], tree.fat_box(tight, stretch ? step[k] : Vec3::Zero()));
    }
}

// `count` unit boxes in [-40, 40]^3 made in one create_proxies call, as a scene's bodies
// are: a build of the whole tree, the reference a refit's cost is compared with.
std::vector<std::int32_t> unit_boxes_built_at_once(DynamicAabbTree& tree, Rng& rng, int count) {
    std::vector<Aabb> tight;
    std::vector<std::uint64_t> users;
    for (int i = 0; i < count; ++i) {
        tight.push_back(Aabb::from_center_extents(rng.vec(-40, 40), Vec3::Constant(0.5)));
        users.push_back(std::uint64_t(i));
    }
    std::vector<std::int32_t> live(tight.size());
    tree.create_proxies(tight, users, live);
    return live;
}

// A pile falling together (junkyard's rocks): every proxy leaves its fat box at once, but
// none changes neighbours, so the flagged nodes are refitted where they are instead of
// rebuilt. The refitted tree keeps its shape (the same walk order), answers every query as
// a tree rebuilt from the same boxes does, and costs no more than that tree.
TEST(AabbTreeMoves, RebuildEnlarged_ProxiesMovingTogether_RefitsAndQueriesAsARebuild) {
    Rng rng(20);
    DynamicAabbTree tree;
    const std::vector<std::int32_t> live = unit_boxes_built_at_once(tree, rng, 400 * kScale);
    for (int round = 0; round < 8; ++round) {
        const std::vector<std::int32_t> order = walk_order(tree);
        const Vec3 fall(0, -Real(0.6), 0);  // a steady fall: the boxes keep their size
        set_all(tree, live, std::vector<Vec3>(live.size(), fall));
        ASSERT_GT(2 * tree.enlarged_node_count() + 1, tree.proxy_count());  // most of the tree
        const std::int64_t refits = tree.refit_count();
        const Snapshot before = snapshot(tree, live);
        tree.rebuild_enlarged();
        tree.validate();
        EXPECT_EQ(tree.enlarged_node_count(), 0);
        EXPECT_EQ(tree.refit_count(), refits + 1) << "round " << round;
        EXPECT_EQ(walk_order(tree), order) << "round " << round;  // refitted, not rebuilt
        expect_same_proxies(tree, live, before);
        DynamicAabbTree rebuilt = tree;
        rebuilt.rebuild();
        EXPECT_LE(tree.area_cost(), rebuilt.area_cost() * 1.01) << "round " << round;
        for (int q = 0; q < 40; ++q) {
            const Aabb box = rng.box(50, 6);
            const std::vector<std::int32_t> expected = brute_sorted(tree, live, box);
            ASSERT_EQ(query_sorted(tree, box), expected) << "round " << round;
            ASSERT_EQ(query_sorted(rebuilt, box), expected) << "round " << round;
        }
    }
}

// Proxies that all move but change neighbours (each to a random place, teleported or
// stretched along the jump): a refit would keep ancestors stretched across the world, so
// the cost test rebuilds them instead.
TEST(AabbTreeMoves, RebuildEnlarged_ProxiesScattered_RebuildsInsteadOfRefitting) {
    Rng rng(21);
    DynamicAabbTree tree;
    const std::vector<std::int32_t> live = unit_boxes_built_at_once(tree, rng, 400 * kScale);
    for (int round = 0; round < 4; ++round) {
        std::vector<Vec3> jump;
        for (std::size_t k = 0; k < live.size(); ++k)
            jump.push_back(rng.vec(-40, 40) - tree.fat_aabb(live[k]).center());
        set_all(tree, live, jump, round % 2 == 0);
        tree.rebuild_enlarged();
        tree.validate();
        DynamicAabbTree rebuilt = tree;
        rebuilt.rebuild();
        EXPECT_LE(tree.area_cost(), rebuilt.area_cost() * 1.25) << "round " << round;
        for (int q = 0; q < 20; ++q) {
            const Aabb box = rng.box(50, 6);
            ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box)) << "round " << round;
        }
    }
    EXPECT_EQ(tree.refit_count(), 0);
}

TEST(AabbTreeMoves, ProxyTrees_UpdatePairsRebuildsWhatMoved) {
    Rng rng(16);
    ProxyTrees trees;
    std::vector<ProxyId> ids;
    for (int i = 0; i < 200; ++i) {
        ids.push_back(
            trees.create_proxy(Aabb::from_center_extents(rng.vec(-20, 20), Vec3::Constant(0.5)), i, i % 10 == 0));
    }
    PairList pairs;
    SingleThreadedJobSystem jobs;
    trees.update_pairs(jobs, pairs);
    for (const ProxyId id : ids) {
        const Vec3 d(1, 0, 0);
        trees.move_proxy(id, Aabb::from_center_extents(trees.fat_aabb(id).center() + d, Vec3::Constant(0.5)), d);
    }
    ASSERT_GT(trees.moving_tree().enlarged_node_count(), 0);
    ASSERT_GT(trees.static_tree().enlarged_node_count(), 0);
    trees.update_pairs(jobs, pairs);
    EXPECT_EQ(trees.moving_tree().enlarged_node_count(), 0);
    EXPECT_EQ(trees.static_tree().enlarged_node_count(), 0);
    trees.validate();
}

// A space of bodies flying apart: after each update the broadphase's moving tree and both
// query scenes' trees hold no flagged node (each was rebuilt where its proxies moved).
TEST(AabbTreeMoves, Space_BroadphaseAndQueryTreesAreRebuiltEachStep) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    settings.sleep.enabled = false;
    Space space(settings);
    std::mt19937_64 random(17);
    std::uniform_real_distribution<Real> spread(-20, 20);
    for (int i = 0; i < 300; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3::Constant(0.4));
        d.position = {spread(random), spread(random), spread(random)};
        d.linear_velocity = d.position.normalized() * 6;
        space.create_body(d);
    }
    const World& world = SpaceInternals::world(space);
    space.ray_hits_any({0, 0, 0}, {0, 1, 0});  // the query scenes exist from the first query on
    for (int step = 0; step < 30; ++step) {
        space.update(Real(1) / 60);
        EXPECT_EQ(world.broadphase->tree.moving_tree().enlarged_node_count(), 0) << "step " << step;
        for (const auto& scene : world.query_scenes) {
            EXPECT_NE(scene, nullptr) << "step " << step;
            if (!scene) continue;
            scene->tree().validate();
            EXPECT_EQ(scene->tree().enlarged_node_count(), 0) << "step " << step;
        }
    }
    // They flew 3 m, ten query margins: their proxies moved many times.
    EXPECT_GT(world.broadphase->tree.moving_tree().height(), 0);
}

}  // namespace
}  // namespace spindle
