// DynamicAabbTree::create_proxies, the bulk build: every proxy queryable with its box and
// user value, a tree as good as rebuild()'s, the same tree from jobs as on one thread, old
// proxies kept when a batch joins them, and incremental use going on after it.
#include "spatial/aabb_tree.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "test_job_systems.hpp"
#include "tree_test_support.hpp"

namespace spindle {
namespace {

using namespace test;

struct Batch {
    std::vector<Aabb> tight;
    std::vector<std::uint64_t> users;
};

Batch random_batch(Rng& rng, int n, std::uint64_t first_user) {
    Batch batch;
    for (int i = 0; i < n; ++i) {
        batch.tight.push_back(rng.box(60, 3));
        batch.users.push_back(first_user + static_cast<std::uint64_t>(i));
    }
    return batch;
}

std::vector<std::int32_t> add(DynamicAabbTree& tree, const Batch& batch, JobSystem* jobs = nullptr) {
    std::vector<std::int32_t> ids(batch.tight.size());
    tree.create_proxies(batch.tight, batch.users, ids, jobs);
    return ids;
}

void expect_proxies(const DynamicAabbTree& tree, const std::vector<std::int32_t>& ids, const Batch& batch) {
    for (std::size_t k = 0; k < ids.size(); ++k) {
        ASSERT_TRUE(tree.is_proxy(ids[k])) << "proxy " << k;
        ASSERT_EQ(tree.user(ids[k]), batch.users[k]);
        const Aabb fat = batch.tight[k].fattened(tree.settings().margin);
        ASSERT_TRUE(tree.fat_aabb(ids[k]).min == fat.min && tree.fat_aabb(ids[k]).max == fat.max) << "proxy " << k;
    }
}

TEST(AabbTreeBulk, IntoAnEmptyTree_AsGoodAsRebuildAndMatchesBruteForce) {
    Rng rng(31);
    const Batch batch = random_batch(rng, 1000 * kScale, 500);
    DynamicAabbTree bulk;
    const std::vector<std::int32_t> ids = add(bulk, batch);
    bulk.validate();
    ASSERT_EQ(bulk.proxy_count(), static_cast<std::int32_t>(batch.tight.size()));
    expect_proxies(bulk, ids, batch);
    EXPECT_EQ(bulk.node_capacity(), 2 * batch.tight.size() - 1);  // no node beyond a full binary tree

    // The same proxies inserted one by one, then rebuilt: the bulk build is that tree.
    DynamicAabbTree incremental;
    for (std::size_t k = 0; k < batch.tight.size(); ++k) incremental.create_proxy(batch.tight[k], batch.users[k]);
    const Real incremental_cost = incremental.area_cost();
    incremental.rebuild();
    // The same nodes' boxes, summed in another node order.
    EXPECT_NEAR(bulk.area_cost(), incremental.area_cost(), 1e-9 * incremental.area_cost());
    EXPECT_EQ(bulk.height(), incremental.height());
    EXPECT_LE(bulk.area_cost(), incremental_cost * 1.1);
    EXPECT_LE(bulk.height(), height_limit(bulk.proxy_count()));
    for (int q = 0; q < 100; ++q) {
        const Aabb box = rng.box(60, 10);
        ASSERT_EQ(query_sorted(bulk, box), brute_sorted(bulk, ids, box));
    }
}

// Big enough to be built in jobs (ranges of up to 256 leaves): on three threads, chunks
// in reverse order, the same tree as on the calling thread alone.
TEST(AabbTreeBulk, InJobs_SameTreeAsOnOneThread) {
    Rng rng(32);
    const Batch batch = random_batch(rng, 600 * kScale, 0);
    DynamicAabbTree serial;
    DynamicAabbTree parallel;
    test::ReverseThreadedJobSystem jobs(3);
    const std::vector<std::int32_t> ids = add(serial, batch);
    ASSERT_EQ(add(parallel, batch, &jobs), ids);
    parallel.validate();
    EXPECT_EQ(walk_order(parallel), walk_order(serial));
    EXPECT_EQ(parallel.area_cost(), serial.area_cost());
    EXPECT_EQ(parallel.height(), serial.height());
}

// A batch joining a tree that has proxies (and holes where some were destroyed): the old
// ones keep their ids, boxes and users; all are found; the tree goes on as before.
TEST(AabbTreeBulk, IntoATreeWithProxies_KeepsThemAndIncrementalUseGoesOn) {
    Rng rng(33);
    DynamicAabbTree tree;
    Batch old_batch = random_batch(rng, 300 * kScale, 0);
    std::vector<std::int32_t> old_ids;
    for (std::size_t k = 0; k < old_batch.tight.size(); ++k) {
        old_ids.push_back(tree.create_proxy(old_batch.tight[k], old_batch.users[k]));
    }
    for (int i = 0; i < 50; ++i) {
        tree.destroy_proxy(old_ids.back());
        old_ids.pop_back();
        old_batch.tight.pop_back();
        old_batch.users.pop_back();
    }
    const Batch batch = random_batch(rng, 500 * kScale, 100000);
    const std::vector<std::int32_t> ids = add(tree, batch);
    tree.validate();
    ASSERT_EQ(tree.proxy_count(), static_cast<std::int32_t>(old_ids.size() + ids.size()));
    expect_proxies(tree, old_ids, old_batch);
    expect_proxies(tree, ids, batch);
    std::vector<std::int32_t> live = old_ids;
    live.insert(live.end(), ids.begin(), ids.end());
    for (int q = 0; q < 100; ++q) {
        const Aabb box = rng.box(60, 10);
        ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box));
    }
    for (const std::int32_t id : ids) {
        const Vec3 d = rng.vec(-2, 2);
        tree.move_proxy(id, Aabb::from_center_extents(tree.fat_aabb(id).center() + d, Vec3::Constant(0.5)), d);
    }
    tree.rebuild_enlarged();
    tree.destroy_proxy(live.front());
    live.erase(live.begin());
    live.push_back(tree.create_proxy(rng.box(60, 3), 7));
    tree.validate();
    for (int q = 0; q < 50; ++q) {
        const Aabb box = rng.box(60, 10);
        ASSERT_EQ(query_sorted(tree, box), brute_sorted(tree, live, box));
    }
}

TEST(AabbTreeBulk, OneProxyAndNone) {
    DynamicAabbTree tree;
    std::vector<std::int32_t> none;
    tree.create_proxies({}, {}, none);
    EXPECT_EQ(tree.proxy_count(), 0);
    const Batch one{{Aabb::from_center_extents(Vec3(1, 2, 3), Vec3::Constant(0.5))}, {42}};
    const std::vector<std::int32_t> ids = add(tree, one);
    tree.validate();
    expect_proxies(tree, ids, one);
    EXPECT_EQ(tree.height(), 0);
}

}  // namespace
}  // namespace spindle
