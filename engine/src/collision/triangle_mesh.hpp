// TriangleMesh: static triangle soup with its own AABB tree (built once, top-down with a
// binned SAH split) and per-edge "active" flags that keep convex shapes from catching on
// the flat interior edges between neighbouring triangles.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <spindle/engine/math.hpp>
#include <spindle/scheduler/function_ref.hpp>

namespace spindle {

struct MeshTriangle {
    std::uint32_t v[3] = {0, 0, 0};  // counter-clockwise seen from the front (normal) side
    // Bit i set: edge v[i] -> v[(i+1)%3] is active (a silhouette or sharp convex edge, where a
    // contact may take the edge's own normal). Flat or concave shared edges are inactive.
    std::uint8_t active_edges = 0x7;
};

// A node of the tree: a leaf holds triangles [first, first+count) of triangles(); an
// internal node (count == 0) has children `first` and `first + 1`.
struct MeshNode {
    Aabb box;
    std::uint32_t first = 0;
    std::uint32_t count = 0;
};

class TriangleMesh {
public:
    // Throws spindle::Error for an index count that is not a multiple of 3, out-of-range
    // indices, non-finite vertices, or a mesh left with no triangle of non-zero area.
    // Zero-area triangles are dropped; triangles() is reordered to follow the tree.
    TriangleMesh(std::span<const Vec3> vertices, std::span<const std::uint32_t> indices);

    std::span<const Vec3> vertices() const noexcept { return m_vertices; }
    std::span<const MeshTriangle> triangles() const noexcept { return m_triangles; }
    std::span<const MeshNode> nodes() const noexcept { return m_nodes; }
    const Aabb& local_bounds() const noexcept { return m_nodes.front().box; }

    // Unit normal of triangle t (counter-clockwise winding).
    Vec3 normal(std::uint32_t t) const;
    // Calls visit(t) for every triangle whose bounds overlap `box` (mesh frame), in tree order.
    void query(const Aabb& box, FunctionRef<void(std::uint32_t)> visit) const;

private:
    void build_tree();
    void mark_active_edges();

    std::vector<Vec3> m_vertices;
    std::vector<MeshTriangle> m_triangles;
    std::vector<MeshNode> m_nodes;
};

}  // namespace spindle
