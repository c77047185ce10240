// TriangleMesh: static triangle soup with its own AABB tree (built once, top-down with a
// binned SAH split) and per-edge "active" flags that keep convex shapes from catching on
// the flat interior edges between neighbouring triangles.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <spindle/engine/math.hpp>
#include <spindle/scheduler/function_ref.hpp>

#include "collision/mesh_grid.hpp"

namespace spindle {

struct MeshTriangle {
    std::uint32_t v[3] = {0, 0, 0};  // counter-clockwise seen from the front (normal) side
    // Bit i set: edge v[i] -> v[(i+1)%3] is active (a silhouette or sharp convex edge, where a
    // contact may take the edge's own normal). Flat or concave shared edges are inactive.
    std::uint8_t active_edges = 0x7;
};

// Triangle t's bounds: what the tree and the grid test a query box against.
inline Aabb triangle_bounds(std::span<const Vec3> vertices, const MeshTriangle& t) {
    Aabb box;
    for (const std::uint32_t i : t.v) box.include(vertices[i]);
    return box;
}

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

    // Unit normal of triangle t (counter-clockwise winding): triangle_normal of its corners,
    // made once (every collide against the mesh meets it again).
    const Vec3& normal(std::uint32_t t) const { return m_normals[t]; }
    // Triangle t's bounds, triangle_bounds of its corners, made once: what every query tests.
    const Aabb& bounds(std::uint32_t t) const { return m_bounds[t]; }
    // Calls visit(t) for every triangle whose bounds overlap `box` (mesh frame), in tree
    // order (increasing t); through the grid when the mesh is flat enough to have one.
    void query(const Aabb& box, FunctionRef<void(std::uint32_t)> visit) const;
    bool has_grid() const noexcept { return m_grid.has_value(); }
    // The same, through the tree alone.
    void query_tree(const Aabb& box, FunctionRef<void(std::uint32_t)> visit) const;

private:
    void build_tree();
    void mark_active_edges();
    Vec3 made_normal(std::uint32_t t) const;

    std::vector<Vec3> m_vertices;
    std::vector<MeshTriangle> m_triangles;
    std::vector<Vec3> m_normals;  // per triangle, in triangles()' order
    std::vector<Aabb> m_bounds;   // the same
    std::vector<MeshNode> m_nodes;
    std::optional<MeshGrid> m_grid;
};

}  // namespace spindle
