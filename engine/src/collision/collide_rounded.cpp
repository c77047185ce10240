// Pairs of rounded shapes (sphere, capsule), whose contact is between closest points of
// their cores, and sphere-box, solved by clamping the centre into the box.
#include <algorithm>
#include <cmath>

#include "collision/clipping.hpp"
#include "collision/pair_functions.hpp"

namespace spindle::detail {
namespace {

// Feature keys of the rounded pairs (other_contact_id space).
constexpr std::uint32_t kSingleKey = 0;
constexpr std::uint32_t kCapsuleEndKey = 1;  // + 0..3: which segment end bounds the overlap

// Cores closer than this have no reliable direction between them; a fallback is used.
constexpr Real kCoincident = 1e-12;

// One contact between core points ca (on A) and cb (on B) swept by radii ra and rb.
// `fallback()` gives the normal when the cores touch exactly (called only then).
template <typename Fallback>
bool rounded_contact(const Vec3& ca, const Vec3& cb, Real ra, Real rb, Fallback&& fallback, Real speculative,
                     Manifold& m) {
    const Vec3 d = cb - ca;
    const Real dist = d.norm();
    const Real separation = dist - ra - rb;
    if (separation > speculative) return false;
    m.normal = dist > kCoincident ? Vec3(d / dist) : Vec3(fallback());
    m.points[0].point = ca + m.normal * (ra + Real(0.5) * separation);
    m.points[0].separation = separation;
    m.points[0].id = other_contact_id(kSingleKey);
    m.point_count = 1;
    return true;
}

// A direction from a to b that does not depend on the cores: the line between the
// centres, else world up. Used only when the cores touch exactly.
Vec3 centre_direction(const Transform& xa, const Transform& xb, const Vec3& perpendicular_to) {
    Vec3 d = xb.p - xa.p;
    d -= perpendicular_to * d.dot(perpendicular_to);
    const Real len = d.norm();
    if (len > kCoincident) return d / len;
    return perpendicular_to.isZero() ? Vec3(Vec3::UnitY()) : any_perpendicular(perpendicular_to);
}

// Two points for capsules lying side by side: the ends of the overlap of B's segment
// projected onto A's. Returns false when the segments are not parallel or do not overlap.
bool parallel_capsules(const Vec3& a0, const Vec3& da, const Vec3& b0, const Vec3& db, Real ra, Real rb,
                       Real speculative, Manifold& m) {
    constexpr Real kParallelSine2 = 0.0025;  // sin^2 of about 3 degrees
    const Real la2 = da.squaredNorm(), lb2 = db.squaredNorm();
    if (da.cross(db).squaredNorm() > kParallelSine2 * la2 * lb2) return false;
    const Real s_start = (b0 - a0).dot(da) / la2;
    const Real s_end = (b0 + db - a0).dot(da) / la2;
    const bool ascending = s_start <= s_end;
    const Real lo = std::max(Real(0), std::min(s_start, s_end));
    const Real hi = std::min(Real(1), std::max(s_start, s_end));
    if (hi - lo < Real(1e-3)) return false;
    const Real ends[2] = {lo, hi};
    // An end is made by A's own end (key 0/1) or by one of B's ends (key 2/3).
    const std::uint32_t keys[2] = {lo == 0 ? 0u : (ascending ? 2u : 3u), hi == 1 ? 1u : (ascending ? 3u : 2u)};
    int n = 0;
    for (int i = 0; i < 2; ++i) {
        const Vec3 pa = a0 + ends[i] * da;
        const Vec3 pb = b0 + closest_parameter_on_segment(pa, b0, b0 + db) * db;
        const Real separation = (pb - pa).dot(m.normal) - ra - rb;
        if (separation > speculative) continue;
        m.points[n].point = pa + m.normal * (ra + Real(0.5) * separation);
        m.points[n].separation = separation;
        m.points[n].id = other_contact_id(kCapsuleEndKey + keys[i]);
        ++n;
    }
    if (n == 0) return false;
    m.point_count = n;
    return true;
}

}  // namespace

int collide_sphere_sphere(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                          Manifold* out, int) {
    const auto up = [] { return Vec3(Vec3::UnitY()); };
    return rounded_contact(xa.p, xb.p, a.radius, b.radius, up, speculative, out[0]) ? 1 : 0;
}

int collide_sphere_capsule(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                           Manifold* out, int) {
    const Vec3 axis = xb.rotate(Vec3(0, b.half_height, 0));
    const Vec3 b0 = xb.p - axis;
    const Real t = closest_parameter_on_segment(xa.p, b0, xb.p + axis);
    const Vec3 cb = b0 + 2 * t * axis;
    const auto across = [&axis] { return any_perpendicular(axis); };
    return rounded_contact(xa.p, cb, a.radius, b.radius, across, speculative, out[0]) ? 1 : 0;
}

int collide_capsule_capsule(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                            Manifold* out, int) {
    const Vec3 ha = xa.rotate(Vec3(0, a.half_height, 0));
    const Vec3 hb = xb.rotate(Vec3(0, b.half_height, 0));
    const Vec3 a0 = xa.p - ha, da = 2 * ha;
    const Vec3 b0 = xb.p - hb, db = 2 * hb;
    Real s = 0, t = 0;
    closest_segment_parameters(a0, da, b0, db, s, t);
    const Vec3 ca = a0 + s * da;
    const Vec3 cb = b0 + t * db;
    // Crossing axes: their common perpendicular; parallel ones: across, towards B.
    const auto fallback = [&] {
        const Vec3 across = da.cross(db);
        const Vec3 n = across.squaredNorm() > Real(1e-12) * da.squaredNorm() * db.squaredNorm()
                           ? Vec3(across.normalized())
                           : centre_direction(xa, xb, da.normalized());
        return n.dot(xb.p - xa.p) < 0 ? Vec3(-n) : n;
    };
    Manifold& m = out[0];
    if (!rounded_contact(ca, cb, a.radius, b.radius, fallback, speculative, m)) return 0;
    parallel_capsules(a0, da, b0, db, a.radius, b.radius, speculative, m);
    return 1;
}

int collide_sphere_box(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                       Manifold* out, int) {
    const Vec3 c = xb.apply_inverse(xa.p);
    const Vec3& h = b.half_extents;
    const Vec3 q = c.cwiseMax(-h).cwiseMin(h);
    Vec3 box_to_sphere;  // local, unit
    Real separation = 0;
    Vec3 on_box;
    if (q != c) {
        const Vec3 d = c - q;
        const Real dist = d.norm();
        box_to_sphere = d / dist;
        separation = dist - a.radius;
        on_box = q;
    } else {
        // Centre inside: leave through the nearest face.
        int axis = 0;
        Real depth = kHuge;
        for (int i = 0; i < 3; ++i) {
            const Real di = h[i] - std::abs(c[i]);
            if (di < depth) depth = di, axis = i;
        }
        box_to_sphere = Vec3::Zero();
        box_to_sphere[axis] = c[axis] < 0 ? -1 : 1;
        separation = -depth - a.radius;
        on_box = c;
        on_box[axis] = box_to_sphere[axis] * h[axis];
    }
    if (separation > speculative) return 0;
    Manifold& m = out[0];
    m.normal = xb.rotate(-box_to_sphere);
    m.points[0].point = xb.apply(on_box + box_to_sphere * (Real(0.5) * separation));
    m.points[0].separation = separation;
    m.points[0].id = other_contact_id(kSingleKey);
    m.point_count = 1;
    return 1;
}

}  // namespace spindle::detail
