// ShapeSpan: a shape's extent along a triangle's normal, against the triangle's plane.
// Most triangles a shape's bounds find lie wholly below it (a body on a terrain) or above.
#include "collision/shape_span.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include "collision/convex_hull.hpp"
#include "collision/lanes.hpp"
#include "collision/polyhedron.hpp"

namespace spindle::detail {
namespace {

// A triangle is ruled out only this far (relative to the coordinates' size) beyond the
// speculative distance: far above the rounding by which this arithmetic and the pair
// test's may differ. GJK's distance between a rounded core and the triangle is never
// below the plane's.
constexpr Real kPlaneSlack = 1e-9;

}  // namespace

ShapeSpan::ShapeSpan(const Shape& a, const Transform& a_in_mesh)
    : m_type(a.type), m_center(a_in_mesh.p), m_rotation(a_in_mesh.q.toRotationMatrix()) {
    switch (a.type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule:
            m_core[0] = a_in_mesh.apply(Vec3(0, -a.half_height, 0));
            m_core[1] = a_in_mesh.apply(Vec3(0, a.half_height, 0));
            m_radius = a.radius;
            break;
        case ShapeType::Box: m_half = a.half_extents; break;
        case ShapeType::ConvexHull: m_hull = a.hull.get(); break;
        default: break;
    }
}

void ShapeSpan::along(const Vec3& n, Real& lo, Real& hi) const {
    switch (m_type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule: {
            const Real d0 = n.dot(m_core[0]), d1 = n.dot(m_core[1]);
            lo = std::min(d0, d1) - m_radius;
            hi = std::max(d0, d1) + m_radius;
            return;
        }
        case ShapeType::Box: {
            const Real c = n.dot(m_center);
            const Real e = (m_rotation.transpose() * n).cwiseAbs().dot(m_half);
            lo = c - e;
            hi = c + e;
            return;
        }
        case ShapeType::ConvexHull: {
            // Four vertices a step from the hull's lanes (the padding repeats a vertex).
            const Vec3 local = m_rotation.transpose() * n;
            const Lanes x = Lanes{} + local.x(), y = Lanes{} + local.y(), z = Lanes{} + local.z();
            const std::span<const VertexLanes> lanes = m_hull->vertex_lanes();
            Lanes low = (lanes[0].x * x + lanes[0].y * y) + lanes[0].z * z, high = low;
            for (std::size_t g = 1; g < lanes.size(); ++g) {
                const Lanes d = (lanes[g].x * x + lanes[g].y * y) + lanes[g].z * z;
                low = d < low ? d : low;
                high = d > high ? d : high;
            }
            const Real c = n.dot(m_center);
            lo = c + std::min(std::min(low[0], low[1]), std::min(low[2], low[3]));
            hi = c + std::max(std::max(high[0], high[1]), std::max(high[2], high[3]));
            return;
        }
        default: lo = -kHuge, hi = kHuge;  // no span known: never clear of a plane
    }
}

bool ShapeSpan::clear_of_plane(const Vec3 (&v)[3], Real speculative) const {
    return clear_of_plane(v, triangle_normal(v[0], v[1], v[2]), speculative);
}

bool ShapeSpan::clear_of_plane(const Vec3 (&v)[3], const Vec3& n, Real speculative) const {
    const Real offset = n.dot(v[0]);
    Real lo, hi;
    along(n, lo, hi);
    const Real slack = kPlaneSlack * (1 + std::abs(offset) + std::abs(lo) + std::abs(hi));
    const Real reach = std::max(speculative, Real(0)) + slack;
    return lo - offset > reach || offset - hi > reach;
}

}  // namespace spindle::detail
