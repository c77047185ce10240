// ProxyTrees: update_pairs against an O(n^2) brute force over random moving scenes,
// the same pairs from any JobSystem, and the reporting rules (once, never static-static).
#include "spatial/proxy_trees.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "test_job_systems.hpp"

namespace spindle {
namespace {

using UserPair = std::pair<std::uint64_t, std::uint64_t>;

Aabb cube(const Vec3& c, Real half) { return Aabb::from_center_extents(c, Vec3::Constant(half)); }

std::vector<UserPair> user_pairs(const PairList& pairs) {
    std::vector<UserPair> out;
    for (const Pair& p : pairs) out.emplace_back(p.user_a, p.user_b);
    return out;
}

bool is_canonical_and_unique(const PairList& pairs) {
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        if (pairs[i].user_a > pairs[i].user_b) return false;
        if (i > 0 &&
            !(UserPair(pairs[i - 1].user_a, pairs[i - 1].user_b) < UserPair(pairs[i].user_a, pairs[i].user_b))) {
            return false;  // users are unique per proxy in these tests, so pairs must strictly increase
        }
    }
    return true;
}

TEST(ProxyTrees, NewProxies_ReportEachOverlapOnceAndNeverStaticWithStatic) {
    ProxyTrees bp;
    SingleThreadedJobSystem jobs;
    bp.create_proxy(cube(Vec3(0, 0, 0), 1), 10, true);
    bp.create_proxy(cube(Vec3(1, 0, 0), 1), 11, true);    // overlaps static 10: never reported
    bp.create_proxy(cube(Vec3(0, 1.5, 0), 1), 3, false);  // overlaps 10, 11 and moving 4
    bp.create_proxy(cube(Vec3(0, 3, 0), 1), 4, false);
    bp.create_proxy(cube(Vec3(50, 0, 0), 1), 5, false);  // alone
    PairList pairs;
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(user_pairs(pairs), (std::vector<UserPair>{{3, 4}, {3, 10}, {3, 11}}));
    for (const Pair& p : pairs) {
        EXPECT_EQ(bp.user(p.proxy_a), p.user_a);
        EXPECT_EQ(bp.user(p.proxy_b), p.user_b);
    }
    EXPECT_EQ(bp.enlarged_count(), 0u);
    bp.update_pairs(jobs, pairs);
    EXPECT_TRUE(pairs.empty());  // nothing moved
}

// Pairs the caller says it has are left out; the rest are the pairs a search without
// the callback reports, in the same order, whether found by a moving or a static proxy.
TEST(ProxyTrees, KnownPairs_LeftOutAndTheRestInOrder) {
    const auto build = [](ProxyTrees& bp) {
        bp.create_proxy(cube(Vec3(0, 0, 0), 1), 20, true);
        for (std::uint64_t k = 0; k < 8; ++k) bp.create_proxy(cube(Vec3(Real(k), 1.5, 0), 1), k, false);
    };
    ProxyTrees all, some;
    build(all);
    build(some);
    SingleThreadedJobSystem jobs;
    PairList every, rest;
    all.update_pairs(jobs, every);
    std::vector<UserPair> asked;
    const auto known = [&asked](std::uint64_t a, std::uint64_t b) {
        asked.emplace_back(a, b);
        return (a + b) % 3 == 0;  // {0, 3}, {1, 2}, {1, 20}, ... known
    };
    some.update_pairs(jobs, rest, known);
    std::vector<UserPair> expected;
    for (const UserPair& p : user_pairs(every)) {
        if ((p.first + p.second) % 3 != 0) expected.push_back(p);
    }
    ASSERT_LT(expected.size(), every.size());
    EXPECT_EQ(user_pairs(rest), expected);
    for (const UserPair& p : asked) EXPECT_LE(p.first, p.second);
    std::sort(asked.begin(), asked.end());
    EXPECT_EQ(asked, user_pairs(every));  // each found pair asked about once, in canonical order
}

TEST(ProxyTrees, MoveInsideFatBox_ReportsNothing_MoveOutside_ReportsAgain) {
    ProxyTrees bp(BroadphaseSettings{.margin = 0.2});
    SingleThreadedJobSystem jobs;
    const ProxyId a = bp.create_proxy(cube(Vec3(0, 0, 0), 1), 1, false);
    bp.create_proxy(cube(Vec3(2.3, 0, 0), 1), 2, false);
    PairList pairs;
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(user_pairs(pairs), (std::vector<UserPair>{{1, 2}}));  // fat boxes overlap: 1.2 + 1.2 > 2.3

    EXPECT_FALSE(bp.move_proxy(a, cube(Vec3(0.1, 0, 0), 1), Vec3(0.1, 0, 0)));
    bp.update_pairs(jobs, pairs);
    EXPECT_TRUE(pairs.empty());

    // Grows: found again (the engine skips pairs it already has).
    EXPECT_TRUE(bp.move_proxy(a, cube(Vec3(0.4, 0, 0), 1), Vec3(0.3, 0, 0)));
    EXPECT_TRUE(bp.is_enlarged(a));
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(user_pairs(pairs), (std::vector<UserPair>{{1, 2}}));
}

TEST(ProxyTrees, TwoEnlargedProxies_PairReportedOnce) {
    ProxyTrees bp;
    SingleThreadedJobSystem jobs;
    const ProxyId a = bp.create_proxy(cube(Vec3(0, 0, 0), 1), 1, false);
    const ProxyId b = bp.create_proxy(cube(Vec3(10, 0, 0), 1), 2, false);
    PairList pairs;
    bp.update_pairs(jobs, pairs);
    EXPECT_TRUE(pairs.empty());
    EXPECT_TRUE(bp.move_proxy(a, cube(Vec3(4, 0, 0), 1), Vec3(4, 0, 0)));
    EXPECT_TRUE(bp.move_proxy(b, cube(Vec3(5, 0, 0), 1), Vec3(-5, 0, 0)));
    bp.update_pairs(jobs, pairs);
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_EQ(pairs[0].proxy_a, a);
    EXPECT_EQ(pairs[0].proxy_b, b);
}

TEST(ProxyTrees, MovedStaticProxy_FindsMovingButNotStatic) {
    ProxyTrees bp;
    SingleThreadedJobSystem jobs;
    const ProxyId s = bp.create_proxy(cube(Vec3(0, 0, 0), 1), 1, true);
    bp.create_proxy(cube(Vec3(10, 0, 0), 1), 2, true);
    bp.create_proxy(cube(Vec3(10, 2, 0), 1), 3, false);
    PairList pairs;
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(user_pairs(pairs), (std::vector<UserPair>{{2, 3}}));
    EXPECT_TRUE(bp.move_proxy(s, cube(Vec3(10, 1, 0), 1), Vec3::Zero()));  // teleported onto both
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(user_pairs(pairs), (std::vector<UserPair>{{1, 3}}));
}

TEST(ProxyTrees, DestroyedEnlargedProxy_IsNotReported) {
    ProxyTrees bp;
    SingleThreadedJobSystem jobs;
    const ProxyId a = bp.create_proxy(cube(Vec3(0, 0, 0), 1), 1, false);
    const ProxyId b = bp.create_proxy(cube(Vec3(1, 0, 0), 1), 2, false);
    bp.create_proxy(cube(Vec3(0, 1, 0), 1), 3, false);
    bp.destroy_proxy(a);
    bp.validate();
    PairList pairs;
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(user_pairs(pairs), (std::vector<UserPair>{{2, 3}}));
    bp.destroy_proxy(b);
    bp.validate();
}

TEST(ProxyTrees, TestOverlap_UsesFatBoxes) {
    ProxyTrees bp(BroadphaseSettings{.margin = 0.1});
    const ProxyId a = bp.create_proxy(cube(Vec3(0, 0, 0), 1), 1, false);
    const ProxyId b = bp.create_proxy(cube(Vec3(2.15, 0, 0), 1), 2, false);  // tight gap 0.15 < 2 margins
    const ProxyId c = bp.create_proxy(cube(Vec3(2.3, 0, 0), 1), 3, true);    // static: no margin
    EXPECT_TRUE(bp.test_overlap(a, b));
    EXPECT_FALSE(bp.test_overlap(a, c));
    EXPECT_TRUE(bp.test_overlap(b, c));
}

TEST(ProxyTrees, NothingEnlarged_RunsNoJobs) {
    ProxyTrees bp;
    test::CountingJobSystem jobs;
    PairList pairs{Pair{}};
    bp.update_pairs(jobs, pairs);
    EXPECT_TRUE(pairs.empty());
    EXPECT_EQ(jobs.chunks, 0);
    const ProxyId a = bp.create_proxy(cube(Vec3::Zero(), 1), 1, false);
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(jobs.chunks, 1);
    bp.move_proxy(a, cube(Vec3(0.01, 0, 0), 1), Vec3(0.01, 0, 0));
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(jobs.chunks, 1);
}

// A random scene of boxes: a fraction static, the rest moving with constant velocity
// (some fast) and bouncing inside a cube; bodies are destroyed and created as it runs.
class Scene {
public:
    Scene(int bodies, std::uint64_t seed, BroadphaseSettings settings = {})
        : m_rng(seed), m_bp(settings), m_world(3.0 * std::cbrt(Real(bodies)) / 2) {
        for (int i = 0; i < bodies; ++i) add_body(uniform(0, 1) < 0.2);
    }

    ProxyTrees& broadphase() { return m_bp; }
    std::size_t body_count() const { return m_bodies.size(); }

    // One step: every moving body moves; a few are destroyed, created, teleported.
    void step() {
        const Real dt = 1.0 / 60.0;
        for (Body& b : m_bodies) {
            if (b.is_static) continue;
            Vec3 d = b.velocity * dt;
            for (int k = 0; k < 3; ++k) {
                if (std::abs(b.center[k] + d[k]) > m_world) {
                    b.velocity[k] = -b.velocity[k];
                    d[k] = -d[k];
                }
            }
            b.center += d;
            if (m_bp.move_proxy(b.proxy, tight(b), d)) b.enlarged = true;
        }
        const int churn = std::max(1, static_cast<int>(m_bodies.size()) / 100);
        for (int i = 0; i < churn; ++i) {
            const std::size_t victim = index(m_bodies.size());
            m_bp.destroy_proxy(m_bodies[victim].proxy);
            m_bodies[victim] = m_bodies.back();
            m_bodies.pop_back();
            add_body(uniform(0, 1) < 0.2);
        }
        // Teleport one static body (the engine allows moving a static body by hand).
        for (Body& b : m_bodies) {
            if (!b.is_static) continue;
            b.center = random_point();
            if (m_bp.move_proxy(b.proxy, tight(b), Vec3::Zero())) b.enlarged = true;
            break;
        }
    }

    // Brute force over every pair: all overlapping fat-box pairs (not static-static), and
    // those with at least one proxy enlarged since the last update.
    void brute_force(std::set<UserPair>& overlapping, std::vector<UserPair>& expected_new) const {
        overlapping.clear();
        expected_new.clear();
        const std::size_t n = m_bodies.size();
        std::vector<Aabb> fat(n);
        for (std::size_t i = 0; i < n; ++i) fat[i] = m_bp.fat_aabb(m_bodies[i].proxy);
        for (std::size_t i = 0; i < n; ++i) {
            const Body& a = m_bodies[i];
            for (std::size_t j = i + 1; j < n; ++j) {
                const Body& b = m_bodies[j];
                if (a.is_static && b.is_static) continue;
                if (!fat[i].overlaps(fat[j])) continue;
                const UserPair p(std::min(a.user, b.user), std::max(a.user, b.user));
                overlapping.insert(p);
                if (a.enlarged || b.enlarged) expected_new.push_back(p);
            }
        }
        std::sort(expected_new.begin(), expected_new.end());
    }

    void clear_enlarged() {
        for (Body& b : m_bodies) b.enlarged = false;
    }

private:
    struct Body {
        ProxyId proxy;
        std::uint64_t user;
        bool is_static;
        bool enlarged;
        Vec3 center;
        Vec3 half;
        Vec3 velocity;
    };

    Real uniform(Real lo, Real hi) { return std::uniform_real_distribution<Real>(lo, hi)(m_rng); }
    std::size_t index(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(m_rng); }
    Vec3 random_point() { return {uniform(-m_world, m_world), uniform(-m_world, m_world), uniform(-m_world, m_world)}; }
    static Aabb tight(const Body& b) { return Aabb::from_center_extents(b.center, b.half); }

    void add_body(bool is_static) {
        Body b;
        b.user = m_next_user++;
        b.is_static = is_static;
        b.enlarged = true;  // a new proxy finds its pairs at the next update
        b.center = random_point();
        b.half = Vec3(uniform(0.2, 1.0), uniform(0.2, 1.0), uniform(0.2, 1.0));
        const Real speed = uniform(0, 1) < 0.1 ? 30.0 : 2.0;  // some fast bodies stretch their boxes
        b.velocity = Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * speed;
        b.proxy = m_bp.create_proxy(tight(b), b.user, is_static);
        m_bodies.push_back(b);
    }

    std::mt19937_64 m_rng;
    ProxyTrees m_bp;
    Real m_world;
    std::uint64_t m_next_user = 1;
    std::vector<Body> m_bodies;
};

struct SceneCase {
    int bodies;
    int steps;
};

class BroadphaseScenes : public ::testing::TestWithParam<SceneCase> {};

// The engine's view: it adds the new pairs to its contacts and drops contacts whose fat
// boxes stopped overlapping. After every update its contacts must be exactly the
// overlapping pairs, and update_pairs must return exactly the brute-force new pairs.
TEST_P(BroadphaseScenes, UpdatePairs_MatchesBruteForce) {
    const SceneCase c = GetParam();
    Scene scene(c.bodies, 42 + static_cast<std::uint64_t>(c.bodies));
    test::ReverseThreadedJobSystem jobs(3);
    std::set<UserPair> contacts;
    std::set<UserPair> overlapping;
    std::vector<UserPair> expected_new;
    PairList pairs;
    for (int step = 0; step < c.steps; ++step) {
        if (step > 0) scene.step();
        scene.brute_force(overlapping, expected_new);
        scene.broadphase().update_pairs(jobs, pairs);
        scene.clear_enlarged();
        ASSERT_TRUE(is_canonical_and_unique(pairs)) << "step " << step;
        ASSERT_EQ(user_pairs(pairs), expected_new) << "step " << step;
        ASSERT_EQ(scene.broadphase().enlarged_count(), 0u);

        for (auto it = contacts.begin(); it != contacts.end();) {
            it = overlapping.count(*it) ? std::next(it) : contacts.erase(it);
        }
        for (const Pair& p : pairs) {
            ASSERT_TRUE(scene.broadphase().test_overlap(p.proxy_a, p.proxy_b));
            contacts.emplace(p.user_a, p.user_b);
        }
        ASSERT_EQ(contacts, overlapping) << "step " << step;
    }
    scene.broadphase().validate();
    EXPECT_LE(scene.broadphase().moving_tree().height(),
              static_cast<int>(2.5 * std::log2(std::max(2, scene.broadphase().moving_tree().proxy_count()))) + 3);
}

#ifdef NDEBUG
INSTANTIATE_TEST_SUITE_P(Sizes, BroadphaseScenes,
                         ::testing::Values(SceneCase{10, 200}, SceneCase{200, 200}, SceneCase{2000, 60},
                                           SceneCase{10000, 12}));
#else
// Debug and sanitizer builds validate both trees after every operation: smaller scenes.
INSTANTIATE_TEST_SUITE_P(Sizes, BroadphaseScenes,
                         ::testing::Values(SceneCase{10, 100}, SceneCase{200, 60}, SceneCase{1000, 20}));
#endif

// Two broadphases fed the same operations, one updated by SingleThreadedJobSystem with
// the default grain, one by threads running chunks backwards with a tiny grain: the new
// pair lists are identical, proxy ids included.
TEST(ProxyTrees, UpdatePairs_SameResultForAnyJobSystemAndGrain) {
#ifdef NDEBUG
    const int bodies = 3000;
    const int steps = 30;
#else
    const int bodies = 600;
    const int steps = 15;
#endif
    Scene single(bodies, 7);
    Scene threaded(bodies, 7, BroadphaseSettings{.grain = 3});
    SingleThreadedJobSystem jobs_single;
    test::ReverseThreadedJobSystem jobs_threaded(4);
    PairList a;
    PairList b;
    std::size_t total = 0;
    for (int step = 0; step < steps; ++step) {
        single.step();
        threaded.step();
        single.broadphase().update_pairs(jobs_single, a);
        threaded.broadphase().update_pairs(jobs_threaded, b);
        ASSERT_EQ(a.size(), b.size()) << "step " << step;
        for (std::size_t i = 0; i < a.size(); ++i) {
            ASSERT_EQ(a[i].proxy_a, b[i].proxy_a);
            ASSERT_EQ(a[i].proxy_b, b[i].proxy_b);
            ASSERT_EQ(a[i].user_a, b[i].user_a);
            ASSERT_EQ(a[i].user_b, b[i].user_b);
        }
        total += a.size();
    }
    EXPECT_GT(total, 0u);
}

// The broadphase's moves in one batch: set_fat_boxes in jobs (three threads taking the
// ranges last to first, a small grain's worth of ids each) leaves the trees as set_fat_box
// on each id in turn does: the same fat boxes, the same flagged nodes, the same enlarged
// list in the same order (grown proxies only, each once: some were enlarged already), and
// then the same pairs. Static proxies and boxes that shrank are among the moves.
TEST(ProxyTrees, FatBoxesSetInJobs_AreTheTreesOfOneByOne) {
#ifdef NDEBUG
    constexpr int kProxies = 4000;
#else
    constexpr int kProxies = 800;
#endif
    std::mt19937_64 rng(23);
    const auto uniform = [&](Real lo, Real hi) { return std::uniform_real_distribution<Real>(lo, hi)(rng); };
    const auto vec = [&](Real lo, Real hi) { return Vec3(uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)); };
    // The same crowding for either count: a debug build's fewer proxies in a smaller room
    // (4,000 in 80 m across; 800 in 80 m across found no pair in some round).
    const Real half = 40 * std::cbrt(Real(kProxies) / 4000);
    ProxyTrees one_by_one;
    std::vector<ProxyId> ids;
    for (int i = 0; i < kProxies; ++i) {
        ids.push_back(one_by_one.create_proxy(cube(vec(-half, half), 0.4), static_cast<std::uint64_t>(i), i % 16 == 0));
    }
    SingleThreadedJobSystem jobs_single;
    test::ReverseThreadedJobSystem jobs_threaded(3);
    PairList pairs_single;
    PairList pairs_threaded;
    one_by_one.update_pairs(jobs_single, pairs_single);
    ProxyTrees batch = one_by_one;
    std::vector<ProxyId> moved(ids.size());
    std::vector<Aabb> boxes(ids.size());
    for (int round = 0; round < 6; ++round) {
        for (std::size_t k = 0; k < ids.size(); ++k) {
            moved[k] = ProxyId{};
            if (uniform(0, 1) < 0.4) continue;
            moved[k] = ids[k];
            const Aabb& fat = one_by_one.fat_aabb(ids[k]);
            // A third shrink inside their fat box (no new pairs), the rest move.
            boxes[k] = uniform(0, 1) < 0.33 ? Aabb{fat.min.array() + 0.05, fat.max.array() - 0.05}
                                            : Aabb::from_center_extents(fat.center() + vec(-0.6, 0.6),
                                                                        Vec3::Constant(uniform(0.3, 0.6)));
        }
        for (std::size_t k = 0; k < ids.size(); k += 7) {  // enlarged before the moves: not listed twice
            one_by_one.touch(ids[k]);
            batch.touch(ids[k]);
        }
        for (std::size_t k = 0; k < ids.size(); ++k) {
            if (moved[k].valid()) one_by_one.set_fat_box(moved[k], boxes[k]);
        }
        batch.set_fat_boxes(jobs_threaded, moved, boxes);
        batch.validate();
        const std::span<const ProxyId> expected = one_by_one.enlarged();
        const std::span<const ProxyId> got = batch.enlarged();
        ASSERT_EQ(got.size(), expected.size()) << "round " << round;
        ASSERT_TRUE(std::equal(got.begin(), got.end(), expected.begin())) << "round " << round;
        ASSERT_GT(batch.moving_tree().enlarged_node_count(), 0);
        ASSERT_EQ(batch.moving_tree().enlarged_node_count(), one_by_one.moving_tree().enlarged_node_count());
        ASSERT_EQ(batch.static_tree().enlarged_node_count(), one_by_one.static_tree().enlarged_node_count());
        for (const ProxyId id : ids) {
            ASSERT_TRUE(batch.fat_aabb(id).min == one_by_one.fat_aabb(id).min &&
                        batch.fat_aabb(id).max == one_by_one.fat_aabb(id).max);
        }
        one_by_one.update_pairs(jobs_single, pairs_single);
        batch.update_pairs(jobs_threaded, pairs_threaded);
        batch.validate();
        ASSERT_GT(pairs_single.size(), 0u);
        ASSERT_EQ(user_pairs(pairs_threaded), user_pairs(pairs_single)) << "round " << round;
    }
}

// The pair lists are raw room (PairList): a resize leaves the new pairs' bytes as they
// were. Before each update the caller's list is cleared and its room filled with 0xff
// bytes (proxies and users out of range) in one broadphase, with zeros in its twin; the
// lists alternate with the merge's scratch, so both grow into filled room. Every pair
// must be written before it is read or returned: the lists come out the same.
TEST(ProxyTrees, UpdatePairs_ListsGrownIntoFilledRoomAsIntoZeros) {
    constexpr int kBodies = 1000;
    constexpr int kSteps = 20;
    constexpr std::size_t kFew = 64;
    const auto fill_room = [](PairList& pairs, unsigned char byte) {
        pairs.reserve(2 * pairs.size() + kFew);
        pairs.clear();
        std::memset(static_cast<void*>(pairs.data()), byte, pairs.capacity() * sizeof(Pair));
    };
    Scene clean(kBodies, 11, BroadphaseSettings{.grain = 3});
    Scene filled(kBodies, 11, BroadphaseSettings{.grain = 3});
    test::ReverseThreadedJobSystem jobs(3);
    PairList a;
    PairList b;
    std::size_t total = 0;
    for (int step = 0; step < kSteps; ++step) {
        if (step > 0) {
            clean.step();
            filled.step();
        }
        fill_room(a, 0x00);
        fill_room(b, 0xff);
        clean.broadphase().update_pairs(jobs, a);
        filled.broadphase().update_pairs(jobs, b);
        ASSERT_EQ(a.size(), b.size()) << "step " << step;
        ASSERT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Pair)), 0) << "step " << step;
        total += a.size();
    }
    EXPECT_GT(total, 0u);
}

// A first step's search: every proxy new, so the chunks' runs (and each proxy's own pairs)
// may already lie in order and are then neither sorted nor merged. The list is the brute
// force's in canonical order, proxies included, however the proxies were made: users in
// order (runs in order), in reverse (runs to merge), shuffled (chunks to sort), and with
// users shared by neighbouring proxies (ties broken by the proxy keys), on one and on
// three threads taking the chunks last to first.
TEST(ProxyTrees, FirstSearch_AnyMakingOrder_PairsInCanonicalOrder) {
    const auto canonical = [](const Pair& a, const Pair& b) {
        return std::make_tuple(a.user_a, a.user_b, a.proxy_a.key(), a.proxy_b.key()) <
               std::make_tuple(b.user_a, b.user_b, b.proxy_a.key(), b.proxy_b.key());
    };
    constexpr int kSide = 12;  // a 12 x 12 x 3 block of touching cubes on a static floor
    std::vector<Vec3> centres;
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < kSide; ++x) {
            for (int z = 0; z < kSide; ++z) centres.emplace_back(x * Real(0.95), y * Real(0.95) + 1, z * Real(0.95));
        }
    }
    std::vector<std::size_t> order(centres.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::vector<std::vector<std::size_t>> orders{order, std::vector<std::size_t>(order.rbegin(), order.rend())};
    std::shuffle(order.begin(), order.end(), std::mt19937_64(3));
    orders.push_back(order);
    // Users of one proxy each, of two proxies each, and too far apart to be counted (the
    // first search orders its pairs by counting their first users where it can).
    enum class Users { Own, Shared, Sparse };
    for (const Users kind : {Users::Own, Users::Shared, Users::Sparse}) {
        const int shared_users = static_cast<int>(kind);
        for (std::size_t o = 0; o < orders.size(); ++o) {
            for (const bool threaded : {false, true}) {
                ProxyTrees bp(BroadphaseSettings{.grain = 5});
                std::vector<ProxyId> ids;
                std::vector<std::uint64_t> users;
                const ProxyId floor = bp.create_proxy(cube(Vec3(6, 0, 6), 7), 0, true);
                for (const std::size_t k : orders[o]) {
                    users.push_back(kind == Users::Shared   ? 1 + k / 2
                                    : kind == Users::Sparse ? 1 + k * (std::uint64_t{1} << 40)
                                                            : 1 + k);
                    ids.push_back(bp.create_proxy(cube(centres[k], 0.5), users.back(), false));
                }
                std::vector<Pair> expected;
                for (std::size_t i = 0; i < ids.size(); ++i) {
                    if (bp.test_overlap(ids[i], floor)) expected.push_back(Pair{floor, ids[i], 0, users[i]});
                    for (std::size_t j = 0; j < ids.size(); ++j) {
                        const bool first = users[i] < users[j] || (users[i] == users[j] && ids[i].key() < ids[j].key());
                        if (j != i && first && bp.test_overlap(ids[i], ids[j])) {
                            expected.push_back(Pair{ids[i], ids[j], users[i], users[j]});
                        }
                    }
                }
                std::sort(expected.begin(), expected.end(), canonical);
                PairList pairs;
                if (threaded) {
                    test::ReverseThreadedJobSystem jobs(3);
                    bp.update_pairs(jobs, pairs);
                } else {
                    SingleThreadedJobSystem jobs;
                    bp.update_pairs(jobs, pairs);
                }
                ASSERT_GT(expected.size(), 3 * centres.size());  // many chunks' worth, and the floor's hundreds
                ASSERT_EQ(pairs.size(), expected.size()) << "order " << o << " shared " << shared_users;
                for (std::size_t i = 0; i < pairs.size(); ++i) {
                    ASSERT_EQ(pairs[i].proxy_a, expected[i].proxy_a)
                        << "order " << o << " shared " << shared_users << " threaded " << threaded << " at " << i;
                    ASSERT_EQ(pairs[i].proxy_b, expected[i].proxy_b);
                    ASSERT_EQ(pairs[i].user_a, expected[i].user_a);
                    ASSERT_EQ(pairs[i].user_b, expected[i].user_b);
                }
            }
        }
    }
}

// A first step walks the moving tree against itself, on one worker or several (the walk
// meets each overlapping node pair once; searches side by side took 2-3 times as long in
// many_pyramids' first step on two). Its pairs go into room for the pairs the caller
// expects, taken at once among the step's stocked arrays: a list grown by doubling on the
// heap wrote twice its bytes on fresh pages (many_pyramids' first step: 1 ms of page faults).
TEST(ProxyTrees, FirstWalk_TakesTheRoomForTheExpectedPairsAtOnce) {
    constexpr std::size_t kExpected = std::size_t{1} << 16;
    for (const bool threaded : {false, true}) {
        const auto first_walk = [threaded](std::size_t expected) {
            auto bp = std::make_unique<ProxyTrees>();
            for (std::uint64_t k = 0; k < 200; ++k) bp->create_proxy(cube(Vec3(1.5 * Real(k), 0, 0), 1), k, false);
            PairList pairs;
            const auto unknown = [](std::uint64_t, std::uint64_t) { return false; };
            if (threaded) {
                test::ReverseThreadedJobSystem jobs(2);
                bp->update_pairs(jobs, pairs, unknown, expected);
            } else {
                SingleThreadedJobSystem jobs;
                bp->update_pairs(jobs, pairs, unknown, expected);
            }
            EXPECT_EQ(pairs.size(), 199u);  // each cube overlaps its neighbours only
            EXPECT_TRUE(is_canonical_and_unique(pairs));
            return bp;
        };
        const auto unexpected = first_walk(0);
        const auto expected = first_walk(kExpected);
        // Without the expectation the walk's room is at most twice its 199 pairs.
        EXPECT_GE(expected->heap_bytes(), unexpected->heap_bytes() + (kExpected - 2 * 199) * sizeof(Pair))
            << "the walk's pairs did not take the expected room" << (threaded ? " on two workers" : "");
    }
}

TEST(ProxyTrees, RebuildStaticTree_KeepsProxiesAndPairs) {
    ProxyTrees bp;
    SingleThreadedJobSystem jobs;
    std::vector<ProxyId> statics;
    for (int i = 0; i < 200; ++i)
        statics.push_back(bp.create_proxy(cube(Vec3(i * 1.5, 0, 0), 1), std::uint64_t(i), true));
    PairList pairs;
    bp.update_pairs(jobs, pairs);
    EXPECT_TRUE(pairs.empty());
    bp.rebuild_static_tree();
    bp.validate();
    const ProxyId m = bp.create_proxy(cube(Vec3(30, 1.5, 0), 1), 1000, false);
    bp.update_pairs(jobs, pairs);
    EXPECT_EQ(user_pairs(pairs), (std::vector<UserPair>{{19, 1000}, {20, 1000}, {21, 1000}}));
    for (const ProxyId s : statics)
        EXPECT_EQ(bp.user(s), static_cast<std::uint64_t>(bp.fat_aabb(s).center().x() / 1.5 + 0.5));
    int found = 0;
    bp.query(cube(Vec3(30, 0.7, 0), 0.1), [&](ProxyId id) {
        found += (id == m || id.is_static()) ? 1 : 0;
        return true;
    });
    EXPECT_EQ(found, 2);  // static 20 and the moving proxy
}

}  // namespace
}  // namespace spindle
