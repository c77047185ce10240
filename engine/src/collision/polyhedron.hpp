// A non-owning view of a convex polyhedron (vertices, face planes and loops, edges with
// their two faces) so one SAT and clipping code serves hulls, boxes and mesh triangles.
// A triangle is a two-faced polyhedron of zero thickness.
#pragma once

#include <array>
#include <cstdint>

#include "collision/convex_hull.hpp"

namespace spindle::detail {

struct PolyView {
    const Vec3* vertices = nullptr;
    const HullFace* faces = nullptr;
    const std::uint32_t* face_vertices = nullptr;
    const HullEdge* edges = nullptr;
    std::uint32_t vertex_count = 0;
    std::uint32_t face_count = 0;
    std::uint32_t edge_count = 0;
    // A ball inside the polyhedron (radius 0 for a triangle): along any direction L the
    // polyhedron reaches at least L . inner_centre + inner_radius, which bounds what any
    // SAT axis can show before its support points are looked at.
    Vec3 inner_centre = Vec3::Zero();
    Real inner_radius = 0;
    // What a hull keeps made for the SAT (ConvexHull::vertex_lanes, arc_edges, arc_lanes);
    // null for a box or a triangle, made per test, whose SAT makes them itself.
    const VertexLanes* vertex_lanes = nullptr;
    const ArcEdge* arc_edges = nullptr;
    const ArcLanes* arc_lanes = nullptr;

    std::uint32_t support_index(const Vec3& d) const {
        std::uint32_t best = 0;
        Real best_dot = vertices[0].dot(d);
        for (std::uint32_t i = 1; i < vertex_count; ++i) {
            const Real x = vertices[i].dot(d);
            if (x > best_dot) best_dot = x, best = i;
        }
        return best;
    }
    const Vec3& face_vertex(const HullFace& f, std::uint32_t k) const { return vertices[face_vertices[f.first + k]]; }
};

PolyView view_of(const ConvexHull& hull);

// Face loops of the box, counter-clockwise seen from outside (see BoxPoly for numbering):
// face f's vertices are kBoxLoops[4 f .. 4 f + 3].
inline constexpr std::uint32_t kBoxLoops[24] = {
    1, 3, 7, 5,  // +x
    0, 4, 6, 2,  // -x
    2, 6, 7, 3,  // +y
    0, 1, 5, 4,  // -y
    4, 5, 7, 6,  // +z
    0, 2, 3, 1,  // -z
};

// A box as a polyhedron: vertex i has coordinate signs (bit0 x, bit1 y, bit2 z; set =
// positive); face 2k is +axis k, face 2k+1 is -axis k.
class BoxPoly {
public:
    explicit BoxPoly(const Vec3& half_extents);
    PolyView view() const;

private:
    std::array<Vec3, 8> m_vertices;
    std::array<HullFace, 6> m_faces;
};

// A triangle as a polyhedron: face 0 is the front (counter-clockwise) side, face 1 the back.
// Its face loops, and its edges i -> i+1, running counter-clockwise on the front face.
inline constexpr std::uint32_t kTriangleLoops[6] = {0, 1, 2, 0, 2, 1};
inline constexpr HullEdge kTriangleEdges[3] = {{0, 1, 0, 1}, {1, 2, 0, 1}, {2, 0, 0, 1}};

// The unit normal of triangle (a, b, c), counter-clockwise seen from its front.
inline Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c) { return (b - a).cross(c - a).normalized(); }

class TrianglePoly {
public:
    TrianglePoly(const Vec3& a, const Vec3& b, const Vec3& c) : TrianglePoly(a, b, c, triangle_normal(a, b, c)) {}
    // With its normal made by triangle_normal(a, b, c) already.
    TrianglePoly(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& normal);
    PolyView view() const;
    const Vec3& normal() const { return m_faces[0].normal; }

private:
    std::array<Vec3, 3> m_vertices;
    std::array<HullFace, 2> m_faces;
};

// The unique edges of a closed polyhedron given its face loops (each edge once, v0 -> v1
// running counter-clockwise in face f0). Writes at most `capacity` edges; returns the count.
std::uint32_t collect_edges(const HullFace* faces, std::uint32_t face_count, const std::uint32_t* face_vertices,
                            HullEdge* out, std::uint32_t capacity);

// True when direction x lies on the Gauss-map arc of an edge: the directions in which
// the edge is the supporting feature. n0, n1: normals of faces f0, f1; e = v1 - v0. Works
// for a triangle's edges too, whose arc is the half circle from front to back normal
// through the edge's outward side.
inline bool on_edge_arc(const Vec3& x, const Vec3& n0, const Vec3& n1, const Vec3& e) {
    return n0.cross(x).dot(e) >= 0 && x.cross(n1).dot(e) >= 0;
}

}  // namespace spindle::detail
