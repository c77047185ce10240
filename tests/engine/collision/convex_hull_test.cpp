// ConvexHull construction: coplanar triangles merge into polygons, interior and
// on-face points vanish, topology is closed, and flat or bad input is rejected.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include <spindle/platform/error.hpp>

#include "collision/convex_hull.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

std::string error_of(const std::vector<Vec3>& points) {
    try {
        ConvexHull hull(points);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

void expect_valid(const ConvexHull& hull) {
    const auto v = hull.vertices();
    const auto f = hull.faces();
    EXPECT_EQ(v.size() - hull.edges().size() + f.size(), 2u) << "Euler characteristic";
    for (const HullFace& face : f) {
        EXPECT_NEAR(face.normal.norm(), 1, 1e-12);
        EXPECT_GE(face.count, 3u);
        for (std::uint32_t k = 0; k < face.count; ++k) {
            EXPECT_NEAR(face.normal.dot(v[hull.face_vertices()[face.first + k]]), face.offset, 1e-9);
        }
        // Every vertex lies on or behind every face.
        for (const Vec3& p : v) EXPECT_LE(face.normal.dot(p) - face.offset, 1e-9);
    }
    for (const HullEdge& e : hull.edges()) {
        // cross(n0, n1) runs along v1 - v0 (the SAT's Gauss-map convention).
        const Vec3 along = f[e.f0].normal.cross(f[e.f1].normal);
        EXPECT_GT(along.dot(v[e.v1] - v[e.v0]), 0);
    }
}

TEST(ConvexHull, CubeMergesIntoSixQuads) {
    std::vector<Vec3> points = test::box_corners(Vec3(1, 2, 3));
    points.emplace_back(0, 0, 0);  // interior
    points.emplace_back(1, 0, 0);  // middle of a face
    points.emplace_back(1, 2, 0);  // middle of an edge
    const ConvexHull hull(points);
    EXPECT_EQ(hull.vertices().size(), 8u);
    EXPECT_EQ(hull.faces().size(), 6u);
    EXPECT_EQ(hull.edges().size(), 12u);
    for (const HullFace& f : hull.faces()) EXPECT_EQ(f.count, 4u);
    EXPECT_NEAR(hull.volume(), 48, 1e-12);
    expect_valid(hull);
}

TEST(ConvexHull, RandomSphereCloudIsClosedAndConvex) {
    std::mt19937 rng(7);
    std::normal_distribution<Real> g;
    std::vector<Vec3> points;
    for (int i = 0; i < 200; ++i) {
        Vec3 p(g(rng), g(rng), g(rng));
        points.push_back(p.normalized() * (i % 3 == 0 ? 0.5 : 1.0));
    }
    const ConvexHull hull(points);
    expect_valid(hull);
    EXPECT_GT(hull.volume(), 3.5);
    EXPECT_LT(hull.volume(), 4.0 / 3.0 * kPi);
}

TEST(ConvexHull, CylinderCapsBecomePolygons) {
    std::vector<Vec3> points;
    for (int i = 0; i < 16; ++i) {
        const Real a = 2 * kPi * i / 16;
        points.emplace_back(std::cos(a), -1, std::sin(a));
        points.emplace_back(std::cos(a), 1, std::sin(a));
    }
    const ConvexHull hull(points);
    expect_valid(hull);
    EXPECT_EQ(hull.faces().size(), 18u);  // 16 sides + 2 caps
    std::set<std::uint32_t> counts;
    for (const HullFace& f : hull.faces()) counts.insert(f.count);
    EXPECT_TRUE(counts.count(16));
}

TEST(ConvexHull, SupportIsTheFarthestVertex) {
    const ConvexHull hull(test::box_corners(Vec3(1, 2, 3)));
    SPINDLE_EXPECT_VEC_NEAR(hull.support(Vec3(1, -1, 1)), Vec3(1, -2, 3), 1e-15);
}

TEST(ConvexHull, RejectsTooFewNonFiniteAndZeroThicknessSets) {
    EXPECT_EQ(error_of({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}), "convex hull: needs at least 4 points, got 3");
    EXPECT_EQ(error_of(
                  {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, std::numeric_limits<Real>::quiet_NaN(), 1)}),
              "convex hull: point 3 must be finite, got (0, nan, 1)");
    EXPECT_EQ(error_of({Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 1)}),
              "convex hull: zero-thickness hull: all points coincide");
    EXPECT_EQ(error_of({Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3)}),
              "convex hull: zero-thickness hull: the points are collinear");
    const std::string flat = error_of({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0.5, 0.5, 0)});
    EXPECT_EQ(flat.rfind("convex hull: zero-thickness hull: the points are coplanar", 0), 0u) << flat;
    EXPECT_THROW(Shape::convex_hull(std::vector<Vec3>{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0)}),
                 Error);
}

}  // namespace
}  // namespace spindle
