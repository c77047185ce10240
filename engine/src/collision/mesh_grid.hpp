// MeshGrid: a uniform grid of buckets over a flat mesh's footprint (a terrain, a
// heightfield), each bucket listing the triangles whose bounds reach into it. A box finds
// its triangles by index arithmetic on the grid instead of descending the mesh's tree,
// which a small box near the ground walks some thirty nodes deep to reach a few triangles.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <spindle/engine/math.hpp>
#include <spindle/scheduler/function_ref.hpp>

namespace spindle {

struct MeshTriangle;

class MeshGrid {
public:
    // A grid for the triangles (indexed into vertices) when the mesh is flat enough for
    // one to pay: few triangles per bucket over the two widest axes of `bounds`, the
    // mesh's own. Otherwise none.
    static std::optional<MeshGrid> build(std::span<const Vec3> vertices, std::span<const MeshTriangle> triangles,
                                         const Aabb& bounds);

    // Calls visit(t) for every triangle whose bounds overlap `box`, in increasing t (the
    // order of the mesh's tree), and returns true; or calls nothing and returns false when
    // the box reaches more triangles than the grid gathers at once (the tree serves it).
    // `bounds`: each triangle's, triangle_bounds as the mesh keeps them.
    bool query(const Aabb& box, std::span<const Aabb> bounds, FunctionRef<void(std::uint32_t)> visit) const;

private:
    MeshGrid() = default;

    struct Range {
        int lo, hi;  // buckets lo..hi along one axis
    };
    Real in_cells(Real x, int axis) const;
    int clamped(Real c, int axis) const;
    Range triangle_cells(Real lo, Real hi, int axis) const;
    Range query_cells(Real lo, Real hi, int axis) const;

    int m_axis[2] = {0, 2};  // the grid's two axes, the mesh's widest
    Vec3 m_origin = Vec3::Zero();
    Real m_inverse_cell = 1;
    int m_count[2] = {1, 1};
    // Bucket (i, j) lists m_entries[m_first[b]..m_first[b + 1]), b = j * m_count[0] + i,
    // triangles in increasing order, each with flags saying whether the bucket is its first
    // along either axis.
    std::vector<std::uint32_t> m_first;
    std::vector<std::uint32_t> m_entries;
};

}  // namespace spindle
