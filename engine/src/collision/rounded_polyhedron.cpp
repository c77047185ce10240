// A sphere or capsule (a point or segment core swept by a radius) against a polyhedron.
// While the cores are apart GJK gives the exact closest points, so a capsule rolling
// over a corner gets the true normal; once the core dips in, SAT over the face normals
// and the edge-segment axes finds the way out. All work happens in B's frame.
// Serves sphere-hull, capsule-box and capsule-hull, and spheres and capsules on mesh triangles.
#include <algorithm>
#include <cmath>

#include "collision/clipping.hpp"
#include "collision/convex_hull.hpp"
#include "collision/gjk.hpp"
#include "collision/pair_functions.hpp"

namespace spindle::detail {
namespace {

// Cores closer than this are treated as overlapping: GJK's direction gets noisy there.
constexpr Real kCoreTolerance = 1e-6;
// A separated capsule whose closest-point normal is within ~2.5 degrees of a face normal
// lies on (or along) that face: it gets two points so it does not rock.
constexpr Real kFaceAlignment = 0.999;

struct Core {
    Vec3 s[2];
    bool is_point;
    Real radius;
};

// Points of the core clipped to face f's prism. Each is measured from the face plane
// along `out` (unit, from B towards A, within a few degrees of the face normal).
// Returns how many were written (0 when the core lies outside the prism).
int face_points(const Core& core, const PolyView& b, std::uint32_t f, const Vec3& out, Real speculative,
                ManifoldPoint* points) {
    const HullFace& face = b.faces[f];
    Real t[2] = {0, 1};
    std::uint16_t key[2] = {clip_key(0, 0, 0), clip_key(0, 1, 0)};
    const Vec3 d = core.s[1] - core.s[0];
    for (std::uint32_t k = 0; k < face.count; ++k) {
        const Vec3& v0 = b.face_vertex(face, k);
        const Vec3& v1 = b.face_vertex(face, (k + 1) % face.count);
        const Vec3 side = (v1 - v0).cross(face.normal);
        // Inside where side . (s0 + t d - v0) <= 0.
        const Real start = side.dot(core.s[0] - v0);
        const Real rate = side.dot(d);
        if (std::abs(rate) <= Real(1e-15) * side.norm()) {
            if (start > 0) return 0;
            continue;
        }
        const Real cut = -start / rate;
        if (rate > 0 && cut < t[1]) t[1] = cut, key[1] = clip_key(1, 1, k);
        if (rate < 0 && cut > t[0]) t[0] = cut, key[0] = clip_key(1, 0, k);
        if (t[0] > t[1]) return 0;
    }
    const int ends = core.is_point || t[1] - t[0] < Real(1e-9) ? 1 : 2;
    const Real slant = face.normal.dot(out);
    int n = 0;
    for (int i = 0; i < ends; ++i) {
        const Vec3 s = core.s[0] + t[i] * d;
        const Real separation = (face.normal.dot(s) - face.offset) / slant - core.radius;
        if (separation > speculative) continue;
        points[n++] = {s - out * (core.radius + Real(0.5) * separation), separation,
                       face_contact_id(true, f, 0, key[i])};
    }
    return n;
}

// A single point between core point on_a and polyhedron point on_b, with `out_normal`
// the unit direction from B towards A.
void single_point(const Vec3& on_a, const Vec3& on_b, const Vec3& out_normal, Real radius, std::uint32_t id,
                  Manifold& m) {
    const Real separation = out_normal.dot(on_a - on_b) - radius;
    m.normal = -out_normal;
    m.points[0] = {on_b + out_normal * (Real(0.5) * separation), separation, id};
    m.point_count = 1;
}

bool separated_cores(const Core& core, const PolyView& b, const GjkResult& g, Real speculative, Manifold& m) {
    if (g.distance - core.radius > speculative) return false;
    const Vec3 out_normal = (g.point_a - g.point_b) / g.distance;
    if (!core.is_point) {
        std::uint32_t best = 0;
        for (std::uint32_t f = 1; f < b.face_count; ++f) {
            if (b.faces[f].normal.dot(out_normal) > b.faces[best].normal.dot(out_normal)) best = f;
        }
        if (b.faces[best].normal.dot(out_normal) > kFaceAlignment) {
            // Points from the face, but the exact closest-point normal: a capsule hanging
            // over an edge still tips off it.
            const int n = face_points(core, b, best, out_normal, speculative, m.points);
            if (n > 0) {
                m.normal = -out_normal;
                m.point_count = n;
                return true;
            }
        }
    }
    single_point(g.point_a, g.point_b, out_normal, core.radius, other_contact_id(0), m);
    return true;
}

bool overlapping_cores(const Core& core, const PolyView& b, Real speculative, Manifold& m) {
    std::uint32_t face = 0;
    Real face_separation = -kHuge;
    for (std::uint32_t f = 0; f < b.face_count; ++f) {
        const HullFace& hf = b.faces[f];
        const Real s = std::min(hf.normal.dot(core.s[0]), hf.normal.dot(core.s[1])) - hf.offset;
        if (s > face_separation) face_separation = s, face = f;
    }
    // Edge axes: the segment's Gauss map is the whole circle perpendicular to it, so
    // an edge counts when its own arc crosses that circle.
    const Vec3 u = core.s[1] - core.s[0];
    Real edge_separation = -kHuge;
    std::uint32_t edge = 0;
    Vec3 edge_axis = Vec3::Zero();
    for (std::uint32_t j = 0; !core.is_point && j < b.edge_count; ++j) {
        const HullEdge& e = b.edges[j];
        const Vec3& v0 = b.vertices[e.v0];
        const Vec3 ev = b.vertices[e.v1] - v0;
        const Vec3 cross = ev.cross(u);
        const Real length2 = cross.squaredNorm();
        if (length2 <= Real(1e-12) * ev.squaredNorm() * u.squaredNorm()) continue;
        for (const Real sign : {Real(1), Real(-1)}) {
            const Vec3 axis = sign * cross;
            if (!on_edge_arc(axis, b.faces[e.f0].normal, b.faces[e.f1].normal, ev)) continue;
            const Vec3 unit = axis / std::sqrt(length2);
            const Real s = unit.dot(core.s[0] - v0);
            if (s > edge_separation) edge_separation = s, edge = j, edge_axis = unit;
            break;
        }
    }
    if (clearly_greater(edge_separation, face_separation)) {
        const HullEdge& e = b.edges[edge];
        const Vec3& v0 = b.vertices[e.v0];
        Real s = 0, t = 0;
        closest_segment_parameters(core.s[0], u, v0, b.vertices[e.v1] - v0, s, t);
        const Vec3 on_a = core.s[0] + s * u;
        const Vec3 on_b = v0 + t * (b.vertices[e.v1] - v0);
        single_point(on_a, on_b, edge_axis, core.radius, edge_contact_id(0, edge), m);
        return edge_separation - core.radius <= speculative;
    }
    const int n = face_points(core, b, face, b.faces[face].normal, speculative, m.points);
    m.normal = -b.faces[face].normal;
    if (n > 0) {
        m.point_count = n;
        return true;
    }
    // The core crosses the face plane outside the face (a sliver of a hull): take its
    // deepest end as it is.
    const HullFace& hf = b.faces[face];
    const int i = hf.normal.dot(core.s[0]) <= hf.normal.dot(core.s[1]) ? 0 : 1;
    const Real separation = hf.normal.dot(core.s[i]) - hf.offset - core.radius;
    if (separation > speculative) return false;
    m.points[0] = {core.s[i] - hf.normal * (core.radius + Real(0.5) * separation), separation,
                   face_contact_id(true, face, 0, clip_key(3, static_cast<std::uint32_t>(i), 0))};
    m.point_count = 1;
    return true;
}

}  // namespace

bool collide_rounded_polyhedron(const Vec3& p0, const Vec3& p1, Real radius, const Transform& xa, const PolyView& b,
                                const Transform& xb, Real speculative, Manifold& m) {
    const Transform a_in_b = xb.inverse() * xa;
    const Core core{{a_in_b.apply(p0), a_in_b.apply(p1)}, p0 == p1, radius};
    const GjkResult g = gjk_distance(core.s, core.is_point ? 1 : 2, b.vertices, static_cast<int>(b.vertex_count));
    const bool hit = !g.overlap && g.distance > kCoreTolerance ? separated_cores(core, b, g, speculative, m)
                                                               : overlapping_cores(core, b, speculative, m);
    if (hit) manifold_to_world(m, xb);
    return hit;
}

int collide_sphere_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                        Manifold* out, int) {
    return collide_rounded_polyhedron(Vec3::Zero(), Vec3::Zero(), a.radius, xa, view_of(*b.hull), xb, speculative,
                                      out[0])
               ? 1
               : 0;
}

int collide_capsule_box(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                        Manifold* out, int) {
    Vec3 p0, p1;
    rounded_core(a, p0, p1);
    const BoxPoly box(b.half_extents);
    return collide_rounded_polyhedron(p0, p1, a.radius, xa, box.view(), xb, speculative, out[0]) ? 1 : 0;
}

int collide_capsule_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                         Manifold* out, int) {
    Vec3 p0, p1;
    rounded_core(a, p0, p1);
    return collide_rounded_polyhedron(p0, p1, a.radius, xa, view_of(*b.hull), xb, speculative, out[0]) ? 1 : 0;
}

}  // namespace spindle::detail
