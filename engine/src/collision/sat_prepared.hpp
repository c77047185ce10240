// A polyhedron's SAT data laid out for the lanes sat.cpp works on, and PreparedPolyhedron,
// that data for a polyhedron in its own frame, made once for many tests of it (a hull
// against each triangle a mesh query finds).
#pragma once

#include <cstdint>

#include "collision/clipping.hpp"
#include "collision/lanes.hpp"
#include "collision/polyhedron.hpp"

namespace spindle::detail {

// An edge in the common frame with what the Gauss-map test needs: the edge's arc
// holds direction x when x . t0 >= 0 and x . t1 >= 0 (see on_edge_arc).
struct ArcEdge {
    Vec3 origin;
    Vec3 direction;
    Vec3 n0, n1;  // normals of the two faces
    Vec3 t0, t1;  // direction x n0, n1 x direction
};

// Four of A's edges for the edge query's cheap rejections: the components of each edge's
// direction and two face normals.
struct EdgeLanes {
    Lanes dx, dy, dz, n0x, n0y, n0z, n1x, n1y, n1z;
};

inline constexpr std::size_t kInlineVertices = 64;

// A polyhedron in its own frame (the frame sat.cpp works in, the first polyhedron's),
// with its vertices in lanes, and its edges prepared on first use: most tests of a pair
// that stays apart end on a face before any edge is looked at.
class PreparedPolyhedron {
public:
    explicit PreparedPolyhedron(const PolyView& view);
    PreparedPolyhedron(const PreparedPolyhedron&) = delete;
    PreparedPolyhedron& operator=(const PreparedPolyhedron&) = delete;

    const PolyView& view() const noexcept { return m_view; }
    const VertexLanes* vertex_lanes() const noexcept { return m_vertex_lanes.data(); }
    // The edges with their face normals.
    const ArcEdge* edges() const {
        prepare_edges();
        return m_edges.data();
    }

private:
    void prepare_edges() const;

    PolyView m_view;
    ScratchBuffer<VertexLanes, kInlineVertices / 4> m_vertex_lanes;
    mutable bool m_edges_ready = false;
    mutable ScratchBuffer<ArcEdge, 2 * kInlineVertices> m_edges;
};

}  // namespace spindle::detail
