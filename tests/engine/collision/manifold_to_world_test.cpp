// A manifold brought from a pair function's frame into the world, its points four at a time
// in lanes, against Transform::apply point by point. This file is built as the engine is
// (-ffp-contract=off, CMakeLists.txt), so the two round alike.
#include <gtest/gtest.h>

#include <random>

#include "collision/clipping.hpp"

namespace spindle {
namespace {

// Every point count, under turns and offsets large and small; the slots past the count are
// left as they were.
TEST(ManifoldToWorld, TurnsEachPointAsTransformApplyDoes) {
    std::mt19937 rng(36);
    std::normal_distribution<Real> g;
    for (int sample = 0; sample < 400; ++sample) {
        Quat q(g(rng), g(rng), g(rng), g(rng));
        q.normalize();
        const Transform x{Vec3(100 * g(rng), g(rng), 1e4 * g(rng)), q};
        Manifold m;
        m.normal = Vec3(g(rng), g(rng), g(rng)).normalized();
        m.point_count = 1 + sample % kMaxManifoldPoints;
        for (ManifoldPoint& p : m.points) p.point = Vec3(g(rng), 10 * g(rng), 0.1 * g(rng));
        const Manifold local = m;
        detail::manifold_to_world(m, x);
        ASSERT_EQ(m.normal, x.rotate(local.normal)) << "sample " << sample;
        for (int i = 0; i < kMaxManifoldPoints; ++i) {
            const Vec3 expected = i < local.point_count ? x.apply(local.points[i].point) : local.points[i].point;
            ASSERT_EQ(m.points[i].point, expected) << "sample " << sample << ", point " << i;
        }
    }
}

}  // namespace
}  // namespace spindle
