// Shapes: immutable geometry shared by bodies. A body's position is its shape's
// origin; mass_properties() says where the centre of mass sits in that frame.
// Factories validate their input and throw spindle::Error naming the field and value.
// Like positions, a shape's geometry stays within a billion metres (1e9 m) of its origin:
// a larger radius, half extent, plane offset, hull point, mesh vertex or compound part
// position is refused (by the factory, or by create_body, set_shape and the queries for
// a shape built by hand), since its bounds and distances would overflow.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include <spindle/engine/math.hpp>

namespace spindle {

class Compound;      // compound.hpp
class ConvexHull;    // convex_hull.hpp
class TriangleMesh;  // triangle_mesh.hpp
struct CompoundPart;

enum class ShapeType : std::uint8_t { Sphere, Capsule, Box, ConvexHull, Plane, TriangleMesh, Compound, Count };

const char* to_string(ShapeType type) noexcept;

struct MassProperties {
    Real mass = 0;
    Vec3 center_of_mass = Vec3::Zero();  // in the shape's frame
    Mat3 inertia = Mat3::Zero();         // about the centre of mass, in the shape's frame
};

struct Shape {
    ShapeType type = ShapeType::Sphere;
    Real radius = 0;                   // sphere, capsule
    Real half_height = 0;              // capsule: segment from (0,-h,0) to (0,h,0)
    Vec3 half_extents = Vec3::Zero();  // box
    Vec3 normal = Vec3::UnitY();       // plane: points x with normal . x = offset (shape frame)
    Real offset = 0;                   // plane
    std::shared_ptr<const ConvexHull> hull;
    std::shared_ptr<const TriangleMesh> mesh;
    std::shared_ptr<const Compound> parts;  // compound

    static Shape sphere(Real radius);
    static Shape capsule(Real half_height, Real radius);
    static Shape box(const Vec3& half_extents);
    // Builds the hull of the points; rejects fewer than 4 points, non-finite points and
    // flat or degenerate sets, naming what was wrong.
    static Shape convex_hull(std::span<const Vec3> points);
    static Shape plane(const Vec3& normal, Real offset);
    // Static only. Rejects out-of-range indices and non-finite vertices; drops
    // zero-area triangles.
    static Shape triangle_mesh(std::span<const Vec3> vertices, std::span<const std::uint32_t> indices);
    // A body made of convex parts (sphere, capsule, box, hull) at poses in this shape's
    // frame; its mass adds up the parts' (overlapping parts count twice). Rejects an empty
    // list, a plane, mesh or compound part, a part of zero volume and a non-finite pose or
    // zero orientation, naming the part; a non-unit orientation is normalised.
    static Shape compound(std::span<const CompoundPart> parts);

    // Plane and triangle mesh can only belong to static bodies.
    bool static_only() const noexcept { return type == ShapeType::Plane || type == ShapeType::TriangleMesh; }
    // World bounds under transform x (a plane's bounds are huge).
    Aabb bounds(const Transform& x) const;
    // Mass, centre of mass and inertia for a uniform density (> 0). Throws for static-only shapes.
    MassProperties mass_properties(Real density) const;
};

// One part of a compound: a convex shape posed in the compound's frame.
struct CompoundPart {
    Shape shape;
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();
};

}  // namespace spindle
