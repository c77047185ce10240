// Helpers for the collision tests: poses, a collide() wrapper that returns the
// manifolds, and checks that every manifold is well formed.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "collision/collide.hpp"
#include "collision/convex_hull.hpp"
#include "collision/triangle_mesh.hpp"

namespace spindle::test {

inline Transform at(const Vec3& p, const Quat& q = Quat::Identity()) { return {p, q}; }
inline Quat about(const Vec3& axis, Real angle) { return Quat(Eigen::AngleAxis<Real>(angle, axis.normalized())); }

// A turn drawn uniformly over all turns.
inline Quat random_turn(std::mt19937& random) {
    std::normal_distribution<Real> normal(0, 1);
    return Quat(normal(random), normal(random), normal(random), normal(random)).normalized();
}

inline std::vector<Manifold> run(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                                 Real speculative = 0, int capacity = 8) {
    std::vector<Manifold> out(static_cast<std::size_t>(capacity));
    const int n = collide(a, xa, b, xb, speculative, out.data(), capacity);
    out.resize(static_cast<std::size_t>(n));
    for (const Manifold& m : out) {
        EXPECT_TRUE(m.normal.allFinite());
        EXPECT_NEAR(m.normal.norm(), 1.0, 1e-9);
        EXPECT_GE(m.point_count, 1);
        EXPECT_LE(m.point_count, kMaxManifoldPoints);
        for (int i = 0; i < m.point_count; ++i) {
            EXPECT_TRUE(m.points[i].point.allFinite());
            EXPECT_TRUE(std::isfinite(m.points[i].separation));
            EXPECT_LE(m.points[i].separation, speculative + 1e-9);
        }
    }
    return out;
}

// Whether the manifold has a point within tol of p.
inline bool has_point(const Manifold& m, const Vec3& p, Real tol = 1e-6) {
    for (int i = 0; i < m.point_count; ++i) {
        if ((m.points[i].point - p).norm() <= tol) return true;
    }
    return false;
}

inline std::vector<Vec3> box_corners(const Vec3& h) {
    std::vector<Vec3> p;
    for (int i = 0; i < 8; ++i) p.emplace_back(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z());
    return p;
}

inline Shape hull_box(const Vec3& h) {
    const std::vector<Vec3> p = box_corners(h);
    return Shape::convex_hull(p);
}

// A 0.5 cube resting 0.01 deep on a floor (half extents (2, 0.5, 2)) at (0.3, 0.99, -0.2):
// four points at its corners, midway down the overlap.
void expect_resting_cube_contact(const Shape& floor, const Shape& cube);

// Two unit cubes rolled 45 degrees about z and x, edges crossed 0.1 deep: one edge point.
void expect_crossed_edges_contact(const Shape& cube);

// collide(b, a) gives the same points as collide(a, b) with the normal turned round.
void expect_swapped_order_flips(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb);

}  // namespace spindle::test

#define SPINDLE_EXPECT_VEC_NEAR(actual, expected, tol) \
    EXPECT_LT(((actual) - (expected)).norm(), tol)     \
        << "actual " << (actual).transpose() << " expected " << (expected).transpose()
