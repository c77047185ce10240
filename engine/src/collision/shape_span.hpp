// ShapeSpan: a convex shape posed in a mesh's frame, reduced to its extent along a
// direction, so that a triangle whose plane it lies clear of is ruled out before the pair
// test builds the triangle's polyhedron and runs SAT or GJK to say the same.
#pragma once

#include <spindle/engine/math.hpp>
#include <spindle/engine/shape.hpp>

namespace spindle::detail {

class ShapeSpan {
public:
    // a: a sphere, capsule, box or hull; a_in_mesh: its pose in the mesh's frame.
    ShapeSpan(const Shape& a, const Transform& a_in_mesh);

    // Lowest and highest of n . x over the shape's points x (mesh frame; n unit length).
    void along(const Vec3& n, Real& lo, Real& hi) const;

    // True when the shape lies farther than `speculative` from the plane of triangle v on
    // either side, by more than rounding: the pair test would find no contact with it.
    bool clear_of_plane(const Vec3 (&v)[3], Real speculative) const;
    // The same with the triangle's normal made by triangle_normal already.
    bool clear_of_plane(const Vec3 (&v)[3], const Vec3& n, Real speculative) const;

private:
    ShapeType m_type;
    Vec3 m_center;
    Mat3 m_rotation;
    Vec3 m_core[2];
    Real m_radius = 0;
    Vec3 m_half = Vec3::Zero();
    const ConvexHull* m_hull = nullptr;
};

}  // namespace spindle::detail
