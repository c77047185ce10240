// MeshGrid: a flat mesh's grid finds the triangles its tree finds, in the tree's order,
// each once, for boxes small and large, inside and outside the mesh; meshes that stack
// triangles, or are small, keep to the tree.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "collision/triangle_mesh.hpp"

namespace spindle {
namespace {

// `layers` copies of an nx x nz grid of cells (two triangles each), `rise` apart in y, on a
// wave of the given amplitude.
TriangleMesh terrain(int nx, int nz, Real cell, Real amplitude, int layers = 1, Real rise = 0) {
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    for (int layer = 0; layer < layers; ++layer) {
        const auto base = static_cast<std::uint32_t>(v.size());
        for (int z = 0; z <= nz; ++z) {
            for (int x = 0; x <= nx; ++x) {
                const Real px = x * cell - 7, pz = z * cell + 3;
                v.emplace_back(px, layer * rise + amplitude * std::sin(0.4 * px) * std::cos(0.3 * pz), pz);
            }
        }
        const auto at = [&](int x, int z) { return base + static_cast<std::uint32_t>(z * (nx + 1) + x); };
        for (int z = 0; z < nz; ++z) {
            for (int x = 0; x < nx; ++x) {
                idx.insert(idx.end(), {at(x, z), at(x, z + 1), at(x + 1, z + 1)});
                idx.insert(idx.end(), {at(x, z), at(x + 1, z + 1), at(x + 1, z)});
            }
        }
    }
    return TriangleMesh(v, idx);
}

std::vector<std::uint32_t> found_by(const TriangleMesh& mesh, const Aabb& box, bool tree) {
    std::vector<std::uint32_t> found;
    const auto visit = [&](std::uint32_t t) { found.push_back(t); };
    if (tree) {
        mesh.query_tree(box, visit);
    } else {
        mesh.query(box, visit);
    }
    return found;
}

TEST(MeshGrid, FindsWhatTheTreeFindsInItsOrder) {
    const TriangleMesh mesh = terrain(40, 30, 1.5, 1.2);
    ASSERT_TRUE(mesh.has_grid());
    std::mt19937 rng(5);
    std::uniform_real_distribution<Real> x(-12, 60), y(-2, 3), z(-2, 52), size(0.01, 2.5);
    std::size_t total = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        // Mostly small boxes (a body's part); every tenth one spans much of the mesh.
        const Real scale = trial % 10 == 0 ? 12 : 1;
        const Aabb box = Aabb::from_center_extents(Vec3(x(rng), y(rng), z(rng)),
                                                   Vec3(size(rng), size(rng) * 0.5, size(rng)) * scale);
        const std::vector<std::uint32_t> grid = found_by(mesh, box, false);
        EXPECT_EQ(grid, found_by(mesh, box, true)) << "trial " << trial;
        total += grid.size();
    }
    EXPECT_GT(total, 10000u);  // the boxes do meet the mesh
}

TEST(MeshGrid, BoxesOnCellBordersFindEachTriangleOnce) {
    const TriangleMesh mesh = terrain(20, 20, 1.0, 0);
    ASSERT_TRUE(mesh.has_grid());
    for (int i = 0; i < 20; ++i) {
        for (int j = 0; j < 20; ++j) {
            // Corners exactly on vertices: triangles touching the box only at its edge count.
            const Vec3 lo(i - 7.0, -0.1, j + 3.0);
            const Aabb box{lo, lo + Vec3(1, 0.2, 2)};
            EXPECT_EQ(found_by(mesh, box, false), found_by(mesh, box, true)) << i << ", " << j;
        }
    }
}

TEST(MeshGrid, StackedOrSmallMeshesKeepToTheTree) {
    EXPECT_FALSE(terrain(20, 20, 1.0, 0.3, 30, 0.5).has_grid());  // 30 triangles deep in every bucket
    EXPECT_FALSE(terrain(8, 8, 1.0, 0.3).has_grid());             // 128 triangles
    EXPECT_TRUE(terrain(12, 12, 1.0, 0.3).has_grid());            // 288
}

}  // namespace
}  // namespace spindle
