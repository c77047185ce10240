// DynamicAabbTree: queries and ray casts against brute force, fat-box rules of
// move_proxy, validity and height under churn, rebuild, steady-state memory.
#include "spatial/aabb_tree.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "tree_test_support.hpp"

namespace spindle {
namespace {

using namespace test;

TEST(AabbTree, EmptyTree_QueriesNothingAndValidates) {
    DynamicAabbTree tree;
    tree.validate();
    EXPECT_EQ(tree.height(), 0);
    EXPECT_EQ(tree.proxy_count(), 0);
    EXPECT_TRUE(query_sorted(tree, Aabb::from_center_extents(Vec3::Zero(), Vec3::Constant(1e9))).empty());
    tree.rebuild();
    tree.validate();
}

// With validate_after_changes, the whole tree is walked after each change while it is
// small and then once every n / 16 changes: a world made body by body pays O(n) walks'
// worth of checking, not one walk per body (O(n^2): 71 % of a 6,400-body TSan test), and
// moves are still checked.
TEST(AabbTree, ValidatingTree_WalksItselfAboutEverySixteenthOfItsSizeInChanges) {
    AabbTreeSettings settings;
    settings.validate_after_changes = true;
    DynamicAabbTree tree(settings);
    Rng rng(5);
    constexpr int kProxies = 2000;
    std::vector<std::int32_t> ids;
    for (int i = 0; i < kProxies; ++i) ids.push_back(tree.create_proxy(rng.box(40, 1), i));
    const std::int64_t made = tree.whole_checks();
    EXPECT_GE(made, 32);             // every change of the first 32 proxies, then more
    EXPECT_LE(made, kProxies / 10);  // not one walk per proxy
    for (int round = 0; round < 4; ++round) {
        for (std::int32_t id : ids) {
            const Vec3 d(0.5, 0, 0);
            const Aabb fat = tree.fat_aabb(id);
            tree.move_proxy(id, {fat.min + 2 * d, fat.max + 2 * d}, d);
        }
    }
    const std::int64_t moved = tree.whole_checks() - made;
    EXPECT_GE(moved, 4 * 16 - 4);  // 4 x 2,000 moves: about one walk every 125
    EXPECT_LE(moved, 4 * 16 + 4);
}

TEST(AabbTree, CreateProxy_FatBoxIsTightPlusMarginAndKeepsUser) {
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0.25});
    const Aabb tight{Vec3(0, 1, 2), Vec3(1, 2, 3)};
    const std::int32_t id = tree.create_proxy(tight, 0xfeedface12345678ull);
    EXPECT_EQ(tree.user(id), 0xfeedface12345678ull);
    EXPECT_TRUE(tree.fat_aabb(id).min.isApprox(Vec3(-0.25, 0.75, 1.75)));
    EXPECT_TRUE(tree.fat_aabb(id).max.isApprox(Vec3(1.25, 2.25, 3.25)));
    tree.destroy_proxy(id);
    EXPECT_EQ(tree.proxy_count(), 0);
    tree.validate();
}

TEST(AabbTree, Query_MatchesBruteForce) {
    Rng rng(1);
    DynamicAabbTree tree;
    std::vector<std::int32_t> live;
    const int n = 500 * kScale;
    for (int i = 0; i < n; ++i) live.push_back(tree.create_proxy(rng.box(50, 2), std::uint64_t(i)));
    tree.validate();
    for (int q = 0; q < 200; ++q) {
        const Aabb box = rng.box(50, 8);
        ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box)) << "query " << q;
    }
}

// Boxes are closed: a query finds a box it touches on any of the six faces, and not one
// a rounding step away on that axis alone; a NaN coordinate finds nothing (as
// Aabb::overlaps). Each face is one of the query's six comparisons.
TEST(AabbTree, Query_FindsABoxTouchingAnyFaceNotOneARoundingStepAway) {
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0});
    const Aabb unit{Vec3::Zero(), Vec3::Ones()};
    tree.create_proxy(unit, 7);
    const auto finds = [&](const Aabb& box) {
        EXPECT_EQ(query_sorted(tree, box).size() == 1, unit.overlaps(box));
        return !query_sorted(tree, box).empty();
    };
    for (int axis = 0; axis < 3; ++axis) {
        for (const Real side : {Real(-1), Real(1)}) {
            Aabb touching = unit;
            touching.min[axis] += side;
            touching.max[axis] += side;
            EXPECT_TRUE(finds(touching)) << "axis " << axis << " side " << side;
            Aabb apart = touching;
            Real& face = side > 0 ? apart.min[axis] : apart.max[axis];
            face = std::nextafter(face, side * Real(2));
            EXPECT_FALSE(finds(apart)) << "axis " << axis << " side " << side;
        }
        Aabb nan = unit;
        nan.min[axis] = std::numeric_limits<Real>::quiet_NaN();
        EXPECT_FALSE(finds(nan)) << "axis " << axis;
    }
}

[[noreturn]] void throwing_handler(const char*, const char* message, const char*, int) {
    throw std::logic_error(message);
}

// Every proxy `box` overlaps, in the order the query meets them.
std::vector<std::int32_t> query_in_order(const DynamicAabbTree& tree, const Aabb& box) {
    std::vector<std::int32_t> ids;
    tree.query(box, [&](std::int32_t id) {
        ids.push_back(id);
        return true;
    });
    return ids;
}

// With the children's float boxes made, a query meets the same proxies in the same order
// as the walk on the double boxes (a copy of the tree without them), and brute force;
// including boxes over a proxy with a face on its opposite face, or a few micrometres past
// or short of it, which a float cannot tell apart at 50 m.
TEST(AabbTree, QueryOnChildBoxes_MeetsTheSameProxiesInTheSameOrder) {
    Rng rng(5);
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0});
    std::vector<std::int32_t> live;
    const int n = 500 * kScale;
    for (int i = 0; i < n; ++i) live.push_back(tree.create_proxy(rng.box(50, 2), std::uint64_t(i)));
    const DynamicAabbTree doubles = tree;
    tree.make_child_boxes();
    ASSERT_TRUE(tree.child_boxes_current());
    ASSERT_FALSE(doubles.child_boxes_current());
    tree.validate();  // checks the float boxes too
    for (int q = 0; q < 800; ++q) {
        Aabb box = rng.box(50, 8);
        if (q % 4 != 0) {  // a face on, or a few micrometres past or short of, a proxy's opposite face
            const Aabb& other = tree.fat_aabb(live[static_cast<std::size_t>(rng.index(n))]);
            const int axis = rng.index(3);
            const Real offset = q % 4 == 1 ? 0 : rng.uniform(-4e-6, 4e-6);
            const Real width = box.max[axis] - box.min[axis];
            for (int k = 0; k < 3; ++k) {  // over the proxy on the other axes, so the face is what decides
                const Real shift = other.center()[k] - box.center()[k];
                box.min[k] += shift;
                box.max[k] += shift;
            }
            if (q % 8 < 4) {
                box.min[axis] = other.max[axis] + offset;
                box.max[axis] = box.min[axis] + width;
            } else {
                box.max[axis] = other.min[axis] + offset;
                box.min[axis] = box.max[axis] - width;
            }
        }
        const std::vector<std::int32_t> found = query_in_order(tree, box);
        ASSERT_EQ(found, query_in_order(doubles, box)) << "query " << q;
        std::vector<std::int32_t> sorted = found;
        std::sort(sorted.begin(), sorted.end());
        ASSERT_EQ(sorted, brute_sorted(tree, live, box)) << "query " << q;
    }
}

// A tree far taller than any balanced one: boxes reaching twice as far each, from which
// the binned build splits off the few farthest, a level at a time, as the first child, so
// a walk leaves one of them waiting on its stack for each level. query()'s float walk keeps
// its stack in a fixed array sized by a height bound: this tree must walk the doubles.
TEST(AabbTree, TallTreeOnChildBoxes_MeetsWhatTheDoublesMeet) {
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0});
    std::vector<std::int32_t> live;
    const int n = 600;
    for (int i = 0; i < n; ++i) {
        const Real reach = std::ldexp(Real(1), i);  // past float's range from i = 128 on: +-inf there
        live.push_back(tree.create_proxy(Aabb{Vec3(-reach, 0, 0), Vec3(0, 1, 1)}, std::uint64_t(i)));
    }
    tree.rebuild();
    const DynamicAabbTree doubles = tree;
    tree.make_child_boxes();
    ASSERT_TRUE(tree.child_boxes_current());
    tree.validate();
    ASSERT_GE(tree.height(), 100) << "the tree is not tall: the test would not test the deep walk";
    Rng rng(11);
    for (int q = 0; q < 100; ++q) {
        const Real reach = std::ldexp(Real(1), 6 * q);
        const Aabb box = Aabb::from_center_extents(Vec3(-reach, 0.5, 0.5), Vec3(rng.uniform(0.1, 2) * reach, 1, 1));
        const std::vector<std::int32_t> found = query_in_order(tree, box);
        ASSERT_EQ(found, query_in_order(doubles, box)) << "query " << q;
        std::vector<std::int32_t> sorted = found;
        std::sort(sorted.begin(), sorted.end());
        ASSERT_EQ(sorted, brute_sorted(tree, live, box)) << "query " << q;
    }
}

// A move leaves the float boxes out of date until rebuild_enlarged makes the moved
// paths' again, and a proxy made or destroyed, or a rebuild, until make_child_boxes: the
// query walks the double boxes meanwhile, and a proxy changed after make_child_boxes is
// found where it is now.
TEST(AabbTree, QueryAfterAChange_DoesNotReadOutOfDateChildBoxes) {
    Rng rng(9);
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0, .displacement_multiplier = 0});
    std::vector<std::int32_t> live;
    for (int i = 0; i < 64; ++i) live.push_back(tree.create_proxy(rng.box(50, 2), std::uint64_t(i)));
    const Aabb far = Aabb::from_center_extents(Vec3(500, 0, 0), Vec3::Ones());
    // `remake` brings the float boxes back: the rebuild of the moved paths, or all of them.
    const auto finds_only = [&](std::int32_t id, const char* change, auto remake) {
        EXPECT_FALSE(tree.child_boxes_current()) << change;
        EXPECT_EQ(query_sorted(tree, far), std::vector<std::int32_t>{id}) << change;
        remake();
        EXPECT_TRUE(tree.child_boxes_current()) << change;
        EXPECT_EQ(query_sorted(tree, far), std::vector<std::int32_t>{id}) << change << ", boxes made again";
        tree.validate();  // the float boxes too, node by node
    };
    const auto rebuild_moved = [&] { tree.rebuild_enlarged(); };
    const auto make_all = [&] { tree.make_child_boxes(); };
    tree.make_child_boxes();
    ASSERT_TRUE(query_sorted(tree, far).empty());
    tree.move_proxy(live[3], far, Vec3::Zero());
    finds_only(live[3], "moved", rebuild_moved);
    tree.move_proxy(live[3], rng.box(50, 2), Vec3::Zero());
    tree.rebuild_enlarged();
    tree.set_fat_box(live[5], far);
    tree.rebuild_enlarged();
    EXPECT_TRUE(tree.child_boxes_current()) << "given a box";
    EXPECT_EQ(query_sorted(tree, far), std::vector<std::int32_t>{live[5]}) << "given a box";
    tree.destroy_proxy(live[5]);
    EXPECT_FALSE(tree.child_boxes_current()) << "destroyed";
    EXPECT_TRUE(query_sorted(tree, far).empty());
    tree.rebuild_enlarged();
    EXPECT_FALSE(tree.child_boxes_current()) << "destroyed, then the moved paths rebuilt";
    tree.make_child_boxes();
    const std::int32_t made = tree.create_proxy(far, 99);
    finds_only(made, "made", make_all);
    tree.destroy_proxy(made);
    tree.make_child_boxes();
    tree.end_shared_fat_boxes(tree.set_fat_box_shared(live[7], far), 1);
    EXPECT_FALSE(tree.child_boxes_current()) << "given a box by a job";
    tree.rebuild_enlarged();
    EXPECT_TRUE(tree.child_boxes_current()) << "given a box by a job";
    EXPECT_EQ(query_sorted(tree, far), std::vector<std::int32_t>{live[7]}) << "given a box by a job";
    tree.rebuild();
    finds_only(live[7], "rebuilt", make_all);
}

// Moves in one corner of a tree with float boxes made: each rebuild_enlarged makes again
// only the nodes it built, and every node's float boxes are still its children's double
// boxes as make_child_boxes converts them (validate() checks node by node); queries meet
// what a copy without float boxes meets, in the same order, and brute force.
TEST(AabbTree, MovesInACorner_RebuildKeepsEveryNodesFloatBoxes) {
    const AssertHandler previous = set_assert_handler(&throwing_handler);
    Rng rng(17);
    // `doubles` is given the same changes and never float boxes: the same tree, walked on doubles.
    DynamicAabbTree tree(AabbTreeSettings{.margin = Real(0.05)});
    DynamicAabbTree doubles(tree.settings());
    std::vector<std::int32_t> live;
    const int n = 300 * kScale;
    for (int i = 0; i < n; ++i) {
        const Aabb box = rng.box(50, 2);
        live.push_back(tree.create_proxy(box, std::uint64_t(i)));
        ASSERT_EQ(doubles.create_proxy(box, std::uint64_t(i)), live.back());
    }
    tree.make_child_boxes();
    const Aabb corner = Aabb::from_center_extents(Vec3::Constant(35), Vec3::Constant(15));
    for (int round = 0; round < 20; ++round) {
        int moved = 0;
        for (const std::int32_t id : live) {
            const Aabb fat = tree.fat_aabb(id);
            if (!corner.contains(Aabb::from_center_extents(fat.center(), Vec3::Zero()))) continue;
            const Vec3 d = rng.vec(-1, 1);
            const Aabb tight = Aabb::from_center_extents(fat.center() + d, Vec3::Constant(0.5));
            if (round % 2 == 0) {
                moved += tree.move_proxy(id, tight, d) ? 1 : 0;
                doubles.move_proxy(id, tight, d);
            } else {
                tree.set_fat_box(id, tree.fat_box(tight, d));
                doubles.set_fat_box(id, tree.fat_box(tight, d));
                ++moved;
            }
        }
        ASSERT_GT(moved, 0) << "round " << round;
        ASSERT_LT(tree.enlarged_node_count(), n / 2) << "round " << round << ": the moves should stay in the corner";
        tree.rebuild_enlarged();
        doubles.rebuild_enlarged();
        ASSERT_TRUE(tree.child_boxes_current()) << "round " << round;
        ASSERT_FALSE(doubles.child_boxes_current());
        ASSERT_NO_THROW(tree.validate()) << "round " << round;
        for (int q = 0; q < 40; ++q) {
            const Aabb box = q % 2 == 0 ? rng.box(50, 8) : Aabb::from_center_extents(rng.vec(20, 50), rng.vec(1, 6));
            const std::vector<std::int32_t> found = query_in_order(tree, box);
            ASSERT_EQ(found, query_in_order(doubles, box)) << "round " << round << ", query " << q;
            std::vector<std::int32_t> sorted = found;
            std::sort(sorted.begin(), sorted.end());
            ASSERT_EQ(sorted, brute_sorted(tree, live, box)) << "round " << round << ", query " << q;
        }
    }
    set_assert_handler(previous);
}

// query() with a skip: the proxies skip accepts are passed over and the rest met in the
// plain query's order, on the float walk and on the doubles' (a copy without float boxes).
TEST(AabbTree, QueryWithSkip_PassesOverWhatItSkipsAndMeetsTheRestInOrder) {
    Rng rng(7);
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0});
    const int n = 300 * kScale;
    for (int i = 0; i < n; ++i) tree.create_proxy(rng.box(50, 2), std::uint64_t(i));
    const DynamicAabbTree doubles = tree;
    tree.make_child_boxes();
    ASSERT_TRUE(tree.child_boxes_current());
    const auto skipped = [](std::int32_t id) { return id % 3 == 0; };
    for (int q = 0; q < 200; ++q) {
        const Aabb box = rng.box(50, 8);
        for (const DynamicAabbTree* walked : {static_cast<const DynamicAabbTree*>(&tree), &doubles}) {
            std::vector<std::int32_t> expected;
            for (const std::int32_t id : query_in_order(*walked, box)) {
                if (!skipped(id)) expected.push_back(id);
            }
            std::vector<std::int32_t> met;
            walked->query(box, skipped, [&](std::int32_t id) {
                met.push_back(id);
                return true;
            });
            ASSERT_EQ(met, expected) << "query " << q << (walked == &tree ? ", float walk" : ", doubles");
        }
    }
}

TEST(AabbTree, Query_CallbackFalseStops) {
    DynamicAabbTree tree;
    for (int i = 0; i < 10; ++i)
        tree.create_proxy(Aabb::from_center_extents(Vec3::Zero(), Vec3::Ones()), std::uint64_t(i));
    int calls = 0;
    tree.query(Aabb::from_center_extents(Vec3::Zero(), Vec3::Ones()), [&](std::int32_t) {
        ++calls;
        return false;
    });
    EXPECT_EQ(calls, 1);
}

TEST(AabbTree, MoveProxy_KeepsFatBoxWhileTightBoxInside) {
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0.1, .displacement_multiplier = 2});
    const Aabb tight = Aabb::from_center_extents(Vec3::Zero(), Vec3::Constant(0.5));
    const std::int32_t id = tree.create_proxy(tight, 7);
    const Aabb fat = tree.fat_aabb(id);
    const Vec3 small(0.05, -0.05, 0.02);
    EXPECT_FALSE(tree.needs_move(id, {tight.min + small, tight.max + small}, small));
    EXPECT_TRUE(tree.needs_move(id, {tight.min + 3 * small, tight.max + 3 * small}, 3 * small));
    EXPECT_FALSE(tree.move_proxy(id, {tight.min + small, tight.max + small}, small));
    EXPECT_TRUE(tree.fat_aabb(id).min == fat.min && tree.fat_aabb(id).max == fat.max);
}

TEST(AabbTree, MoveProxy_ReinsertsStretchedAlongDisplacementWhenTightBoxLeaves) {
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0.1, .displacement_multiplier = 2});
    const Aabb tight = Aabb::from_center_extents(Vec3::Zero(), Vec3::Constant(0.5));
    const std::int32_t id = tree.create_proxy(tight, 7);
    tree.create_proxy(Aabb::from_center_extents(Vec3(5, 0, 0), Vec3::Constant(0.5)), 8);
    const Vec3 d(0.3, -0.2, 0);
    const Aabb moved{tight.min + d, tight.max + d};
    EXPECT_TRUE(tree.move_proxy(id, moved, d));
    const Aabb& fat = tree.fat_aabb(id);
    // Margin on every side, plus 2 x displacement on the side it moves towards.
    EXPECT_TRUE(fat.min.isApprox(Vec3(-0.2 - 0.1, -0.7 - 0.1 - 0.4, -0.5 - 0.1)));
    EXPECT_TRUE(fat.max.isApprox(Vec3(0.8 + 0.1 + 0.6, 0.3 + 0.1, 0.5 + 0.1)));
    EXPECT_TRUE(fat.contains(moved));
    EXPECT_EQ(tree.user(id), 7u);
    tree.validate();
}

TEST(AabbTree, MoveProxy_SteadyMotionReinsertsOnlyWhenLeavingAndShrinksAfterStop) {
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0.1, .displacement_multiplier = 2});
    Aabb tight = Aabb::from_center_extents(Vec3::Zero(), Vec3::Constant(0.5));
    const std::int32_t id = tree.create_proxy(tight, 1);
    const Vec3 d(1.0, 0, 0);  // fast: ten margins per step
    int reinserts = 0;
    for (int step = 0; step < 20; ++step) {
        tight = {tight.min + d, tight.max + d};
        reinserts += tree.move_proxy(id, tight, d) ? 1 : 0;
        ASSERT_TRUE(tree.fat_aabb(id).contains(tight));
    }
    // Stretched two displacements ahead, the box lasts two steps.
    EXPECT_LE(reinserts, 11);
    // The body stops: the long box is shrunk back to tight + margin (needs_move says so
    // first, and asking twice changes nothing).
    EXPECT_TRUE(tree.needs_move(id, tight, Vec3::Zero()));
    EXPECT_TRUE(tree.needs_move(id, tight, Vec3::Zero()));
    EXPECT_TRUE(tree.move_proxy(id, tight, Vec3::Zero()));
    EXPECT_FALSE(tree.needs_move(id, tight, Vec3::Zero()));
    EXPECT_TRUE(tree.fat_aabb(id).max.isApprox(tight.max + Vec3::Constant(0.1)));
    EXPECT_FALSE(tree.move_proxy(id, tight, Vec3::Zero()));
}

TEST(AabbTree, Churn_StaysValidShallowAndMatchesBruteForce) {
    Rng rng(2);
    DynamicAabbTree tree;
    std::vector<std::int32_t> live;
    std::vector<Vec3> centers;
    const int target = 400 * kScale;
    const int operations = 6000 * kScale;
    for (int op = 0; op < operations; ++op) {
        const int kind = rng.index(10);
        if (live.size() < 4 || (kind < 3 && static_cast<int>(live.size()) < target)) {
            live.push_back(tree.create_proxy(rng.box(40, 1.5), std::uint64_t(op)));
        } else if (kind < 5) {
            const int i = rng.index(static_cast<int>(live.size()));
            tree.destroy_proxy(live[static_cast<std::size_t>(i)]);
            live[static_cast<std::size_t>(i)] = live.back();
            live.pop_back();
        } else {
            const std::int32_t id = live[static_cast<std::size_t>(rng.index(static_cast<int>(live.size())))];
            const Vec3 d = rng.vec(-0.5, 0.5);
            const Aabb fat = tree.fat_aabb(id);
            const Aabb tight{fat.min + Vec3::Constant(0.1) + d, fat.max - Vec3::Constant(0.1) + d};
            if (tight.valid()) tree.move_proxy(id, tight, d);
        }
        if (op % 500 == 0) {
            tree.validate();
            ASSERT_LE(tree.height(), height_limit(tree.proxy_count())) << "after " << op << " operations";
            const Aabb box = rng.box(40, 6);
            ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box));
        }
    }
    tree.validate();
    EXPECT_LE(tree.height(), height_limit(tree.proxy_count()));
}

TEST(AabbTree, SortedInsertion_StaysShallow) {
    // Boxes on a line, inserted in order: the worst case for a tree without rotations.
    DynamicAabbTree tree;
    const int n = 1024 * kScale;
    std::vector<std::int32_t> ids;
    for (int i = 0; i < n; ++i) {
        ids.push_back(
            tree.create_proxy(Aabb::from_center_extents(Vec3(i, 0, 0), Vec3::Constant(0.4)), std::uint64_t(i)));
    }
    tree.validate();
    EXPECT_LE(tree.height(), height_limit(n));
    // And removed in order.
    for (int i = 0; i < n / 2; ++i) tree.destroy_proxy(ids[static_cast<std::size_t>(i)]);
    tree.validate();
    EXPECT_LE(tree.height(), height_limit(tree.proxy_count()));
}

TEST(AabbTree, SteadyChurn_DoesNotGrowNodePool) {
    Rng rng(3);
    DynamicAabbTree tree;
    std::vector<std::int32_t> live;
    const int n = 300 * kScale;
    for (int i = 0; i < n; ++i) live.push_back(tree.create_proxy(rng.box(30, 1), std::uint64_t(i)));
    const std::size_t capacity = tree.node_capacity();
    for (int op = 0; op < 2000 * kScale; ++op) {
        const auto i = static_cast<std::size_t>(rng.index(n));
        if (op % 2 == 0) {
            tree.destroy_proxy(live[i]);
            live[i] = tree.create_proxy(rng.box(30, 1), std::uint64_t(op));
        } else {
            const Vec3 d = rng.vec(-1, 1);
            const Aabb tight = Aabb::from_center_extents(tree.fat_aabb(live[i]).center() + d, Vec3::Constant(0.5));
            tree.move_proxy(live[i], tight, d);
        }
    }
    EXPECT_EQ(tree.node_capacity(), capacity);
    tree.validate();
}

TEST(AabbTree, Rebuild_KeepsProxiesAndQueriesAndLowersCost) {
    Rng rng(4);
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0});
    std::vector<std::int32_t> live;
    const int n = 800 * kScale;
    for (int i = 0; i < n; ++i) live.push_back(tree.create_proxy(rng.box(60, 3), std::uint64_t(1000 + i)));
    // Holes in the id range, so rebuild has free nodes between leaves.
    for (int i = 0; i < n / 4; ++i) {
        tree.destroy_proxy(live.back());
        live.pop_back();
    }
    std::vector<Aabb> boxes;
    std::vector<std::uint64_t> users;
    for (const std::int32_t id : live) {
        boxes.push_back(tree.fat_aabb(id));
        users.push_back(tree.user(id));
    }
    const Real incremental_cost = tree.area_cost();
    const std::size_t capacity = tree.node_capacity();

    tree.rebuild();
    tree.validate();
    EXPECT_EQ(tree.proxy_count(), static_cast<std::int32_t>(live.size()));
    EXPECT_LE(tree.node_capacity(), capacity);
    for (std::size_t i = 0; i < live.size(); ++i) {
        ASSERT_TRUE(tree.is_proxy(live[i]));
        EXPECT_EQ(tree.user(live[i]), users[i]);
        EXPECT_TRUE(tree.fat_aabb(live[i]).min == boxes[i].min && tree.fat_aabb(live[i]).max == boxes[i].max);
    }
    EXPECT_LE(tree.area_cost(), incremental_cost * 1.1);
    EXPECT_LE(tree.height(), height_limit(tree.proxy_count()));
    for (int q = 0; q < 100; ++q) {
        const Aabb box = rng.box(60, 10);
        ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box));
    }
    // Incremental use goes on after a rebuild.
    for (int i = 0; i < 50; ++i) live.push_back(tree.create_proxy(rng.box(60, 3), std::uint64_t(i)));
    tree.destroy_proxy(live.front());
    tree.validate();
}

TEST(AabbTree, Rebuild_IdenticalBoxesGiveBalancedTree) {
    DynamicAabbTree tree(AabbTreeSettings{.margin = 0});
    const int n = 1000;
    for (int i = 0; i < n; ++i)
        tree.create_proxy(Aabb::from_center_extents(Vec3::Zero(), Vec3::Ones()), std::uint64_t(i));
    tree.rebuild();
    tree.validate();
    EXPECT_LE(tree.height(), static_cast<int>(std::ceil(std::log2(n))));
}

bool segment_hits(const Aabb& b, const Vec3& origin, const Vec3& translation, Real max_fraction) {
    Real lo = 0;
    Real hi = max_fraction;
    for (int k = 0; k < 3; ++k) {
        if (translation[k] == 0) {
            if (origin[k] < b.min[k] || origin[k] > b.max[k]) return false;
            continue;
        }
        Real t1 = (b.min[k] - origin[k]) / translation[k];
        Real t2 = (b.max[k] - origin[k]) / translation[k];
        if (t1 > t2) std::swap(t1, t2);
        lo = std::max(lo, t1);
        hi = std::min(hi, t2);
    }
    return lo <= hi;
}

TEST(AabbTree, RayCast_MatchesBruteForceAndStops) {
    Rng rng(5);
    DynamicAabbTree tree;
    std::vector<std::int32_t> live;
    for (int i = 0; i < 300 * kScale; ++i) live.push_back(tree.create_proxy(rng.box(30, 2), std::uint64_t(i)));
    for (int r = 0; r < 100; ++r) {
        const Vec3 origin = rng.vec(-40, 40);
        Vec3 translation = rng.vec(-60, 60);
        if (r % 10 == 0) translation.y() = 0;  // axis-parallel components
        std::vector<std::int32_t> hits;
        tree.ray_cast(origin, translation, 1, [&](std::int32_t id, Real max_fraction) {
            hits.push_back(id);
            return max_fraction;
        });
        std::sort(hits.begin(), hits.end());
        std::vector<std::int32_t> expected;
        for (const std::int32_t id : live) {
            if (segment_hits(tree.fat_aabb(id), origin, translation, 1)) expected.push_back(id);
        }
        ASSERT_EQ(hits, expected) << "ray " << r;
        if (!expected.empty()) {
            int calls = 0;
            tree.ray_cast(origin, translation, 1, [&](std::int32_t, Real) {
                ++calls;
                return Real(0);
            });
            EXPECT_EQ(calls, 1);
        }
    }
}

#ifndef NDEBUG
TEST(AabbTree, StaleProxyId_Asserts) {
    const AssertHandler previous = set_assert_handler(&throwing_handler);
    DynamicAabbTree tree;
    const std::int32_t a = tree.create_proxy(Aabb::from_center_extents(Vec3::Zero(), Vec3::Ones()), 1);
    tree.create_proxy(Aabb::from_center_extents(Vec3::Ones(), Vec3::Ones()), 2);
    tree.destroy_proxy(a);
    EXPECT_THROW(tree.destroy_proxy(a), std::logic_error);
    EXPECT_THROW((void)tree.fat_aabb(12345), std::logic_error);
    EXPECT_THROW(tree.create_proxy(Aabb{}, 3), std::logic_error);  // empty box: min > max
    set_assert_handler(previous);
    tree.validate();
}
#endif

}  // namespace
}  // namespace spindle
