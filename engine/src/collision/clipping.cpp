// Clipping with feature tracking, reduction of contact candidates to a four-point
// manifold, and segment closest points (see clipping.hpp).
#include "collision/clipping.hpp"

#include <algorithm>
#include <cmath>

#include <spindle/platform/assert.hpp>

namespace spindle::detail {

int start_clip_polygon(const Vec3* p, int count, ClipVertex* out) {
    for (int i = 0; i < count; ++i) {
        out[i].p = p[i];
        out[i].key = clip_key(0, static_cast<std::uint32_t>(i), 0);
        out[i].edge = static_cast<std::uint16_t>(i);
    }
    return count;
}

int clip_polygon(const ClipVertex* in, int count, const ClipPlane& plane, std::uint32_t side, ClipVertex* out) {
    return clip_polygon_by(
        in, count, [&plane](const Vec3& p) { return plane.normal.dot(p) - plane.offset; }, side, out);
}

namespace {

// Separations this close count as equally deep when picking the first point.
constexpr Real kEqualDepth = 1e-5;
// Points closer than this are one point to the reduction.
constexpr Real kSamePoint = 1e-6;

// Signed area (times two) of triangle a b c seen along n. Inlined: the reduction calls it
// for every candidate against each side of its triangle.
[[gnu::always_inline]] inline Real signed_area(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n) {
    return (b - a).cross(c - a).dot(n);
}

ManifoldPoint to_point(const ContactCandidate& c) {
    ManifoldPoint p;
    p.point = c.point;
    p.separation = c.separation;
    p.id = c.id;
    return p;
}

}  // namespace

void reduce_to_manifold(const ContactCandidate* c, int count, Manifold& m, bool prune) {
    if (count <= kMaxManifoldPoints && !prune) {
        for (int i = 0; i < count; ++i) m.points[i] = to_point(c[i]);
        m.point_count = count;
        return;
    }
    m.point_count = 0;
    if (count == 0) return;
    // 1: the deepest (it carries the most load); among points equally deep (a box lying
    // flat) the one farthest out, so the four picked span the whole patch.
    Vec3 centre = Vec3::Zero();
    for (int i = 0; i < count; ++i) centre += c[i].point;
    centre /= Real(count);
    int i0 = 0;
    for (int i = 1; i < count; ++i) {
        if (c[i].separation < c[i0].separation) i0 = i;
    }
    const Real deepest = c[i0].separation;
    for (int i = 0; i < count; ++i) {
        if (c[i].separation <= deepest + kEqualDepth &&
            (c[i].point - centre).squaredNorm() > (c[i0].point - centre).squaredNorm()) {
            i0 = i;
        }
    }
    m.points[m.point_count++] = to_point(c[i0]);
    // 2: farthest from it; 3: largest triangle; 4: most area added outside that triangle.
    int i1 = -1;
    Real best = kSamePoint * kSamePoint;
    for (int i = 0; i < count; ++i) {
        const Real d = (c[i].point - c[i0].point).squaredNorm();
        if (d > best) best = d, i1 = i;
    }
    if (i1 < 0) return;
    m.points[m.point_count++] = to_point(c[i1]);
    const Real length = std::sqrt(best);
    int i2 = -1;
    best = kSamePoint * length;  // twice the smallest triangle area worth a point
    for (int i = 0; i < count; ++i) {
        const Real a = std::abs(signed_area(c[i0].point, c[i1].point, c[i].point, m.normal));
        if (a > best) best = a, i2 = i;
    }
    if (i2 < 0) return;
    if (signed_area(c[i0].point, c[i1].point, c[i2].point, m.normal) < 0) std::swap(i1, i2);
    m.points[1] = to_point(c[i1]);
    m.points[m.point_count++] = to_point(c[i2]);
    int i3 = -1;
    best = kSamePoint * length;
    for (int i = 0; i < count; ++i) {
        // Counter-clockwise triangle: a point outside an edge has negative area against it.
        const Real a = -std::min({signed_area(c[i0].point, c[i1].point, c[i].point, m.normal),
                                  signed_area(c[i1].point, c[i2].point, c[i].point, m.normal),
                                  signed_area(c[i2].point, c[i0].point, c[i].point, m.normal)});
        if (a > best) best = a, i3 = i;
    }
    if (i3 >= 0) m.points[m.point_count++] = to_point(c[i3]);
}

Real closest_parameter_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 d = b - a;
    const Real dd = d.squaredNorm();
    if (dd <= 0) return 0;
    return std::clamp((p - a).dot(d) / dd, Real(0), Real(1));
}

void closest_segment_parameters(const Vec3& p1, const Vec3& d1, const Vec3& p2, const Vec3& d2, Real& s, Real& t) {
    constexpr Real kTiny = 1e-24;
    const Vec3 r = p1 - p2;
    const Real a = d1.squaredNorm();
    const Real e = d2.squaredNorm();
    const Real f = d2.dot(r);
    if (a <= kTiny && e <= kTiny) {
        s = t = 0;
        return;
    }
    if (a <= kTiny) {
        s = 0;
        t = std::clamp(f / e, Real(0), Real(1));
        return;
    }
    const Real c = d1.dot(r);
    if (e <= kTiny) {
        t = 0;
        s = std::clamp(-c / a, Real(0), Real(1));
        return;
    }
    const Real b = d1.dot(d2);
    const Real denom = a * e - b * b;  // |d1 x d2|^2, zero when parallel
    if (denom <= Real(1e-12) * a * e) {
        // Parallel: take the middle of the overlap of segment 2 projected on segment 1.
        const Real s_start = -c / a;
        const Real s_end = (-c + b) / a;
        const Real lo = std::max(Real(0), std::min(s_start, s_end));
        const Real hi = std::min(Real(1), std::max(s_start, s_end));
        s = lo <= hi ? Real(0.5) * (lo + hi) : (hi < 0 ? Real(0) : Real(1));
    } else {
        s = std::clamp((b * f - c * e) / denom, Real(0), Real(1));
    }
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, Real(0), Real(1));
    } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, Real(0), Real(1));
    }
}

Vec3 any_perpendicular(const Vec3& v) {
    // Cross with the axis least aligned with v, so the result is never tiny.
    const Vec3 a = v.cwiseAbs();
    const Vec3 axis = a.x() <= a.y() && a.x() <= a.z() ? Vec3::UnitX()
                                                       : (a.y() <= a.z() ? Vec3::UnitY() : Vec3::UnitZ());
    return v.cross(axis).normalized();
}

}  // namespace spindle::detail
