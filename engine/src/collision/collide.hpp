// Narrowphase contract: contact manifolds between two posed shapes, dispatched through
// a table of pair functions filled once (no virtual call per pair).
#pragma once

#include <cstdint>

#include <spindle/engine/math.hpp>
#include <spindle/engine/shape.hpp>

namespace spindle {

inline constexpr int kMaxManifoldPoints = 4;

struct ManifoldPoint {
    Vec3 point = Vec3::Zero();  // world, midway between the two surfaces
    Real separation = 0;        // signed distance along the normal; negative = penetration
    std::uint32_t id = 0;       // feature id: the same touching features give the same id every step
};

struct Manifold {
    Vec3 normal = Vec3::UnitY();  // world, unit length, pointing from shape A to shape B
    ManifoldPoint points[kMaxManifoldPoints];
    int point_count = 0;
    // The parts that touch when a shape is a compound (their indices in it); else 0.
    std::uint32_t part_a = 0, part_b = 0;
};

// Writes the manifolds of a (posed by xa) against b (posed by xb) into out[0..capacity)
// and returns how many. Points are produced while the shapes are closer than
// `speculative_distance` (speculative contacts have separation > 0). Convex pairs give
// at most one manifold; a triangle mesh may give several (one per distinct normal, the
// deepest four), a compound one (or a mesh's several) per touching part pair, in part
// order, the deepest `capacity` of them when more touch.
// Any order of shape types is accepted; normals always point from a to b.
int collide(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative_distance,
            Manifold* out, int capacity);

// The radius of a shape's round part (sphere, capsule; else 0): its surface point along
// any direction is the core's plus this much, so it does not move as the body turns
// about the core (a rolling ball's contact stays below its centre).
inline Real round_radius(const Shape& shape) {
    return shape.type == ShapeType::Sphere || shape.type == ShapeType::Capsule ? shape.radius : 0;
}

}  // namespace spindle
