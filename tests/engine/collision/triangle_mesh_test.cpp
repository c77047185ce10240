// TriangleMesh: validation, zero-area triangles dropped, the AABB tree finds exactly the
// overlapping triangles, and flat seams are marked inactive while sharp ridges stay active.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <spindle/platform/error.hpp>

#include "collision/polyhedron.hpp"
#include "collision/triangle_mesh.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

std::string error_of(const std::vector<Vec3>& v, const std::vector<std::uint32_t>& i) {
    try {
        TriangleMesh mesh(v, i);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

// An n x n grid of quads (two triangles each) in the y = 0 plane, facing +y.
TriangleMesh grid(int n, Real cell, Real (*height)(Real, Real) = nullptr) {
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    for (int z = 0; z <= n; ++z) {
        for (int x = 0; x <= n; ++x) {
            const Real px = x * cell, pz = z * cell;
            v.emplace_back(px, height ? height(px, pz) : 0, pz);
        }
    }
    const auto at = [n](int x, int z) { return static_cast<std::uint32_t>(z * (n + 1) + x); };
    for (int z = 0; z < n; ++z) {
        for (int x = 0; x < n; ++x) {
            idx.insert(idx.end(), {at(x, z), at(x, z + 1), at(x + 1, z + 1)});
            idx.insert(idx.end(), {at(x, z), at(x + 1, z + 1), at(x + 1, z)});
        }
    }
    return TriangleMesh(v, idx);
}

TEST(TriangleMesh, ZeroAreaTriangleIsDropped) {
    const std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(2, 0, 0)};
    const TriangleMesh mesh(v, std::vector<std::uint32_t>{0, 2, 1, 0, 1, 3, 1, 1, 2});
    EXPECT_EQ(mesh.triangles().size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(mesh.normal(0), Vec3(0, 1, 0), 1e-12);
}

TEST(TriangleMesh, RejectsBadIndicesAndVertices) {
    const std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    EXPECT_EQ(error_of(v, {0, 1}), "triangle mesh: index count must be a multiple of 3, got 2");
    EXPECT_EQ(error_of(v, {0, 1, 3}), "triangle mesh: index 2 (triangle 0) must be below the vertex count 3, got 3");
    EXPECT_EQ(error_of({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, std::numeric_limits<Real>::infinity())}, {0, 1, 2}),
              "triangle mesh: vertex 2 must be finite, got (0, 0, inf)");
    EXPECT_EQ(error_of(v, {0, 0, 1}), "triangle mesh: has no triangle of non-zero area");
}

TEST(TriangleMesh, QueryFindsExactlyTheOverlappingTriangles) {
    const TriangleMesh mesh = grid(20, 1.0);
    EXPECT_EQ(mesh.triangles().size(), 800u);
    std::mt19937 rng(3);
    std::uniform_real_distribution<Real> u(-2, 22);
    for (int trial = 0; trial < 50; ++trial) {
        const Vec3 c(u(rng), 0, u(rng));
        const Aabb box = Aabb::from_center_extents(c, Vec3(1.3, 0.5, 0.7));
        std::set<std::uint32_t> found;
        mesh.query(box, [&](std::uint32_t t) { EXPECT_TRUE(found.insert(t).second); });
        std::set<std::uint32_t> expected;
        for (std::uint32_t t = 0; t < mesh.triangles().size(); ++t) {
            Aabb tb;
            for (const std::uint32_t i : mesh.triangles()[t].v) tb.include(mesh.vertices()[i]);
            if (tb.overlaps(box)) expected.insert(t);
        }
        EXPECT_EQ(found, expected);
    }
}

// The normals and bounds are made once, after the tree has put the triangles in its order:
// each is its own triangle's, as triangle_normal and triangle_bounds make them from the
// corners, to the bit.
TEST(TriangleMesh, EachNormalAndBoxIsItsTrianglesOwnToTheBit) {
    const TriangleMesh mesh = grid(12, 0.7, [](Real x, Real z) { return 0.4 * std::sin(x) * std::cos(0.6 * z); });
    for (std::uint32_t t = 0; t < mesh.triangles().size(); ++t) {
        const MeshTriangle& tri = mesh.triangles()[t];
        const Vec3 made = detail::triangle_normal(mesh.vertices()[tri.v[0]], mesh.vertices()[tri.v[1]],
                                                  mesh.vertices()[tri.v[2]]);
        const Aabb box = triangle_bounds(mesh.vertices(), tri);
        for (int i = 0; i < 3; ++i) {
            EXPECT_EQ(mesh.normal(t)[i], made[i]) << "triangle " << t;
            EXPECT_EQ(mesh.bounds(t).min[i], box.min[i]) << "triangle " << t;
            EXPECT_EQ(mesh.bounds(t).max[i], box.max[i]) << "triangle " << t;
        }
    }
}

TEST(TriangleMesh, FlatSeamsAreInactiveAndRidgesActive) {
    const TriangleMesh flat = grid(2, 1.0);
    // Interior edges are shared and flat: inactive. Border edges: active.
    int active = 0;
    for (const MeshTriangle& t : flat.triangles()) active += __builtin_popcount(t.active_edges);
    EXPECT_EQ(active, 8);  // the 8 border edges of a 2 x 2 grid

    // A roof: two triangles meeting at a 90 degree convex ridge along x.
    const std::vector<Vec3> v{Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0, 0, -1), Vec3(0, 0, 1)};
    const TriangleMesh roof(v, std::vector<std::uint32_t>{0, 1, 2, 1, 0, 3});
    for (const MeshTriangle& t : roof.triangles()) EXPECT_EQ(t.active_edges, 0x7);
}

}  // namespace
}  // namespace spindle
