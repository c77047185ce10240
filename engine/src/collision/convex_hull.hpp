// ConvexHull: the convex polyhedron of a point set (quickhull, coplanar triangles merged
// into polygons), with the topology the narrowphase's SAT and clipping walk.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <spindle/engine/math.hpp>

#include "collision/lanes.hpp"

namespace spindle {

// A face: the plane normal . x = offset (normal unit, pointing out) and a loop of vertex
// indices, counter-clockwise seen from outside, stored at face_vertices()[first, first+count).
struct HullFace {
    Vec3 normal = Vec3::UnitY();
    Real offset = 0;
    std::uint32_t first = 0;
    std::uint32_t count = 0;
};

// An edge v0 -> v1. It runs counter-clockwise in face f0's loop and the other way in f1's,
// so cross(normal(f0), normal(f1)) points along v1 - v0 (the Gauss-map arc's axis).
struct HullEdge {
    std::uint32_t v0 = 0;
    std::uint32_t v1 = 0;
    std::uint32_t f0 = 0;
    std::uint32_t f1 = 0;
};

class ConvexHull {
public:
    // Builds the hull of the points. Throws spindle::Error for fewer than 4 points,
    // non-finite points, and sets that span no volume ("zero-thickness hull": all points
    // coincident, collinear or coplanar). Interior points are dropped.
    explicit ConvexHull(std::span<const Vec3> points);

    std::span<const Vec3> vertices() const noexcept { return m_vertices; }
    std::span<const HullFace> faces() const noexcept { return m_faces; }
    std::span<const std::uint32_t> face_vertices() const noexcept { return m_face_vertices; }
    std::span<const HullEdge> edges() const noexcept { return m_edges; }
    // Made once with the hull, for the SAT, which would otherwise make them for every pair
    // the hull is in: the vertices in lanes, and each edge of edges() with its Gauss-map arc
    // in the hull's own frame, alone and four in lanes.
    std::span<const detail::VertexLanes> vertex_lanes() const noexcept { return m_vertex_lanes; }
    std::span<const detail::ArcEdge> arc_edges() const noexcept { return m_arc_edges; }
    std::span<const detail::ArcLanes> arc_lanes() const noexcept { return m_arc_lanes; }

    // Centre of the volume (uniform density) and the volume itself.
    const Vec3& centroid() const noexcept { return m_centroid; }
    Real volume() const noexcept { return m_volume; }
    // Distance from the centroid to the nearest face plane: the ball of this radius about
    // the centroid lies inside the hull (the SAT bounds its separations with it).
    Real inner_radius() const noexcept { return m_inner_radius; }
    // Second moment of volume about the centroid, integral of (x - c)(x - c)^T dV; the
    // inertia tensor for density rho is rho * (trace(C) I - C).
    const Mat3& covariance() const noexcept { return m_covariance; }
    const Aabb& local_bounds() const noexcept { return m_bounds; }
    // Exact world bounds under x: the vertices moved into the world, four at a time, each
    // coordinate rounded as x.p + r * v rounds it: the values of a loop over vertices() (a
    // zero's sign aside, where equal minima may be taken in another order).
    Aabb bounds(const Transform& x) const;
    // The same with x's rotation as a matrix, for callers that bound many hulls under one x.
    Aabb bounds(const Mat3& r, const Vec3& p) const;

    // The vertex index farthest along direction d (any length).
    std::uint32_t support_index(const Vec3& d) const noexcept;
    Vec3 support(const Vec3& d) const noexcept { return m_vertices[support_index(d)]; }

private:
    void compute_volume_properties();

    std::vector<Vec3> m_vertices;
    std::vector<HullFace> m_faces;
    std::vector<std::uint32_t> m_face_vertices;
    std::vector<HullEdge> m_edges;
    std::vector<detail::VertexLanes> m_vertex_lanes;
    std::vector<detail::ArcEdge> m_arc_edges;
    std::vector<detail::ArcLanes> m_arc_lanes;
    Vec3 m_centroid = Vec3::Zero();
    Real m_volume = 0;
    Real m_inner_radius = 0;
    Mat3 m_covariance = Mat3::Zero();
    Aabb m_bounds;
};

}  // namespace spindle
