// Properties over random poses for every convex pair: swapping the order flips the
// normal and keeps the depth, and the reported depth matches the true penetration
// depth found by brute force over support functions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;

// Support value max over the shape of d . x (d unit, world).
Real support(const Shape& s, const Transform& x, const Vec3& d) {
    const Vec3 local = x.rotate_inverse(d);
    Real best = -kHuge;
    switch (s.type) {
        case ShapeType::Sphere: best = 0; break;
        case ShapeType::Capsule: best = std::abs(local.y()) * s.half_height; break;
        case ShapeType::Box: best = local.cwiseAbs().dot(s.half_extents); break;
        case ShapeType::ConvexHull:
            for (const Vec3& v : s.hull->vertices()) best = std::max(best, v.dot(local));
            break;
        default: break;
    }
    if (s.type == ShapeType::Sphere || s.type == ShapeType::Capsule) best += s.radius;
    return best + d.dot(x.p);
}

// Overlap of the projections on d; its minimum over d is the penetration depth.
Real overlap(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, const Vec3& d) {
    return support(a, xa, d) + support(b, xb, -d);
}

// How far a world point lies outside the shape (0 inside or on it; for a hull, the
// largest distance beyond a face plane, which is 0 exactly when the point is inside).
Real outside(const Shape& s, const Transform& x, const Vec3& p) {
    const Vec3 local = x.apply_inverse(p);
    switch (s.type) {
        case ShapeType::Sphere: return std::max(local.norm() - s.radius, Real(0));
        case ShapeType::Capsule: {
            const Vec3 core(0, std::clamp(local.y(), -s.half_height, s.half_height), 0);
            return std::max((local - core).norm() - s.radius, Real(0));
        }
        case ShapeType::Box: return (local.cwiseAbs() - s.half_extents).cwiseMax(0).norm();
        case ShapeType::ConvexHull: {
            Real beyond = 0;
            for (const HullFace& f : s.hull->faces()) beyond = std::max(beyond, f.normal.dot(local) - f.offset);
            return beyond;
        }
        default: return kHuge;
    }
}

Real penetration_depth(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb) {
    // Fibonacci sphere, then shrinking cones around the best direction.
    Vec3 best_d = Vec3::UnitY();
    Real best = kHuge;
    const int n = 1500;
    for (int i = 0; i < n; ++i) {
        const Real y = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - y * y), phi = i * 2.399963229728653;
        const Vec3 d(r * std::cos(phi), y, r * std::sin(phi));
        const Real o = overlap(a, xa, b, xb, d);
        if (o < best) best = o, best_d = d;
    }
    std::mt19937 rng(1);
    std::normal_distribution<Real> g;
    for (Real cone = 0.1; cone > 1e-8; cone *= 0.7) {
        for (int i = 0; i < 40; ++i) {
            const Vec3 d = (best_d + cone * Vec3(g(rng), g(rng), g(rng))).normalized();
            const Real o = overlap(a, xa, b, xb, d);
            if (o < best) best = o, best_d = d;
        }
    }
    return best;
}

std::vector<Shape> convex_shapes() {
    std::mt19937 rng(11);
    std::uniform_real_distribution<Real> u(-0.6, 0.6);
    std::vector<Vec3> cloud;
    for (int i = 0; i < 24; ++i) cloud.emplace_back(u(rng), u(rng) * 1.3, u(rng));
    return {Shape::sphere(0.45), Shape::capsule(0.5, 0.25), Shape::box(Vec3(0.5, 0.3, 0.4)), Shape::convex_hull(cloud)};
}

TEST(ConvexConsistency, SwappedOrderFlipsNormalAndKeepsDepth) {
    const std::vector<Shape> shapes = convex_shapes();
    std::mt19937 rng(5);
    std::uniform_real_distribution<Real> u(-1, 1);
    for (const Shape& a : shapes) {
        for (const Shape& b : shapes) {
            SCOPED_TRACE(std::string(to_string(a.type)) + " vs " + to_string(b.type));
            for (int trial = 0; trial < 100; ++trial) {
                const Transform xa = at(Vec3(u(rng), u(rng), u(rng)) * 0.1,
                                        about(Vec3(u(rng), u(rng), u(rng)), 3 * u(rng)));
                const Transform xb = at(Vec3(u(rng), u(rng), u(rng)) * 0.8,
                                        about(Vec3(u(rng), u(rng), u(rng)), 3 * u(rng)));
                const auto ab = test::run(a, xa, b, xb, 0.05);
                const auto ba = test::run(b, xb, a, xa, 0.05);
                ASSERT_EQ(ab.size(), ba.size());
                if (ab.empty()) continue;
                // Mixed types run the same pair function underneath. Equal types may pick
                // the other shape's face as reference (the choice is biased towards A
                // within 2%), so their depths agree only to that tolerance.
                const Real sa = deepest(ab[0]), sb = deepest(ba[0]);
                EXPECT_NEAR(sa, sb, a.type != b.type ? 1e-9 : 0.021 * std::abs(sa) + 6e-4);
                if (a.type != b.type) {
                    SPINDLE_EXPECT_VEC_NEAR(ab[0].normal, Vec3(-ba[0].normal), 1e-12);
                }
            }
        }
    }
}

TEST(ConvexConsistency, DepthMatchesBruteForcePenetration) {
    const std::vector<Shape> shapes = convex_shapes();
    std::mt19937 rng(9);
    std::uniform_real_distribution<Real> u(-1, 1);
    for (const Shape& a : shapes) {
        for (const Shape& b : shapes) {
            SCOPED_TRACE(std::string(to_string(a.type)) + " vs " + to_string(b.type));
            int checked = 0, exact = 0;
            for (int trial = 0; trial < 40; ++trial) {
                const Transform xa = at(Vec3::Zero(), about(Vec3(u(rng), u(rng), u(rng)), 3 * u(rng)));
                const Transform xb = at(Vec3(u(rng), u(rng), u(rng)) * 0.7,
                                        about(Vec3(u(rng), u(rng), u(rng)), 3 * u(rng)));
                const Real depth = penetration_depth(a, xa, b, xb);
                const auto m = test::run(a, xa, b, xb);
                if (depth <= 1e-6) {
                    EXPECT_TRUE(m.empty()) << "trial " << trial << ": separated by " << -depth;
                    continue;
                }
                ASSERT_EQ(m.size(), 1u) << "trial " << trial << ": depth " << depth;
                ++checked;
                // The normal is a minimum-overlap direction: no sampled direction beats it
                // by more than the biases towards A's face and towards faces over edges
                // (2% + 0.5 mm each; without them every normal here is minimal).
                const Real along_normal = overlap(a, xa, b, xb, m[0].normal);
                EXPECT_LE(along_normal, depth * 1.042 + 1.1e-3) << "trial " << trial << " normal off";
                // No point is deeper than the overlap along the normal; mostly the deepest
                // point has exactly that depth (not when the deepest corner of one shape
                // lies beside the other's reference face: clipping drops it).
                const Real sep = deepest(m[0]);
                EXPECT_GE(sep, -along_normal - 1e-9) << "trial " << trial;
                if (std::abs(sep + along_normal) < 1e-6) ++exact;
                // Between polyhedra, each clipped point's two surface points (a point lies
                // midway between them) lie on their shapes: no point stands for a corner
                // hanging beside the other shape. (A single point may: an edge pair's, or
                // the deepest corner when nothing survives clipping.)
                const bool flat = a.type != ShapeType::Sphere && a.type != ShapeType::Capsule &&
                                  b.type != ShapeType::Sphere && b.type != ShapeType::Capsule;
                for (int k = 0; flat && m[0].point_count > 1 && k < m[0].point_count; ++k) {
                    const ManifoldPoint& p = m[0].points[k];
                    const Vec3 half = Real(0.5) * p.separation * m[0].normal;
                    EXPECT_LT(outside(a, xa, p.point - half), 1e-6) << "trial " << trial << " point " << k << " off A";
                    EXPECT_LT(outside(b, xb, p.point + half), 1e-6) << "trial " << trial << " point " << k << " off B";
                }
            }
            EXPECT_GT(checked, 8);
            EXPECT_GE(exact, checked * 2 / 3) << exact << " of " << checked << " exact";
        }
    }
}

// Shapes that face each other along x with flat or round sides, each with its extent along x.
struct Facing {
    Shape shape;
    Quat q;
    Real extent;
};

std::vector<Facing> facing_shapes() {
    const Quat lying = about(Vec3::UnitX(), kPi / 2);  // capsule axis along z
    return {{Shape::sphere(0.4), Quat::Identity(), 0.4},
            {Shape::capsule(0.5, 0.3), lying, 0.3},
            {Shape::box(Vec3(0.5, 0.4, 0.3)), Quat::Identity(), 0.5},
            {test::hull_box(Vec3(0.6, 0.3, 0.4)), Quat::Identity(), 0.6}};
}

TEST(ConvexPairs, SeparatedTouchingAndPenetratingAlongX) {
    for (const Facing& a : facing_shapes()) {
        for (const Facing& b : facing_shapes()) {
            SCOPED_TRACE(std::string(to_string(a.shape.type)) + " vs " + to_string(b.shape.type));
            const Real contact = a.extent + b.extent;
            const auto pose_b = [&](Real gap) { return at(Vec3(contact + gap, 0, 0), b.q); };
            const Transform xa = at(Vec3::Zero(), a.q);
            // Apart by 0.1: nothing, or a speculative manifold at +0.1 when the margin allows.
            EXPECT_TRUE(test::run(a.shape, xa, b.shape, pose_b(0.1)).empty());
            auto m = test::run(a.shape, xa, b.shape, pose_b(0.1), 0.2);
            ASSERT_EQ(m.size(), 1u);
            SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(1, 0, 0), 1e-9);
            EXPECT_NEAR(deepest(m[0]), 0.1, 1e-9);
            // Touching.
            m = test::run(a.shape, xa, b.shape, pose_b(0), 1e-9);
            ASSERT_EQ(m.size(), 1u);
            EXPECT_NEAR(deepest(m[0]), 0, 1e-9);
            // Resting 0.02 deep: every point at that depth, midway between the surfaces.
            m = test::run(a.shape, xa, b.shape, pose_b(-0.02));
            ASSERT_EQ(m.size(), 1u);
            SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(1, 0, 0), 1e-9);
            for (int i = 0; i < m[0].point_count; ++i) {
                EXPECT_NEAR(m[0].points[i].separation, -0.02, 1e-9);
                EXPECT_NEAR(m[0].points[i].point.x(), a.extent - 0.01, 1e-9);
            }
        }
    }
}

}  // namespace
}  // namespace spindle
