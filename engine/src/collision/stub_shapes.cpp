// TEMPORARY: minimal shapes and collision (sphere, box, plane) so the pipeline runs
// until the narrowphase branch lands; replaced wholesale by engine/src/collision/.
#include <spindle/engine/collision.hpp>
#include <spindle/platform/error.hpp>

namespace spindle {

Shape Shape::sphere(Real radius) {
    if (!(radius > 0) || !std::isfinite(radius)) throw Error("sphere: radius must be positive and finite");
    Shape s;
    s.type = ShapeType::Sphere;
    s.radius = radius;
    return s;
}
Shape Shape::box(const Vec3& half_extents) {
    if (!((half_extents.array() > 0).all()) || !half_extents.allFinite()) throw Error("box: half_extents must be positive");
    Shape s;
    s.type = ShapeType::Box;
    s.half_extents = half_extents;
    return s;
}
Shape Shape::capsule(Real, Real) { throw Error("capsule: not yet"); }
Shape Shape::convex_hull(std::span<const Vec3>) { throw Error("convex hull: not yet"); }
Shape Shape::triangle_mesh(std::span<const Vec3>, std::span<const std::uint32_t>) { throw Error("mesh: not yet"); }
Shape Shape::plane(const Vec3& normal, Real offset) {
    Shape s;
    s.type = ShapeType::Plane;
    s.normal = normal.normalized();
    s.offset = offset;
    return s;
}

Aabb Shape::bounds(const Transform& x) const {
    switch (type) {
        case ShapeType::Sphere: return Aabb::from_center_extents(x.p, Vec3::Constant(radius));
        case ShapeType::Box: {
            const Mat3 r = x.q.toRotationMatrix().cwiseAbs();
            return Aabb::from_center_extents(x.p, r * half_extents);
        }
        default: return Aabb{Vec3::Constant(-1e18), Vec3::Constant(1e18)};
    }
}

MassProperties Shape::mass_properties(Real density) const {
    MassProperties mp;
    if (type == ShapeType::Sphere) {
        mp.mass = density * 4.0 / 3.0 * kPi * radius * radius * radius;
        mp.inertia = Mat3::Identity() * (0.4 * mp.mass * radius * radius);
    } else if (type == ShapeType::Box) {
        const Vec3 e = 2 * half_extents;
        mp.mass = density * e.x() * e.y() * e.z();
        mp.inertia = (Vec3(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(), e.x() * e.x() + e.y() * e.y()) *
                      (mp.mass / 12))
                         .asDiagonal();
    } else {
        throw Error("mass_properties: static-only shape");
    }
    return mp;
}

namespace {

int sphere_sphere(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real spec, Manifold* out) {
    const Vec3 d = xb.p - xa.p;
    const Real dist = d.norm();
    const Real sep = dist - a.radius - b.radius;
    if (sep > spec) return 0;
    const Vec3 n = dist > 1e-12 ? Vec3(d / dist) : Vec3::UnitY();
    out->normal = n;
    out->point_count = 1;
    out->points[0] = {xa.p + n * (a.radius + 0.5 * sep), sep, 0};
    return 1;
}

// a is the plane.
int plane_convex(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real spec, Manifold* out) {
    const Vec3 n = xa.rotate(a.normal);
    const Real offset = a.offset + n.dot(xa.p);
    out->normal = n;
    out->point_count = 0;
    if (b.type == ShapeType::Sphere) {
        const Real sep = n.dot(xb.p) - offset - b.radius;
        if (sep > spec) return 0;
        out->points[0] = {xb.p - n * (b.radius + 0.5 * sep), sep, 0};
        out->point_count = 1;
        return 1;
    }
    if (b.type == ShapeType::Box) {
        for (std::uint32_t corner = 0; corner < 8; ++corner) {
            const Vec3 local((corner & 1) ? b.half_extents.x() : -b.half_extents.x(),
                             (corner & 2) ? b.half_extents.y() : -b.half_extents.y(),
                             (corner & 4) ? b.half_extents.z() : -b.half_extents.z());
            const Vec3 p = xb.apply(local);
            const Real sep = n.dot(p) - offset;
            if (sep > spec || out->point_count == kMaxManifoldPoints) continue;
            out->points[out->point_count++] = {p - n * (0.5 * sep), sep, corner};
        }
        return out->point_count > 0 ? 1 : 0;
    }
    return 0;
}

}  // namespace

int collide(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real spec, Manifold* out, int) {
    if (a.type == ShapeType::Sphere && b.type == ShapeType::Sphere) return sphere_sphere(a, xa, b, xb, spec, out);
    if (a.type == ShapeType::Plane) return plane_convex(a, xa, b, xb, spec, out);
    if (b.type == ShapeType::Plane) {
        const int n = plane_convex(b, xb, a, xa, spec, out);
        if (n) out->normal = -out->normal;
        return n;
    }
    return 0;
}

}  // namespace spindle
