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

// What the last test of a box or hull pair found apart, kept with the contact: the axis
// that separated the two (a face of either, or an edge of each). A pair that stays apart
// is then told so by one support query on that axis instead of a whole SAT. The indices
// are the pair function's (the lower shape type is its A), so a contact always reads its
// own. Only an axis that still separates past the speculative distance ends the test,
// and the whole SAT would have found it too: the result is the same bits with or without.
class FeatureCache {
public:
    enum class Kind : std::uint32_t { None, FaceA, FaceB, EdgePair };
    FeatureCache() = default;
    FeatureCache(Kind kind, std::uint32_t index_a, std::uint32_t index_b)
        : m_bits(static_cast<std::uint32_t>(kind) | (index_a & kIndexMask) << 2 | (index_b & kIndexMask) << 17) {}
    Kind kind() const noexcept { return static_cast<Kind>(m_bits & 3u); }
    std::uint32_t index_a() const noexcept { return m_bits >> 2 & kIndexMask; }
    std::uint32_t index_b() const noexcept { return m_bits >> 17 & kIndexMask; }
    friend bool operator==(FeatureCache, FeatureCache) = default;

private:
    // Four bytes, in a gap of the contact record: a hull has at most 762 edges.
    static constexpr std::uint32_t kIndexMask = (1u << 15) - 1;
    std::uint32_t m_bits = 0;
};

// collide() with the pair's cache, for the narrowphase: box-hull and hull-hull pairs
// read and write it; any other pair clears it.
int collide_cached(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative_distance,
                   Manifold* out, int capacity, FeatureCache& cache);

// The radius of a shape's round part (sphere, capsule; else 0): its surface point along
// any direction is the core's plus this much, so it does not move as the body turns
// about the core (a rolling ball's contact stays below its centre).
inline Real round_radius(const Shape& shape) {
    return shape.type == ShapeType::Sphere || shape.type == ShapeType::Capsule ? shape.radius : 0;
}

}  // namespace spindle
