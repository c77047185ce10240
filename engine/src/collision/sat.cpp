// Polyhedron-polyhedron contact (hull-hull, box-hull, box/hull-triangle): SAT over the
// face normals of both and the edge pairs whose Gauss-map arcs cross (the only edge
// pairs that can realise the minimum), then clipping of the incident face or one point
// between the two edges. All work happens in A's frame.
#include <algorithm>
#include <cmath>

#include "collision/clipping.hpp"
#include "collision/convex_hull.hpp"
#include "collision/pair_functions.hpp"
#include "collision/sat_prepared.hpp"

namespace spindle::detail {
namespace {

void fill_lanes(const Vec3* vertices, std::uint32_t count, VertexLanes* out) {
    for (std::uint32_t i = 0; i < (count + 3) / 4 * 4; ++i) {
        const Vec3& v = vertices[i < count ? i : 0];
        out[i / 4].x[i % 4] = v.x(), out[i / 4].y[i % 4] = v.y(), out[i / 4].z[i % 4] = v.z();
    }
}

// A polyhedron placed in the common frame: its vertices already there, its normals
// rotated by r and its plane offsets shifted by t on demand; or, when it is `at_home` (the
// frame is its own, A's), its normals and offsets as stored. Turning a normal by the
// identity gives it back (a zero's sign aside), so both read the same planes.
struct Posed {
    const PolyView& view;
    const Vec3* vertices;      // in the common frame
    const VertexLanes* lanes;  // null: a polyhedron of at most four vertices (a triangle), walked one by one
    Mat3 r = Mat3::Identity();
    Vec3 t = Vec3::Zero();
    Vec3 inner_centre = Vec3::Zero();  // view.inner_centre in the common frame
    bool at_home = false;              // the common frame is the view's own: r and t are the identity

    Vec3 normal(std::uint32_t f) const { return at_home ? view.faces[f].normal : Vec3(r * view.faces[f].normal); }
    Real offset(std::uint32_t f, const Vec3& n) const {
        return at_home ? view.faces[f].offset : view.faces[f].offset + n.dot(t);
    }
    // The vertex farthest along d, the first of equals: four vertices a step, each lane
    // keeping its own best and the first index it was found at.
    std::uint32_t support(const Vec3& d) const {
        if (lanes == nullptr) {
            // The same products and sums as one lane's, the first of equals as the lanes pick it.
            const auto along = [&d](const Vec3& v) { return (v.x() * d.x() + v.y() * d.y()) + v.z() * d.z(); };
            std::uint32_t best_index = 0;
            Real best = along(vertices[0]);
            for (std::uint32_t i = 1; i < view.vertex_count; ++i) {
                const Real x = along(vertices[i]);
                if (x > best) best = x, best_index = i;
            }
            return best_index;
        }
        const Lanes dx = Lanes{} + d.x(), dy = Lanes{} + d.y(), dz = Lanes{} + d.z();
        using Indices = std::int64_t __attribute__((vector_size(4 * sizeof(std::int64_t))));
        Lanes best = (lanes[0].x * dx + lanes[0].y * dy) + lanes[0].z * dz;
        Indices best_index{0, 1, 2, 3};
        Indices index = best_index;
        const std::uint32_t groups = (view.vertex_count + 3) / 4;
        for (std::uint32_t g = 1; g < groups; ++g) {
            index += 4;
            const Lanes x = (lanes[g].x * dx + lanes[g].y * dy) + lanes[g].z * dz;
            const LaneMask better = x > best;
            best = better ? x : best;
            best_index = better ? index : best_index;
        }
        int lane = 0;
        for (int k = 1; k < 4; ++k) {
            if (best[k] > best[lane] || (best[k] == best[lane] && best_index[k] < best_index[lane])) lane = k;
        }
        return best_index[lane] < view.vertex_count ? static_cast<std::uint32_t>(best_index[lane]) : 0;
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

// Separation of `other` from face f's plane of p.
[[gnu::always_inline]] inline Real face_separation(const Posed& p, const Posed& other, std::uint32_t f) {
    const Vec3 n = p.normal(f);
    return n.dot(other.vertices[other.support(-n)]) - p.offset(f, n);
}

// Part of a bound on a separation kept in hand against rounding, relative to the sizes
// involved: far more than the arithmetic's error (edge pairs closer to parallel than
// edge_pair_axis admits included), far less than any gap that matters.
constexpr Real kBoundRounding = 1e-7;

// Largest separation of `other` from the face planes of p, the first face of equals.
// Stops at the first face past `limit`, as a walk over the faces in order would. Face f
// shows at most n . c - offset - r, (c, r) being other's inner ball in p's frame: faces
// whose bound is below the separation of the face with the highest bound, and not past
// `limit`, can neither win nor stop the walk, and are not walked.
FaceQuery query_faces(const Posed& p, const Posed& other, Real limit) {
    const Vec3 c = p.r.transpose() * (other.inner_centre - p.t);
    const Real r = other.view.inner_radius;
    const Real scale = c.norm() + r;
    ScratchBuffer<Real, 2 * kInlineVertices> bound(p.view.face_count);
    std::uint32_t first = 0;
    for (std::uint32_t f = 0; f < p.view.face_count; ++f) {
        const HullFace& face = p.view.faces[f];
        const Real slack = kBoundRounding * (std::abs(face.offset) + scale);
        bound[f] = face.normal.dot(c) - face.offset - r + slack;
        if (bound[f] > bound[first]) first = f;
    }
    const Real first_separation = face_separation(p, other, first);
    FaceQuery best;
    for (std::uint32_t f = 0; f < p.view.face_count; ++f) {
        if (f != first && bound[f] < first_separation && bound[f] <= limit) continue;
        const Real s = f == first ? first_separation : face_separation(p, other, f);
        if (s > best.separation) best = {s, f};
        if (s > limit) break;
    }
    return best;
}

// Edge j's arc, its faces' normals n0 (f0's) and n1 (f1's) turned already.
ArcEdge arc_edge(const Posed& p, std::uint32_t j, const Vec3& n0, const Vec3& n1) {
    const HullEdge& e = p.view.edges[j];
    ArcEdge a;
    a.origin = p.vertices[e.v0];
    a.direction = p.vertices[e.v1] - a.origin;
    a.n0 = n0;
    a.n1 = n1;
    a.t0 = a.direction.cross(a.n0);
    a.t1 = a.n1.cross(a.direction);
    return a;
}

ArcEdge arc_edge(const Posed& p, std::uint32_t j) {
    const HullEdge& e = p.view.edges[j];
    return arc_edge(p, j, p.normal(e.f0), p.normal(e.f1));
}

void prepare_edges(const Posed& p, ArcEdge* out) {
    for (std::uint32_t j = 0; j < p.view.edge_count; ++j) out[j] = arc_edge(p, j);
}

// Whether edges ea (of A) and eb (of B) form a face of the Minkowski difference: their
// arcs cross on the Gauss map, A's at the direction L = +-(ea x eb) and B's at -L. If so,
// the unit axis (from A to B) and the separation of the two edges' lines along it.
// crossing_edge_pair_axis: the same for arcs known to cross each other's great circles.
[[gnu::always_inline]] inline bool crossing_edge_pair_axis(const ArcEdge& ea, const ArcEdge& eb, Vec3& unit,
                                                           Real& separation) {
    const Vec3 cross = ea.direction.cross(eb.direction);
    const Real length2 = cross.squaredNorm();
    if (length2 <= Real(1e-12) * ea.direction.squaredNorm() * eb.direction.squaredNorm()) return false;
    // L = +cross or -cross must lie on A's arc while -L lies on B's arc.
    const Real x0 = cross.dot(ea.t0), x1 = cross.dot(ea.t1);
    const Real y0 = cross.dot(eb.t0), y1 = cross.dot(eb.t1);
    Real sign = 0;
    if (x0 >= 0 && x1 >= 0 && y0 <= 0 && y1 <= 0) sign = 1;
    else if (x0 <= 0 && x1 <= 0 && y0 >= 0 && y1 >= 0) sign = -1;
    if (sign == 0) return false;
    unit = cross * (sign / std::sqrt(length2));
    separation = unit.dot(eb.origin - ea.origin);
    return true;
}

[[gnu::always_inline]] inline bool edge_pair_axis(const ArcEdge& ea, const ArcEdge& eb, Vec3& unit, Real& separation) {
    // Cheap rejections first: each arc must cross the other's great circle.
    if (eb.n0.dot(ea.direction) * eb.n1.dot(ea.direction) > 0) return false;
    if (ea.n0.dot(eb.direction) * ea.n1.dot(eb.direction) > 0) return false;
    return crossing_edge_pair_axis(ea, eb, unit, separation);
}

// Edge j with what arc_reach needs, in the polyhedron's own frame (no origin).
ArcEdge own_arc_edge(const PolyView& v, std::uint32_t j) {
    const HullEdge& e = v.edges[j];
    ArcEdge a;
    a.direction = v.vertices[e.v1] - v.vertices[e.v0];
    a.n0 = v.faces[e.f0].normal;
    a.n1 = v.faces[e.f1].normal;
    a.t0 = a.direction.cross(a.n0);
    a.t1 = a.n1.cross(a.direction);
    return a;
}

}  // namespace

Real arc_reach(const ArcEdge& e, const Vec3& d) {
    if (d.dot(e.t0) >= 0 && d.dot(e.t1) >= 0) {
        const Real along = d.dot(e.direction);
        return std::sqrt(std::max(d.squaredNorm() - along * along / e.direction.squaredNorm(), Real(0)));
    }
    return std::max(e.n0.dot(d), e.n1.dot(d));
}

// Eigen's cross product, lane by lane: a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0.
ArcLanes own_arc_lanes(const PolyView& v) {
    ArcLanes l;
    for (std::uint32_t j = 0; j < 4; ++j) {
        if (j >= v.edge_count) {  // past the last edge, as ArcLanes says: a unit direction, zero normals
            l.dy[j] = l.dz[j] = l.n0x[j] = l.n0y[j] = l.n0z[j] = l.n1x[j] = l.n1y[j] = l.n1z[j] = 0;
            l.dx[j] = 1;
            continue;
        }
        const HullEdge& e = v.edges[j];
        const Vec3 direction = v.vertices[e.v1] - v.vertices[e.v0];
        const Vec3& n0 = v.faces[e.f0].normal;
        const Vec3& n1 = v.faces[e.f1].normal;
        l.dx[j] = direction.x(), l.dy[j] = direction.y(), l.dz[j] = direction.z();
        l.n0x[j] = n0.x(), l.n0y[j] = n0.y(), l.n0z[j] = n0.z();
        l.n1x[j] = n1.x(), l.n1y[j] = n1.y(), l.n1z[j] = n1.z();
    }
    l.dd = l.dx * l.dx + (l.dy * l.dy + l.dz * l.dz);
    l.t0x = l.dy * l.n0z - l.dz * l.n0y, l.t0y = l.dz * l.n0x - l.dx * l.n0z, l.t0z = l.dx * l.n0y - l.dy * l.n0x;
    l.t1x = l.n1y * l.dz - l.n1z * l.dy, l.t1y = l.n1z * l.dx - l.n1x * l.dz, l.t1z = l.n1x * l.dy - l.n1y * l.dx;
    return l;
}

Lanes arc_reach(const ArcLanes& e, const Vec3& d) {
    const Lanes x = Lanes{} + d.x(), y = Lanes{} + d.y(), z = Lanes{} + d.z();
    // Each dot product summed as Eigen sums a 3-vector's: a0 b0 + (a1 b1 + a2 b2).
    const auto dot = [&](const Lanes& ax, const Lanes& ay, const Lanes& az) { return x * ax + (y * ay + z * az); };
    const LaneMask on_arc = (dot(e.t0x, e.t0y, e.t0z) >= 0) & (dot(e.t1x, e.t1y, e.t1z) >= 0);
    const Lanes along = dot(e.dx, e.dy, e.dz);
    const Lanes rest = d.squaredNorm() - along * along / e.dd;
    const Lanes across = lane_sqrt(rest < 0 ? Lanes{} : rest);  // std::max(rest, 0)
    const Lanes r0 = dot(e.n0x, e.n0y, e.n0z), r1 = dot(e.n1x, e.n1y, e.n1z);
    const Lanes at_end = r0 < r1 ? r1 : r0;  // std::max(r0, r1)
    return on_arc ? across : at_end;
}

namespace {

// Edge pairs that form a face of the Minkowski difference: A's edge arc and B's
// negated edge arc cross on the Gauss map, at the direction L = +-(ea x eb). Only a pair
// that shows more than `floor` (the deepest face's separation) can change the SAT's
// answer, and along L the pair shows at most L . d - rA - rB (d from A's inner ball's
// centre to B's, rA and rB their radii: each shape reaches past its ball), so an edge
// whose arc never reaches that far along d (B's: along -d) is in no such pair and is
// dropped before the pairs are formed. Of the pairs left, most fail the first two tests
// of edge_pair_axis (an arc that does not cross the other's great circle): those run on
// four of A's edges at once, each lane computing what the scalar test computes in the
// same order; A's bounds do too. The pairs tested keep their order, so the answer is the
// whole query's whenever it beats `floor`; otherwise it is `floor` with no pair found.
EdgeQuery query_edges(const PreparedPolyhedron& prepared_a, const Posed& a, const Posed& b, Real floor, Real limit) {
    const Vec3 d = b.inner_centre - a.inner_centre;
    const Real radii = a.view.inner_radius + b.view.inner_radius;
    const Real needed = floor + radii - kBoundRounding * (d.norm() + radii + std::abs(floor));

    // A's edges kept, four bits a group.
    const ArcEdge* edges_a = prepared_a.edges();
    const ArcLanes* lanes_a = prepared_a.edge_lanes();
    const std::uint32_t groups = (a.view.edge_count + 3) / 4;
    ScratchBuffer<std::uint8_t, kInlineVertices> kept_a(groups);
    unsigned any_a = 0;
    for (std::uint32_t g = 0; g < groups; ++g) {
        unsigned bits = lane_bits(arc_reach(lanes_a[g], d) > needed);
        if (4 * g + 4 > a.view.edge_count) bits &= (1u << (a.view.edge_count - 4 * g)) - 1;  // past the last edge
        kept_a[g] = static_cast<std::uint8_t>(bits);
        any_a |= bits;
    }
    if (any_a == 0) return {floor};
    // B's edges are bounded in B's own frame (-d turned into it): only those kept are turned.
    const Vec3 d_in_b = b.r.transpose() * -d;
    ScratchBuffer<ArcEdge, 2 * kInlineVertices> edges_b(b.view.edge_count);
    ScratchBuffer<std::uint32_t, 2 * kInlineVertices> kept_b(b.view.edge_count);
    std::uint32_t count_b = 0;
    const bool triangle = b.view.arc_edges == nullptr && b.view.edge_count <= 4;
    if (triangle) {
        // A triangle's edges, made and bounded in one group of lanes; each joins its two
        // faces, whose normals are turned once.
        const unsigned bits = lane_bits(arc_reach(own_arc_lanes(b.view), d_in_b) > needed) &
                              ((1u << b.view.edge_count) - 1);
        const Vec3 normals[2] = {b.normal(0), b.normal(1)};
        for (unsigned left = bits; left != 0; left &= left - 1) {
            const auto j = static_cast<std::uint32_t>(__builtin_ctz(left));
            kept_b[count_b] = j;
            const HullEdge& e = b.view.edges[j];
            edges_b[count_b++] = arc_edge(b, j, normals[e.f0], normals[e.f1]);
        }
    } else {
        for (std::uint32_t j = 0; j < b.view.edge_count; ++j) {
            if (arc_reach(b.view.arc_edges ? b.view.arc_edges[j] : own_arc_edge(b.view, j), d_in_b) > needed) {
                kept_b[count_b] = j;
                edges_b[count_b++] = arc_edge(b, j);
            }
        }
    }
    if (count_b == 0) return {floor};

    EdgeQuery best{floor};
    for (std::uint32_t kb = 0; kb < count_b; ++kb) {
        const std::uint32_t jb = kept_b[kb];
        const ArcEdge& eb = edges_b[kb];
        const Lanes bn0x = Lanes{} + eb.n0.x(), bn0y = Lanes{} + eb.n0.y(), bn0z = Lanes{} + eb.n0.z();
        const Lanes bn1x = Lanes{} + eb.n1.x(), bn1y = Lanes{} + eb.n1.y(), bn1z = Lanes{} + eb.n1.z();
        const Lanes bdx = Lanes{} + eb.direction.x(), bdy = Lanes{} + eb.direction.y(),
                    bdz = Lanes{} + eb.direction.z();
        for (std::uint32_t g = 0; g < groups; ++g) {
            if (kept_a[g] == 0) continue;
            const ArcLanes& l = lanes_a[g];
            const Lanes a0 = (l.n0x * bdx + l.n0y * bdy) + l.n0z * bdz;
            const Lanes a1 = (l.n1x * bdx + l.n1y * bdy) + l.n1z * bdz;
            unsigned crossing = lane_bits(a0 * a1 <= 0) & kept_a[g];
            // A triangle's edge joins its two faces, n and -n: its arc is a half circle, which
            // every great arc crosses (b0 b1 = -(n.da)^2, to the bit), so only A's arc is tested.
            if (!triangle) {
                const Lanes b0 = (bn0x * l.dx + bn0y * l.dy) + bn0z * l.dz;
                const Lanes b1 = (bn1x * l.dx + bn1y * l.dy) + bn1z * l.dz;
                crossing &= lane_bits(b0 * b1 <= 0);
            }
            for (; crossing != 0; crossing &= crossing - 1) {
                const std::uint32_t ja = 4 * g + static_cast<std::uint32_t>(__builtin_ctz(crossing));
                Vec3 unit;
                Real s;
                // The lanes ran edge_pair_axis's first two tests, bit for bit (against a
                // triangle only the second: the first passes there whatever the edge).
                if (!crossing_edge_pair_axis(edges_a[ja], eb, unit, s)) continue;
                if (s > best.separation) best = {s, ja, jb, unit, true};
                if (s > limit) return best;
            }
        }
    }
    return best;
}

// The axis of the feature the cache holds, with the separation along it computed as the
// whole SAT computes it: past the speculative distance it ends the test exactly when that
// axis would end the whole SAT. Not valid when the feature no longer stands (an index past
// the shape's, edges that no longer form a face of the Minkowski difference).
struct CachedAxis {
    bool valid = false;
    Real separation = 0;
    Vec3 unit = Vec3::UnitY();  // edge pairs only: from A to B
};

CachedAxis cached_axis(const FeatureCache& cache, const Posed& a, const Posed& b) {
    CachedAxis axis;
    switch (cache.kind()) {
        case FeatureCache::Kind::FaceA:
            if (cache.index_a() < a.view.face_count) axis = {true, face_separation(a, b, cache.index_a())};
            break;
        case FeatureCache::Kind::FaceB:
            if (cache.index_b() < b.view.face_count) axis = {true, face_separation(b, a, cache.index_b())};
            break;
        case FeatureCache::Kind::EdgePair:
            if (cache.index_a() < a.view.edge_count && cache.index_b() < b.view.edge_count) {
                // A in its own frame: a hull's kept arc is arc_edge's to the bit.
                const std::uint32_t ja = cache.index_a();
                axis.valid = edge_pair_axis(a.at_home && a.view.arc_edges ? a.view.arc_edges[ja] : arc_edge(a, ja),
                                            arc_edge(b, cache.index_b()), axis.unit, axis.separation);
            }
            break;
        case FeatureCache::Kind::None: break;
    }
    return axis;
}

// A FaceB cache's index_a (unused by B's face otherwise) when the face was not the SAT's
// choice but the one a contact was measured over past the incident face's clip (the
// fallbacks of face_of_b_manifold): the cached path measures it over the face again.
constexpr std::uint32_t kOverFaceOfB = 1;

void remember_axis(FeatureCache* cache, FeatureCache::Kind kind, std::uint32_t index_a, std::uint32_t index_b,
                   Real separation) {
    if (cache) *cache = FeatureCache(kind, index_a, index_b, static_cast<float>(separation));
}

// The face of `inc` that faces most against the reference normal n.
std::uint32_t incident_face(const Posed& inc, const Vec3& n) {
    std::uint32_t incident = 0;
    Real most_against = kHuge;
    for (std::uint32_t f = 0; f < inc.view.face_count; ++f) {
        const Real x = inc.normal(f).dot(n);
        if (x < most_against) most_against = x, incident = f;
    }
    return incident;
}

// The incident face's vertices clipped against the reference face's side planes in turn,
// in `in` and `next` by turns (each with room for the incident face and one vertex more
// per side plane); returns where the polygon left lies, its count in `count`. kSides is
// the reference face's count when known (a triangle's three: the loop unrolled), else 0.
template <std::uint32_t kSides>
[[gnu::always_inline]] inline const ClipVertex* clip_incident(const Posed& ref, const HullFace& ref_face, const Vec3& n,
                                                              const Posed& inc, const HullFace& inc_face,
                                                              ClipVertex* in, ClipVertex* next, int& count) {
    count = static_cast<int>(inc_face.count);
    for (std::uint32_t k = 0; k < inc_face.count; ++k) {
        // Field by field: an aggregate made first and then copied was written twice.
        in[k].p = inc.vertices[inc.view.face_vertices[inc_face.first + k]];
        in[k].key = clip_key(0, k, 0);
        in[k].edge = static_cast<std::uint16_t>(k);
    }
    const std::uint32_t sides = kSides != 0 ? kSides : ref_face.count;
#pragma GCC unroll 3
    for (std::uint32_t k = 0; k < sides; ++k) {
        if (count == 0) break;
        const Vec3& v0 = ref.vertices[ref.view.face_vertices[ref_face.first + k]];
        const Vec3& v1 = ref.vertices[ref.view.face_vertices[ref_face.first + (k + 1 == sides ? 0 : k + 1)]];
        const Vec3 side = (v1 - v0).cross(n).normalized();
        const Real offset = side.dot(v0);
        // A side plane with every vertex inside leaves the polygon as it is: no copy.
        int inside = 0;
        while (inside < count && side.dot(in[inside].p) - offset <= 0) ++inside;
        if (inside == count) continue;
        // clip_polygon's step, inlined here (the narrowphase's most frequent clip).
        count = clip_polygon_by(
            in, count, [&](const Vec3& p) { return side.dot(p) - offset; }, k, next);
        std::swap(in, next);
    }
    return in;
}

// A triangle of a mesh clipping a hull's face is the common clip: its polygon fits in two
// fixed arrays when the incident face has at most this many vertices.
constexpr std::uint32_t kTriangleClipIncident = 13;

// Clips face `incident` of `inc` against reference face `face` of `ref` (normal n) and
// returns the points within reach. A vertex that clipping drops lies beside the reference
// face, outside `ref`, and is not kept.
int clipped_contact(const Posed& ref, std::uint32_t face, const Vec3& n, const Posed& inc, std::uint32_t incident,
                    bool reference_is_b, Real speculative, ContactCandidate* out) {
    const HullFace& ref_face = ref.view.faces[face];
    const HullFace& inc_face = inc.view.faces[incident];
    const auto within_reach = [&](const ClipVertex* left, int count) {
        const Real d = ref.offset(face, n);
        int n_out = 0;
        for (int k = 0; k < count; ++k) {
            const Real s = n.dot(left[k].p) - d;
            if (s > speculative) continue;
            out[n_out++] = {left[k].p - n * (Real(0.5) * s), s,
                            face_contact_id(reference_is_b, face, incident, left[k].key)};
        }
        return n_out;
    };
    int count = 0;
    if (ref_face.count == 3 && inc_face.count <= kTriangleClipIncident) {
        ClipVertex first[kTriangleClipIncident + 3], second[kTriangleClipIncident + 3];
        const ClipVertex* left = clip_incident<3>(ref, ref_face, n, inc, inc_face, first, second, count);
        return within_reach(left, count);
    }
    const std::size_t capacity = inc_face.count + ref_face.count + 1;
    ScratchBuffer<ClipVertex, 2 * kInlineVertices> buffer(2 * capacity);
    const ClipVertex* left = clip_incident<0>(ref, ref_face, n, inc, inc_face, buffer.data(), buffer.data() + capacity,
                                              count);
    return within_reach(left, count);
}

// The incident face of `inc` (the one facing most against the reference face's normal)
// clipped against reference face `face` of `ref`; its normal in n.
int face_contact(const Posed& ref, std::uint32_t face, const Posed& inc, bool reference_is_b, Real speculative, Vec3& n,
                 ContactCandidate* out) {
    n = ref.normal(face);
    return clipped_contact(ref, face, n, inc, incident_face(inc, n), reference_is_b, speculative, out);
}

// When nothing over the reference face is within reach, yet the face axis says the shapes
// touch (it won over an edge pair by the bias towards faces): the incident vertex deepest
// along the normal stands for the contact, so the pair is never left without one.
int deepest_vertex_contact(const Posed& ref, std::uint32_t face, const Posed& inc, bool reference_is_b,
                           Real speculative, ContactCandidate* out) {
    const Vec3 n = ref.normal(face);
    const Real d = ref.offset(face, n);
    const std::uint32_t incident = incident_face(inc, n);
    const std::uint32_t v = inc.support(-n);
    const Real s = n.dot(inc.vertices[v]) - d;
    if (s > speculative) return 0;
    out[0] = {inc.vertices[v] - n * (Real(0.5) * s), s,
              face_contact_id(reference_is_b, face, incident, clip_key(3, v, v >> 6))};
    return 1;
}

bool over_face(const Posed& ref, std::uint32_t face, const Vec3& n, const Vec3& p);

// The manifold (in A's frame) of reference face `face`, of B when `reference_is_b`, with
// the deepest incident vertex standing in when no clipped point is within reach (unless
// `clipped_only`). Where B is a triangle of a mesh (`b_is_triangle`) and A's face the
// reference, only a vertex over that face stands in: one beside it lies over the face's
// plane carried on past its edges, which says nothing of where the shapes meet (a box
// coming down fast over a mesh took a neighbouring triangle's far corners as its points),
// and the triangles under the face make its contact. Between hulls it always stands in: a
// chosen axis must make a manifold (overlapping hulls had none). False when there is no point.
bool face_manifold(const Posed& pa, const Posed& pb, std::uint32_t face, bool reference_is_b, Real speculative,
                   bool clipped_only, Manifold& m, bool b_is_triangle = false) {
    const Posed& ref = reference_is_b ? pb : pa;
    const Posed& inc = reference_is_b ? pa : pb;
    // Clipping leaves at most (incident face + reference face) vertices.
    ScratchBuffer<ContactCandidate, kInlineVertices> candidates(pa.view.vertex_count + pb.view.vertex_count);
    Vec3 n;
    int count = face_contact(ref, face, inc, reference_is_b, speculative, n, candidates.data());
    if (count == 0 && !clipped_only &&
        (reference_is_b || !b_is_triangle || over_face(ref, face, n, inc.vertices[inc.support(-n)])))
        count = deepest_vertex_contact(ref, face, inc, reference_is_b, speculative, candidates.data());
    if (count == 0) return false;
    m.normal = reference_is_b ? Vec3(-n) : n;
    reduce_to_manifold(candidates.data(), count, m);
    return true;
}

// True when p lies over reference face `face` of `ref` (normal n): inside each of the side
// planes its clipping uses.
bool over_face(const Posed& ref, std::uint32_t face, const Vec3& n, const Vec3& p) {
    const HullFace& f = ref.view.faces[face];
    for (std::uint32_t k = 0; k < f.count; ++k) {
        const Vec3& v0 = ref.vertices[ref.view.face_vertices[f.first + k]];
        const Vec3& v1 = ref.vertices[ref.view.face_vertices[f.first + (k + 1) % f.count]];
        if ((v1 - v0).cross(n).dot(p - v0) > 0) return false;
    }
    return true;
}

// The manifold (in A's frame) of B's face `face` measured over that face alone: A's incident
// face clipped against it; when nothing clipped is within reach, A's vertex deepest along the
// normal if it lies over the face (it is then A's deepest point there), else every face of A
// that faces against the normal clipped against the face (A's surface over the face, which
// holds its deepest point there). The face's plane carried on past its edges says nothing of
// A beyond them: a long hull across a sloping triangle of a mesh lies far under that plane
// there, over other triangles. False when nothing over the face is within reach.
// With a cache, a manifold made keeps the face there as FaceB: from the incident face's clip
// (the one face_manifold makes with this face as the reference) as the SAT would keep it,
// from the fallbacks marked kOverFaceOfB, so the cached path measures it over the face again.
bool face_of_b_over(const Posed& pa, const Posed& pb, std::uint32_t face, Real speculative, Manifold& m,
                    FeatureCache* cache) {
    const Vec3 n = pb.normal(face);
    ScratchBuffer<ContactCandidate, kInlineVertices> candidates(pa.view.vertex_count + pb.view.vertex_count);
    const std::uint32_t incident = incident_face(pa, n);
    int count = clipped_contact(pb, face, n, pa, incident, true, speculative, candidates.data());
    m.normal = -n;
    if (count > 0) {
        reduce_to_manifold(candidates.data(), count, m);
        if (cache) remember_axis(cache, FeatureCache::Kind::FaceB, 0, face, face_separation(pb, pa, face));
        return true;
    }
    const Vec3& deepest = pa.vertices[pa.support(-n)];
    const Real d = pb.offset(face, n);
    if (n.dot(deepest) - d > speculative) return false;  // no point of A is within reach
    if (over_face(pb, face, n, deepest)) {
        count = deepest_vertex_contact(pb, face, pa, true, speculative, candidates.data());
        reduce_to_manifold(candidates.data(), count, m);
        if (count > 0 && cache)
            remember_axis(cache, FeatureCache::Kind::FaceB, kOverFaceOfB, face, face_separation(pb, pa, face));
        return count > 0;
    }
    // Each face of A clipped leaves at most its own vertices and one more per side of B's face.
    std::size_t room = 0;
    for (std::uint32_t f = 0; f < pa.view.face_count; ++f) room += pa.view.faces[f].count + pb.view.faces[face].count;
    ScratchBuffer<ContactCandidate, 2 * kInlineVertices> surface(room);
    count = 0;
    for (std::uint32_t f = 0; f < pa.view.face_count; ++f) {
        // The incident face was clipped above and left nothing within reach.
        if (f == incident || pa.normal(f).dot(n) >= 0) continue;
        // What clipping leaves of a face lies between its vertices: none within reach, none left.
        const HullFace& af = pa.view.faces[f];
        bool reaches = false;
        for (std::uint32_t k = 0; k < af.count && !reaches; ++k)
            reaches = n.dot(pa.vertices[pa.view.face_vertices[af.first + k]]) - d <= speculative;
        if (reaches) count += clipped_contact(pb, face, n, pa, f, true, speculative, surface.data() + count);
    }
    // Neighbouring faces share the points clipped on their common edge: pruned.
    reduce_to_manifold(surface.data(), count, m, true);
    if (m.point_count > 0 && cache)
        remember_axis(cache, FeatureCache::Kind::FaceB, kOverFaceOfB, face, face_separation(pb, pa, face));
    return m.point_count > 0;
}

// The one point (in A's frame) between edge edge_a of A and edge_b of B, along `axis`.
// With `crossing_only`, false when the closest points of the two lines lie beyond the ends
// of either edge: the edges no longer cross, and something else touches.
bool edge_manifold(const Posed& pa, const Posed& pb, std::uint32_t edge_a, std::uint32_t edge_b, const Vec3& axis,
                   bool crossing_only, Manifold& m) {
    const HullEdge& ea = pa.view.edges[edge_a];
    const HullEdge& eb = pb.view.edges[edge_b];
    const Vec3& a0 = pa.vertices[ea.v0];
    const Vec3& b0 = pb.vertices[eb.v0];
    const Vec3 da = pa.vertices[ea.v1] - a0, db = pb.vertices[eb.v1] - b0;
    Real s = 0, u = 0;
    closest_segment_parameters(a0, da, b0, db, s, u);
    if (crossing_only && (s <= 0 || s >= 1 || u <= 0 || u >= 1)) return false;
    const Vec3 on_a = a0 + s * da, on_b = b0 + u * db;
    m.normal = axis;
    m.points[0] = {Real(0.5) * (on_a + on_b), axis.dot(on_b - on_a), edge_contact_id(edge_a, edge_b)};
    m.point_count = 1;
    return true;
}

// The manifold from the cached touching feature alone (in A's frame), when the feature
// still makes one within reach.
bool cached_manifold(const FeatureCache& cache, const CachedAxis& axis, const Posed& pa, const Posed& pb,
                     Real speculative, Manifold& m) {
    switch (cache.kind()) {
        case FeatureCache::Kind::FaceA: return face_manifold(pa, pb, cache.index_a(), false, speculative, true, m);
        case FeatureCache::Kind::FaceB:
            if (cache.index_a() == kOverFaceOfB)
                return face_of_b_over(pa, pb, cache.index_b(), speculative, m, nullptr);
            return face_manifold(pa, pb, cache.index_b(), true, speculative, true, m);
        case FeatureCache::Kind::EdgePair:
            return edge_manifold(pa, pb, cache.index_a(), cache.index_b(), axis.unit, true, m) &&
                   m.points[0].separation <= speculative;
        case FeatureCache::Kind::None: break;
    }
    return false;
}

}  // namespace

PreparedPolyhedron::PreparedPolyhedron(const PolyView& view)
    : m_view(view),
      m_lane_buffer(view.vertex_lanes ? 0 : (view.vertex_count + 3) / 4),
      m_lanes(view.vertex_lanes ? view.vertex_lanes : m_lane_buffer.data()),
      m_edge_buffer(view.arc_edges ? 0 : view.edge_count),
      m_edges(view.arc_edges),
      m_edge_lane_buffer(view.arc_edges && view.arc_lanes ? 0 : (view.edge_count + 3) / 4),
      m_edge_lanes(view.arc_edges ? view.arc_lanes : nullptr) {
    if (!view.vertex_lanes) fill_lanes(view.vertices, view.vertex_count, m_lane_buffer.data());
}

void PreparedPolyhedron::prepare_edges() const {
    if (m_edges == nullptr) {
        const Posed own{m_view, m_view.vertices, m_lanes, Mat3::Identity(), Vec3::Zero(), m_view.inner_centre, true};
        detail::prepare_edges(own, m_edge_buffer.data());
        m_edges = m_edge_buffer.data();
    }
    if (m_edge_lanes == nullptr) {
        fill_arc_lanes(m_edges, m_view.edge_count, m_edge_lane_buffer.data());
        m_edge_lanes = m_edge_lane_buffer.data();
    }
}

bool collide_polyhedra(const PolyView& a, const Transform& xa, const PolyView& b, const Transform& xb, Real speculative,
                       Manifold& m, FeatureCache* cache, Real feature_slop) {
    const PreparedPolyhedron prepared(a);
    return collide_polyhedra(prepared, xa, b, xb, speculative, m, cache, feature_slop);
}

namespace {

// Poses b in a's frame (a's vertices as prepared, b's moved and laid out in lanes on the
// stack) and returns with(pa, pb). Inlined: collide_polyhedra is the narrowphase's
// hottest call.
template <typename With>
[[gnu::always_inline]] inline bool with_posed_pair(const PreparedPolyhedron& prepared, const PolyView& b,
                                                   const RelativePose& b_in_a, With&& with) {
    const PolyView& a = prepared.view();
    const Mat3& r = b_in_a.r;
    const Vec3& t = b_in_a.t;
    ScratchBuffer<Vec3, kInlineVertices> b_vertices(b.vertex_count);
    for (std::uint32_t i = 0; i < b.vertex_count; ++i) b_vertices[i] = r * b.vertices[i] + t;
    // Lanes pay for themselves only past one group: a triangle's support walks its three vertices.
    const bool b_in_lanes = b.vertex_count > 4;
    ScratchBuffer<VertexLanes, kInlineVertices / 4> b_lanes(b_in_lanes ? (b.vertex_count + 3) / 4 : 0);
    if (b_in_lanes) fill_lanes(b_vertices.data(), b.vertex_count, b_lanes.data());
    const Posed pa{a, a.vertices, prepared.vertex_lanes(), Mat3::Identity(), Vec3::Zero(), a.inner_centre, true};
    const Posed pb{b, b_vertices.data(), b_in_lanes ? b_lanes.data() : nullptr, r, t, r * b.inner_centre + t, false};
    return with(pa, pb);
}

}  // namespace

bool collide_polyhedra(const PreparedPolyhedron& prepared, const Transform& xa, const PolyView& b, const Transform& xb,
                       Real speculative, Manifold& m, FeatureCache* cache, Real feature_slop) {
    return collide_polyhedra(prepared, xa, b, RelativePose(xa, xb), speculative, m, cache, feature_slop);
}

namespace {

enum class SatResult { Apart, Touching, NormalOnly };

// collide_polyhedra's work on a posed pair: Touching with the manifold in A's frame, or Apart.
// Before the whole SAT makes the manifold of the axis it chose, normal_only(normal) (the
// normal in A's frame) may say its points are not wanted: the answer is then NormalOnly, with
// the cache kept as for Touching and m as it was. (Between hulls a chosen axis always makes a
// manifold: the deepest vertex stands in for a face's clip, and it lies at the face's
// separation, which is within reach. With `b_is_triangle`, B a triangle of a mesh, A's face
// may make none: face_manifold.) With `keep_face_b` (a face of B, or -1), a cache that keeps
// that face, past the slop, has it measured over (face_of_b_over) before any whole SAT.
template <typename NormalOnly>
[[gnu::always_inline]] inline SatResult sat_posed(const PreparedPolyhedron& prepared, const Posed& pa, const Posed& pb,
                                                  Real speculative, Manifold& m, FeatureCache* cache, Real feature_slop,
                                                  NormalOnly&& normal_only, int keep_face_b = -1,
                                                  bool b_is_triangle = false) {
    using Kind = FeatureCache::Kind;
    if (cache && cache->kind() != Kind::None) {
        const CachedAxis axis = cached_axis(*cache, pa, pb);
        if (axis.valid && axis.separation > speculative) return SatResult::Apart;
        if (axis.valid && std::abs(axis.separation - cache->separation()) < feature_slop &&
            cached_manifold(*cache, axis, pa, pb, speculative, m))
            return SatResult::Touching;
        // B's face `keep_face_b`, kept because the mesh's rule had it measured over, is measured
        // over again past the slop: the whole SAT would mostly choose an edge or a face of A that
        // the rule sends back to the same face.
        if (axis.valid && cache->kind() == Kind::FaceB && static_cast<int>(cache->index_b()) == keep_face_b &&
            face_of_b_over(pa, pb, cache->index_b(), speculative, m, cache))
            return SatResult::Touching;
    }
    const FaceQuery face_a = query_faces(pa, pb, speculative);
    if (face_a.separation > speculative) {
        remember_axis(cache, Kind::FaceA, face_a.face, 0, face_a.separation);
        return SatResult::Apart;
    }
    const FaceQuery face_b = query_faces(pb, pa, speculative);
    if (face_b.separation > speculative) {
        remember_axis(cache, Kind::FaceB, 0, face_b.face, face_b.separation);
        return SatResult::Apart;
    }
    const EdgeQuery edge = query_edges(prepared, pa, pb, std::max(face_a.separation, face_b.separation), speculative);
    if (edge.separation > speculative) {
        remember_axis(cache, Kind::EdgePair, edge.edge_a, edge.edge_b, edge.separation);
        return SatResult::Apart;
    }

    if (edge.found && clearly_greater(edge.separation, std::max(face_a.separation, face_b.separation))) {
        remember_axis(cache, Kind::EdgePair, edge.edge_a, edge.edge_b, edge.separation);
        if (normal_only(edge.axis)) return SatResult::NormalOnly;
        edge_manifold(pa, pb, edge.edge_a, edge.edge_b, edge.axis, false, m);
        return SatResult::Touching;
    }

    const bool reference_is_b = clearly_greater(face_b.separation, face_a.separation);
    const FaceQuery& reference = reference_is_b ? face_b : face_a;
    if (reference_is_b) remember_axis(cache, Kind::FaceB, 0, reference.face, reference.separation);
    else remember_axis(cache, Kind::FaceA, reference.face, 0, reference.separation);
    // face_manifold's normal, as it makes it.
    if (normal_only(reference_is_b ? Vec3(-pb.normal(reference.face)) : pa.normal(reference.face)))
        return SatResult::NormalOnly;
    if (!face_manifold(pa, pb, reference.face, reference_is_b, speculative, false, m, b_is_triangle)) {
        remember_axis(cache, Kind::None, 0, 0, 0);
        return SatResult::Apart;
    }
    return SatResult::Touching;
}

}  // namespace

bool collide_polyhedra(const PreparedPolyhedron& prepared, const Transform& xa, const PolyView& b,
                       const RelativePose& b_in_a, Real speculative, Manifold& m, FeatureCache* cache,
                       Real feature_slop) {
    return with_posed_pair(prepared, b, b_in_a, [&](const Posed& pa, const Posed& pb) {
        const auto points_wanted = [](const Vec3&) { return false; };
        if (sat_posed(prepared, pa, pb, speculative, m, cache, feature_slop, points_wanted) != SatResult::Touching)
            return false;
        manifold_to_world(m, xa);
        return true;
    });
}

bool collide_polyhedron_triangle(const PreparedPolyhedron& prepared, const Transform& xa, const PolyView& triangle,
                                 const RelativePose& triangle_in_a, Real speculative, Manifold& m, FeatureCache* cache,
                                 Real feature_slop, const FaceMeasure& measure) {
    return with_posed_pair(prepared, triangle, triangle_in_a, [&](const Posed& pa, const Posed& pb) {
        // The normal alone decides when the points cannot: m then carries it, with no points.
        const auto normal_only = [&](const Vec3& normal) {
            if (measure.points_matter) return false;
            m.normal = xa.rotate(normal);
            m.point_count = 0;
            return measure.again(m);
        };
        switch (sat_posed(prepared, pa, pb, speculative, m, cache, feature_slop, normal_only,
                          measure.points_matter ? -1 : static_cast<int>(measure.face), true)) {
            case SatResult::Apart: return false;
            case SatResult::Touching:
                manifold_to_world(m, xa);
                if (!measure.again(m)) return true;
                break;
            case SatResult::NormalOnly: break;
        }
        if (!face_of_b_over(pa, pb, measure.face, speculative, m, cache)) return false;
        manifold_to_world(m, xa);
        return true;
    });
}

bool face_of_b_manifold(const PreparedPolyhedron& prepared, const Transform& xa, const PolyView& b, const Transform& xb,
                        std::uint32_t face_b, Real speculative, Manifold& m) {
    return face_of_b_manifold(prepared, xa, b, RelativePose(xa, xb), face_b, speculative, m);
}

bool face_of_b_manifold(const PreparedPolyhedron& prepared, const Transform& xa, const PolyView& b,
                        const RelativePose& b_in_a, std::uint32_t face_b, Real speculative, Manifold& m,
                        FeatureCache* cache) {
    return with_posed_pair(prepared, b, b_in_a, [&](const Posed& pa, const Posed& pb) {
        if (!face_of_b_over(pa, pb, face_b, speculative, m, cache)) return false;
        manifold_to_world(m, xa);
        return true;
    });
}

bool kept_axis_separates(const PreparedPolyhedron& prepared, const Vec3 (&triangle)[3], const Vec3& normal,
                         const RelativePose& b_in_a, const FeatureCache& cache, Real speculative) {
    if (cache.kind() != FeatureCache::Kind::FaceA && cache.kind() != FeatureCache::Kind::EdgePair) return false;
    // The triangle as with_posed_pair poses it, and as a TrianglePoly views it (its faces'
    // offsets aside, which neither axis reads), so the axis is measured to the bit as there.
    const PolyView& a = prepared.view();
    const HullFace faces[2] = {{normal, 0, 0, 3}, {-normal, 0, 3, 3}};
    PolyView b;
    b.vertices = triangle;
    b.faces = faces;
    b.face_vertices = kTriangleLoops;
    b.edges = kTriangleEdges;
    b.vertex_count = 3, b.face_count = 2, b.edge_count = 3;
    const Vec3 posed[3] = {b_in_a.r * triangle[0] + b_in_a.t, b_in_a.r * triangle[1] + b_in_a.t,
                           b_in_a.r * triangle[2] + b_in_a.t};
    const Posed pa{a, a.vertices, prepared.vertex_lanes(), Mat3::Identity(), Vec3::Zero(), a.inner_centre, true};
    const Posed pb{b, posed, nullptr, b_in_a.r, b_in_a.t, Vec3::Zero(), false};
    const CachedAxis axis = cached_axis(cache, pa, pb);
    return axis.valid && axis.separation > speculative;
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
