// A hull's world bounds, worked out four vertices at a time, against the loop over its
// vertices that Shape::bounds ran before. This file is built as the engine is
// (-ffp-contract=off, CMakeLists.txt): a build that fused a multiply into the add after it
// would round the loop's coordinates differently from the engine's.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "collision/convex_hull.hpp"

namespace spindle {
namespace {

// Hulls whose vertex count leaves one to three lanes of the last group over, kept off the
// origin (a padded lane must not add a point), under turns and offsets large and small.
TEST(HullBounds, AreTheVerticesMovedOneByOne) {
    std::mt19937 rng(33);
    std::normal_distribution<Real> g;
    int part_groups = 0;
    for (int sample = 0; sample < 200; ++sample) {
        std::vector<Vec3> points;
        const Vec3 offset(3 + g(rng), 3 + g(rng), 3 + g(rng));
        for (int i = 0; i < 4 + sample % 13; ++i) points.push_back(offset + Vec3(g(rng), g(rng), g(rng)));
        const ConvexHull hull(points);
        Quat q(g(rng), g(rng), g(rng), g(rng));
        q.normalize();
        const Transform x{Vec3(100 * g(rng), g(rng), 1e4 * g(rng)), q};
        Aabb expected;
        const Mat3 r = x.q.toRotationMatrix();
        for (const Vec3& v : hull.vertices()) expected.include(x.p + r * v);
        const Aabb got = hull.bounds(x);
        ASSERT_EQ(got.min, expected.min) << "sample " << sample << ", " << hull.vertices().size() << " vertices";
        ASSERT_EQ(got.max, expected.max) << "sample " << sample << ", " << hull.vertices().size() << " vertices";
        part_groups += hull.vertices().size() % 4 != 0 ? 1 : 0;
    }
    EXPECT_GT(part_groups, 100);
}

}  // namespace
}  // namespace spindle
