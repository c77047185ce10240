// A polyhedron's SAT data laid out for the lanes sat.cpp works on, and PreparedPolyhedron,
// that data for a polyhedron in its own frame, made once for many tests of it (a hull
// against each triangle a mesh query finds).
#pragma once

#include <cstdint>

#include "collision/clipping.hpp"
#include "collision/lanes.hpp"
#include "collision/polyhedron.hpp"

namespace spindle::detail {

inline constexpr std::size_t kInlineVertices = 64;

// A polyhedron in its own frame (the frame sat.cpp works in, the first polyhedron's),
// with its vertices in lanes, and its edges (alone and in lanes) prepared on first use: most
// tests of a pair that stays apart end on a face before any edge is looked at. A hull's view
// brings them made (PolyView::vertex_lanes, arc_edges, arc_lanes), and they are read from there.
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
    // The same edges four in lanes.
    const ArcLanes* edge_lanes() const {
        if (m_edge_lanes == nullptr) prepare_edges();
        return m_edge_lanes;
    }

private:
    void prepare_edges() const;

    PolyView m_view;
    ScratchBuffer<VertexLanes, kInlineVertices / 4> m_lane_buffer;  // used when the view brings none
    const VertexLanes* m_lanes;
    mutable ScratchBuffer<ArcEdge, 2 * kInlineVertices> m_edge_buffer;
    mutable const ArcEdge* m_edges;
    mutable ScratchBuffer<ArcLanes, 2 * kInlineVertices / 4> m_edge_lane_buffer;
    mutable const ArcLanes* m_edge_lanes;
};

// How far along d any direction on an edge's Gauss-map arc reaches: the largest L . d over
// the arc, where d's projection on the arc's great circle falls, else at an end (the edge
// query's bound, sat.cpp). The lanes' version does it for four edges, each lane giving the
// bits the single edge's gives.
Real arc_reach(const ArcEdge& e, const Vec3& d);
Lanes arc_reach(const ArcLanes& e, const Vec3& d);

// The edges' arcs of a polyhedron of at most four edges (a triangle) in its own frame, in
// one group of lanes: each lane the bits of the edge's ArcEdge (its origin aside); lanes
// past the last edge hold a unit direction and zero normals.
ArcLanes own_arc_lanes(const PolyView& v);

}  // namespace spindle::detail
