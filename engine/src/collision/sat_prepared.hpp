// A polyhedron's SAT data laid out for the lanes sat.cpp works on, and PreparedPolyhedron,
// that data for a polyhedron in its own frame, made once for many tests of it (a hull
// against each triangle a mesh query finds).
#pragma once

#include <cstdint>

#include "collision/clipping.hpp"
#include "collision/lanes.hpp"
#include "collision/polyhedron.hpp"

namespace spindle::detail {

// Four of A's edges for the edge query's cheap rejections: the components of each edge's
// direction and two face normals.
struct EdgeLanes {
    Lanes dx, dy, dz, n0x, n0y, n0z, n1x, n1y, n1z;
};

inline constexpr std::size_t kInlineVertices = 64;

// A polyhedron in its own frame (the frame sat.cpp works in, the first polyhedron's),
// with its vertices in lanes, and its edges prepared on first use: most tests of a pair
// that stays apart end on a face before any edge is looked at. A hull's view brings both
// made (PolyView::vertex_lanes, arc_edges), and they are read from there.
class PreparedPolyhedron {
public:
    explicit PreparedPolyhedron(const PolyView& view);
    PreparedPolyhedron(const PreparedPolyhedron&) = delete;
    PreparedPolyhedron& operator=(const PreparedPolyhedron&) = delete;

    const PolyView& view() const noexcept { return m_view; }
    const VertexLanes* vertex_lanes() const noexcept { return m_lanes; }
    // The edges with their face normals.
    const ArcEdge* edges() const {
        if (m_edges == nullptr) prepare_edges();
        return m_edges;
    }

private:
    void prepare_edges() const;

    PolyView m_view;
    ScratchBuffer<VertexLanes, kInlineVertices / 4> m_lane_buffer;  // used when the view brings none
    const VertexLanes* m_lanes;
    mutable ScratchBuffer<ArcEdge, 2 * kInlineVertices> m_edge_buffer;
    mutable const ArcEdge* m_edges;
};

}  // namespace spindle::detail
