// Polyhedron-polyhedron contact (hull-hull, box-hull, box/hull-triangle): SAT over the
// face normals of both and the edge pairs whose Gauss-map arcs cross (the only edge
// pairs that can realise the minimum), then clipping of the incident face or one point
// between the two edges. All work happens in A's frame.
#include <cmath>

#include "collision/clipping.hpp"
#include "collision/convex_hull.hpp"
#include "collision/pair_functions.hpp"

namespace spindle::detail {
namespace {

constexpr std::size_t kInlineVertices = 64;

// A polyhedron placed in the common frame: its vertices already there, its normals
// rotated by r and its plane offsets shifted by t on demand.
struct Posed {
    const PolyView& view;
    const Vec3* vertices;  // in the common frame
    Mat3 r;
    Vec3 t;

    Vec3 normal(std::uint32_t f) const { return r * view.faces[f].normal; }
    Real offset(std::uint32_t f, const Vec3& n) const { return view.faces[f].offset + n.dot(t); }
    std::uint32_t support(const Vec3& d) const {
        std::uint32_t best = 0;
        Real best_dot = vertices[0].dot(d);
        for (std::uint32_t i = 1; i < view.vertex_count; ++i) {
            const Real x = vertices[i].dot(d);
            if (x > best_dot) best_dot = x, best = i;
        }
        return best;
    }
};

struct FaceQuery {
    Real separation = -kHuge;
    std::uint32_t face = 0;
};

struct EdgeQuery {
    Real separation = -kHuge;
    std::uint32_t edge_a = 0;
    std::uint32_t edge_b = 0;
    Vec3 axis = Vec3::UnitY();
    bool found = false;
};

// Largest separation of `other` from the face planes of p. Stops early past `limit`.
FaceQuery query_faces(const Posed& p, const Posed& other, Real limit) {
    FaceQuery best;
    for (std::uint32_t f = 0; f < p.view.face_count; ++f) {
        const Vec3 n = p.normal(f);
        const Real s = n.dot(other.vertices[other.support(-n)]) - p.offset(f, n);
        if (s > best.separation) best = {s, f};
        if (s > limit) break;
    }
    return best;
}

// An edge in the common frame with what the Gauss-map test needs: the edge's arc
// holds direction x when x . t0 >= 0 and x . t1 >= 0 (see on_edge_arc).
struct ArcEdge {
    Vec3 origin;
    Vec3 direction;
    Vec3 n0, n1;  // normals of the two faces
    Vec3 t0, t1;  // direction x n0, n1 x direction
};

void prepare_edges(const Posed& p, ArcEdge* out) {
    for (std::uint32_t j = 0; j < p.view.edge_count; ++j) {
        const HullEdge& e = p.view.edges[j];
        ArcEdge& a = out[j];
        a.origin = p.vertices[e.v0];
        a.direction = p.vertices[e.v1] - a.origin;
        a.n0 = p.normal(e.f0);
        a.n1 = p.normal(e.f1);
        a.t0 = a.direction.cross(a.n0);
        a.t1 = a.n1.cross(a.direction);
    }
}

// Edge pairs that form a face of the Minkowski difference: A's edge arc and B's
// negated edge arc cross on the Gauss map, at the direction L = +-(ea x eb).
EdgeQuery query_edges(const Posed& a, const Posed& b, Real limit) {
    ScratchBuffer<ArcEdge, 2 * kInlineVertices> edges_a(a.view.edge_count), edges_b(b.view.edge_count);
    prepare_edges(a, edges_a.data());
    prepare_edges(b, edges_b.data());
    EdgeQuery best;
    for (std::uint32_t jb = 0; jb < b.view.edge_count; ++jb) {
        const ArcEdge& eb = edges_b[jb];
        for (std::uint32_t ja = 0; ja < a.view.edge_count; ++ja) {
            const ArcEdge& ea = edges_a[ja];
            // Cheap rejections first: each arc must cross the other's great circle.
            if (eb.n0.dot(ea.direction) * eb.n1.dot(ea.direction) > 0) continue;
            if (ea.n0.dot(eb.direction) * ea.n1.dot(eb.direction) > 0) continue;
            const Vec3 cross = ea.direction.cross(eb.direction);
            const Real length2 = cross.squaredNorm();
            if (length2 <= Real(1e-12) * ea.direction.squaredNorm() * eb.direction.squaredNorm()) continue;
            // L = +cross or -cross must lie on A's arc while -L lies on B's arc.
            const Real x0 = cross.dot(ea.t0), x1 = cross.dot(ea.t1);
            const Real y0 = cross.dot(eb.t0), y1 = cross.dot(eb.t1);
            Real sign = 0;
            if (x0 >= 0 && x1 >= 0 && y0 <= 0 && y1 <= 0) sign = 1;
            else if (x0 <= 0 && x1 <= 0 && y0 >= 0 && y1 >= 0) sign = -1;
            if (sign == 0) continue;
            const Vec3 unit = cross * (sign / std::sqrt(length2));
            const Real s = unit.dot(eb.origin - ea.origin);
            if (s > best.separation) best = {s, ja, jb, unit, true};
            if (s > limit) return best;
        }
    }
    return best;
}

// Clips the incident face of `inc` against reference face `face` of `ref`. A vertex that
// clipping drops lies beside the reference face, outside `ref`, and is not kept, unless
// no point survives at all.
int face_contact(const Posed& ref, std::uint32_t face, const Posed& inc, bool reference_is_b, Real speculative, Vec3& n,
                 ContactCandidate* out) {
    n = ref.normal(face);
    const Real d = ref.offset(face, n);
    std::uint32_t incident = 0;
    Real most_against = kHuge;
    for (std::uint32_t f = 0; f < inc.view.face_count; ++f) {
        const Real x = inc.normal(f).dot(n);
        if (x < most_against) most_against = x, incident = f;
    }
    const HullFace& ref_face = ref.view.faces[face];
    const HullFace& inc_face = inc.view.faces[incident];
    const std::size_t capacity = inc_face.count + ref_face.count + 1;
    ScratchBuffer<ClipVertex, 2 * kInlineVertices> buffer(2 * capacity);
    ClipVertex* in = buffer.data();
    ClipVertex* next = buffer.data() + capacity;
    int count = static_cast<int>(inc_face.count);
    for (std::uint32_t k = 0; k < inc_face.count; ++k) {
        in[k] = {inc.vertices[inc.view.face_vertices[inc_face.first + k]], clip_key(0, k, 0),
                 static_cast<std::uint16_t>(k)};
    }
    for (std::uint32_t k = 0; k < ref_face.count && count > 0; ++k) {
        const Vec3& v0 = ref.vertices[ref.view.face_vertices[ref_face.first + k]];
        const Vec3& v1 = ref.vertices[ref.view.face_vertices[ref_face.first + (k + 1) % ref_face.count]];
        const Vec3 side = (v1 - v0).cross(n).normalized();
        count = clip_polygon(in, count, {side, side.dot(v0)}, k, next);
        std::swap(in, next);
    }
    int n_out = 0;
    for (int k = 0; k < count; ++k) {
        const Real s = n.dot(in[k].p) - d;
        if (s > speculative) continue;
        out[n_out++] = {in[k].p - n * (Real(0.5) * s), s, face_contact_id(reference_is_b, face, incident, in[k].key)};
    }
    if (n_out > 0) return n_out;
    // Nothing over the reference face is within reach, yet the face axis says the shapes
    // touch (it won over an edge pair by the bias towards faces): the incident vertex
    // deepest along the normal stands for the contact, so the pair is never left without one.
    const std::uint32_t v = inc.support(-n);
    const Real s = n.dot(inc.vertices[v]) - d;
    if (s > speculative) return 0;
    out[0] = {inc.vertices[v] - n * (Real(0.5) * s), s,
              face_contact_id(reference_is_b, face, incident, clip_key(3, v, v >> 6))};
    return 1;
}

}  // namespace

bool collide_polyhedra(const PolyView& a, const Transform& xa, const PolyView& b, const Transform& xb, Real speculative,
                       Manifold& m) {
    const Mat3 r = (xa.q.conjugate() * xb.q).toRotationMatrix();
    const Vec3 t = xa.apply_inverse(xb.p);
    ScratchBuffer<Vec3, kInlineVertices> b_vertices(b.vertex_count);
    for (std::uint32_t i = 0; i < b.vertex_count; ++i) b_vertices[i] = r * b.vertices[i] + t;
    const Posed pa{a, a.vertices, Mat3::Identity(), Vec3::Zero()};
    const Posed pb{b, b_vertices.data(), r, t};

    const FaceQuery face_a = query_faces(pa, pb, speculative);
    if (face_a.separation > speculative) return false;
    const FaceQuery face_b = query_faces(pb, pa, speculative);
    if (face_b.separation > speculative) return false;
    const EdgeQuery edge = query_edges(pa, pb, speculative);
    if (edge.separation > speculative) return false;

    if (edge.found && clearly_greater(edge.separation, std::max(face_a.separation, face_b.separation))) {
        const HullEdge& ea = a.edges[edge.edge_a];
        const HullEdge& eb = b.edges[edge.edge_b];
        const Vec3& a0 = a.vertices[ea.v0];
        const Vec3& b0 = b_vertices[eb.v0];
        const Vec3 da = a.vertices[ea.v1] - a0, db = b_vertices[eb.v1] - b0;
        Real s = 0, u = 0;
        closest_segment_parameters(a0, da, b0, db, s, u);
        const Vec3 on_a = a0 + s * da, on_b = b0 + u * db;
        m.normal = edge.axis;
        m.points[0] = {Real(0.5) * (on_a + on_b), edge.axis.dot(on_b - on_a),
                       edge_contact_id(edge.edge_a, edge.edge_b)};
        m.point_count = 1;
        manifold_to_world(m, xa);
        return true;
    }

    const bool reference_is_b = clearly_greater(face_b.separation, face_a.separation);
    // Clipping leaves at most (incident face + reference face) vertices.
    ScratchBuffer<ContactCandidate, kInlineVertices> candidates(a.vertex_count + b.vertex_count);
    Vec3 n;
    const int count = reference_is_b ? face_contact(pb, face_b.face, pa, true, speculative, n, candidates.data())
                                     : face_contact(pa, face_a.face, pb, false, speculative, n, candidates.data());
    if (count == 0) return false;
    m.normal = reference_is_b ? Vec3(-n) : n;
    reduce_to_manifold(candidates.data(), count, m);
    manifold_to_world(m, xa);
    return true;
}

int collide_box_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                     Manifold* out, int) {
    const BoxPoly box(a.half_extents);
    return collide_polyhedra(box.view(), xa, view_of(*b.hull), xb, speculative, out[0]) ? 1 : 0;
}

int collide_hull_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                      Manifold* out, int) {
    return collide_polyhedra(view_of(*a.hull), xa, view_of(*b.hull), xb, speculative, out[0]) ? 1 : 0;
}

}  // namespace spindle::detail
