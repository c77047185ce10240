// FeatureCache (collide_cached): a box or hull pair that stays apart is told so by the
// axis that last separated it, and nothing else changes: along tumbling paths the cached
// calls give the same manifolds, bit for bit, as collide() without a cache.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;

// A hull of 32 points on a sphere of radius r, as Box3D's convex_pile draws them.
Shape random_hull(std::uint32_t seed, Real r) {
    std::mt19937 random(seed);
    std::normal_distribution<Real> normal(0, 1);
    std::vector<Vec3> points;
    for (int i = 0; i < 32; ++i)
        points.push_back(r * Vec3(normal(random), normal(random), normal(random)).normalized());
    return Shape::convex_hull(points);
}

void expect_same(const Manifold* x, int nx, const Manifold* y, int ny, int step) {
    ASSERT_EQ(nx, ny) << "step " << step;
    for (int m = 0; m < nx; ++m) {
        ASSERT_EQ(x[m].point_count, y[m].point_count) << "step " << step;
        EXPECT_EQ(x[m].normal, y[m].normal) << "step " << step;
        for (int j = 0; j < x[m].point_count; ++j) {
            EXPECT_EQ(x[m].points[j].point, y[m].points[j].point) << "step " << step;
            EXPECT_EQ(x[m].points[j].separation, y[m].points[j].separation) << "step " << step;
            EXPECT_EQ(x[m].points[j].id, y[m].points[j].id) << "step " << step;
        }
    }
}

// B tumbles past A (and through it) while both turn: the pair is apart, touching and apart
// again, each way round, with face, edge and swapped (hull-box) axes.
struct Tumble {
    Shape a, b;
    int apart = 0, cached_apart = 0, touching = 0;

    void run(std::uint32_t seed) {
        FeatureCache cache;
        std::mt19937 random(seed);
        std::uniform_real_distribution<Real> u(-1, 1);
        const Vec3 axis_a(u(random), u(random), u(random)), axis_b(u(random), u(random), u(random));
        const Vec3 start(u(random), 6, u(random)), end(u(random), -6, u(random));
        for (int step = 0; step <= 300; ++step) {
            const Real t = step / 300.0;
            const Transform xa = at(Vec3::Zero(), about(axis_a, 2 * t));
            const Transform xb = at(start + t * (end - start), about(axis_b, 5 * t));
            const Real speculative = 0.1;
            const FeatureCache before = cache;
            Manifold cached[8], plain[8];
            const int nc = collide_cached(a, xa, b, xb, speculative, cached, 8, cache);
            const int np = collide(a, xa, b, xb, speculative, plain, 8);
            expect_same(cached, nc, plain, np, step);
            if (nc > 0) {
                touching += 1;
                EXPECT_EQ(cache.kind(), FeatureCache::Kind::None) << "step " << step;
            } else {
                apart += 1;
                EXPECT_NE(cache.kind(), FeatureCache::Kind::None) << "step " << step;
                cached_apart += before.kind() != FeatureCache::Kind::None && before == cache;
            }
        }
    }
};

TEST(FeatureCache, HullPairsGiveTheSameManifoldsAsWithoutACache) {
    for (std::uint32_t seed = 1; seed <= 12; ++seed) {
        Tumble tumble{random_hull(seed, 2), random_hull(seed + 100, 1.5)};
        tumble.run(seed);
        EXPECT_GT(tumble.touching, 10) << "seed " << seed;
        // Most steps apart keep the axis that separated the step before.
        EXPECT_GT(tumble.cached_apart, tumble.apart / 2) << "seed " << seed;
    }
}

TEST(FeatureCache, BoxHullPairsGiveTheSameManifoldsEitherWayRound) {
    for (std::uint32_t seed = 1; seed <= 6; ++seed) {
        Tumble box_first{Shape::box(Vec3(1.5, 0.4, 1)), random_hull(seed, 1.5)};
        box_first.run(seed);
        Tumble hull_first{random_hull(seed, 1.5), Shape::box(Vec3(1.5, 0.4, 1))};
        hull_first.run(seed);
        EXPECT_GT(box_first.touching, 10) << "seed " << seed;
        EXPECT_GT(hull_first.touching, 10) << "seed " << seed;
    }
}

TEST(FeatureCache, OtherPairsClearIt) {
    FeatureCache cache(FeatureCache::Kind::FaceA, 3, 0);
    Manifold out[8];
    const Shape box = Shape::box(Vec3(1, 1, 1));
    EXPECT_EQ(collide_cached(box, at(Vec3::Zero()), box, at(Vec3(0, 1.9, 0)), 0, out, 8, cache), 1);
    EXPECT_EQ(cache.kind(), FeatureCache::Kind::None);
}

}  // namespace
}  // namespace spindle
