// Shape factories (with input validation), world bounds and mass properties. Closed
// forms for the primitives; hulls integrate their polyhedron (see convex_hull.cpp).
#include "collision/convex_hull.hpp"

#include <spindle/engine/shape.hpp>
#include <spindle/platform/error.hpp>

#include "collision/compound.hpp"
#include "collision/error_text.hpp"
#include "collision/triangle_mesh.hpp"

namespace spindle {
namespace {

using detail::to_text;

void require_positive(const char* shape, const char* field, Real value) {
    if (!(is_finite(value) && value > 0)) {
        throw Error(std::string(shape) + ": " + field + " must be positive and finite, got " + to_text(value));
    }
}

void require_finite(const char* shape, const char* field, Real value) {
    if (!is_finite(value)) throw Error(std::string(shape) + ": " + field + " must be finite, got " + to_text(value));
}

void require_density(Real density) {
    if (!(is_finite(density) && density > 0)) {
        throw Error("mass properties: density must be positive and finite, got " + to_text(density));
    }
}

// Bounds of a box with half extents e, posed by x: the extents of a rotated box are
// |R| e, exact for boxes and a cheap over-estimate for anything inside them.
Aabb rotated_box_bounds(const Transform& x, const Vec3& center, const Vec3& e) {
    const Mat3 r = x.q.toRotationMatrix();
    return Aabb::from_center_extents(x.apply(center), r.cwiseAbs() * e);
}

Aabb plane_bounds(const Shape& s, const Transform& x) {
    // A plane is unbounded, except along its normal when that is a world axis: then
    // the solid half-space ends at the plane, which lets a static tree cull by it.
    Aabb box{Vec3::Constant(-kHuge), Vec3::Constant(kHuge)};
    const Vec3 n = x.rotate(s.normal);
    const Vec3 on_plane = x.apply(s.normal * s.offset);
    for (int i = 0; i < 3; ++i) {
        if (n[i] == 1) box.max[i] = on_plane[i];
        if (n[i] == -1) box.min[i] = on_plane[i];
    }
    return box;
}

}  // namespace

Shape Shape::sphere(Real radius) {
    require_positive("sphere", "radius", radius);
    Shape s;
    s.type = ShapeType::Sphere;
    s.radius = radius;
    return s;
}

Shape Shape::capsule(Real half_height, Real radius) {
    require_positive("capsule", "half_height", half_height);
    require_positive("capsule", "radius", radius);
    Shape s;
    s.type = ShapeType::Capsule;
    s.half_height = half_height;
    s.radius = radius;
    return s;
}

Shape Shape::box(const Vec3& half_extents) {
    require_positive("box", "half_extents.x", half_extents.x());
    require_positive("box", "half_extents.y", half_extents.y());
    require_positive("box", "half_extents.z", half_extents.z());
    Shape s;
    s.type = ShapeType::Box;
    s.half_extents = half_extents;
    return s;
}

Shape Shape::convex_hull(std::span<const Vec3> points) {
    Shape s;
    s.type = ShapeType::ConvexHull;
    s.hull = std::make_shared<const ConvexHull>(points);
    return s;
}

Shape Shape::plane(const Vec3& normal, Real offset) {
    const Real length = normal.norm();
    if (!is_finite(normal) || !(length > 0)) {
        throw Error("plane: normal must be finite and non-zero, got " + to_text(normal));
    }
    require_finite("plane", "offset", offset);
    Shape s;
    s.type = ShapeType::Plane;
    // normal . x = offset describes the same plane after dividing both sides by |normal|.
    s.normal = normal / length;
    s.offset = offset / length;
    return s;
}

Shape Shape::triangle_mesh(std::span<const Vec3> vertices, std::span<const std::uint32_t> indices) {
    Shape s;
    s.type = ShapeType::TriangleMesh;
    s.mesh = std::make_shared<const TriangleMesh>(vertices, indices);
    return s;
}

Shape Shape::compound(std::span<const CompoundPart> parts) {
    Shape s;
    s.type = ShapeType::Compound;
    s.parts = std::make_shared<const Compound>(parts);
    return s;
}

Aabb Shape::bounds(const Transform& x) const {
    switch (type) {
        case ShapeType::Sphere: return Aabb::from_center_extents(x.p, Vec3::Constant(radius));
        case ShapeType::Capsule: {
            const Vec3 axis = x.rotate(Vec3(0, half_height, 0));
            const Vec3 extents = axis.cwiseAbs() + Vec3::Constant(radius);
            return Aabb::from_center_extents(x.p, extents);
        }
        case ShapeType::Box: return rotated_box_bounds(x, Vec3::Zero(), half_extents);
        // Exact: hulls are small, and tight bounds save broadphase pairs.
        case ShapeType::ConvexHull: return hull->bounds(x);
        case ShapeType::Plane: return plane_bounds(*this, x);
        case ShapeType::TriangleMesh: {
            const Aabb& local = mesh->local_bounds();
            return rotated_box_bounds(x, local.center(), local.extents());
        }
        case ShapeType::Compound: return parts->bounds(x);
        case ShapeType::Count: break;
    }
    return {};
}

MassProperties Shape::mass_properties(Real density) const {
    if (static_only()) {
        throw Error(std::string(to_string(type)) + ": a static-only shape has no mass properties");
    }
    require_density(density);
    MassProperties mp;
    switch (type) {
        case ShapeType::Sphere: {
            const Real r2 = radius * radius;
            mp.mass = density * Real(4) / 3 * kPi * r2 * radius;
            mp.inertia = Mat3::Identity() * (Real(2) / 5 * mp.mass * r2);
            break;
        }
        case ShapeType::Capsule: {
            // Cylinder of height 2h plus two hemispheres; each hemisphere's inertia about a
            // transverse axis is moved from its own centre of mass (3r/8 from the flat face).
            const Real r = radius;
            const Real h = half_height;
            const Real r2 = r * r;
            const Real m_cylinder = density * kPi * r2 * (2 * h);
            const Real m_spheres = density * Real(4) / 3 * kPi * r2 * r;
            mp.mass = m_cylinder + m_spheres;
            const Real axial = m_cylinder * r2 / 2 + m_spheres * Real(2) / 5 * r2;
            const Real transverse = m_cylinder * (r2 / 4 + h * h / 3) +
                                    m_spheres * (Real(2) / 5 * r2 + h * h + Real(3) / 4 * h * r);
            mp.inertia = Vec3(transverse, axial, transverse).asDiagonal();
            break;
        }
        case ShapeType::Box: {
            const Vec3 s2 = half_extents.cwiseProduct(half_extents);
            mp.mass = density * 8 * half_extents.prod();
            mp.inertia = (Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()) * (mp.mass / 3)).asDiagonal();
            break;
        }
        case ShapeType::ConvexHull: {
            mp.mass = density * hull->volume();
            mp.center_of_mass = hull->centroid();
            const Mat3& c = hull->covariance();
            mp.inertia = density * (c.trace() * Mat3::Identity() - c);
            break;
        }
        case ShapeType::Compound: return parts->mass_properties(density);
        default: break;
    }
    return mp;
}

}  // namespace spindle
