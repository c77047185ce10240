// Narrowphase contract: contact manifolds between two posed shapes, dispatched through
// a table of pair functions filled once (no virtual call per pair).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

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

// The manifold's least separation: its deepest point's (kHuge when it has none).
inline Real deepest(const Manifold& m) {
    Real d = kHuge;
    for (int i = 0; i < m.point_count; ++i) d = std::min(d, m.points[i].separation);
    return d;
}

// A compound's parts' world boxes under the pose it is collided at, as Compound::bounds
// writes them (the broadphase's), for a and b; empty where not at hand (the walk makes them).
struct PartBoxes {
    std::span<const Aabb> a, b;
};

// The two bodies' motion, for a compound pair with more touching part pairs than room: the
// manifolds kept are those that would be deepest after a step at these velocities, so that
// a part coming down fast is not dropped for parts already resting (a long body lying down
// about its landed end). World frame; centres are the centres of mass.
struct PairMotion {
    Vec3 centre_a, v_a, w_a;
    Vec3 centre_b, v_b, w_b;
    Real dt = 0;

    // The same motion with a and b swapped.
    PairMotion swapped() const { return {centre_b, v_b, w_b, centre_a, v_a, w_a, dt}; }
};

// Writes the manifolds of a (posed by xa) against b (posed by xb) into out[0..capacity)
// and returns how many. Points are produced while the shapes are closer than
// `speculative_distance` (speculative contacts have separation > 0). Convex pairs give
// at most one manifold; a triangle mesh may give several (one per distinct normal, the
// deepest four), a compound one (or a mesh's several) per touching part pair, in part
// order, the deepest `capacity` of them when more touch (the deepest a step ahead, when
// `motion` is given).
// Any order of shape types is accepted; normals always point from a to b. A compound's
// walk takes its part boxes from `boxes` where given: the same boxes, not made again.
int collide(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative_distance,
            Manifold* out, int capacity, const PartBoxes& boxes = {}, const PairMotion* motion = nullptr);

// What the last whole test of a box or hull pair decided on, kept with the contact (the
// idea of Box3D's b3SATCache): the feature whose axis separated the two or made their
// manifold (a face of either, or an edge of each) and the separation along that axis then.
// The indices are the pair function's (the lower shape type is its A), so a contact always
// reads its own. Next time one query on that axis comes first:
// - still apart past the speculative distance: apart, as the whole SAT would find too (the
//   same bits with or without the cache);
// - else, while the separation along the axis is within `feature_slop` of the one kept and
//   the feature still makes a contact (the face's clipped points within reach, the two
//   edges still crossing), the manifold is built from that feature alone. It may then not
//   be the SAT's best axis any more: the pair has moved less than a slop along it, which
//   the solver allows as penetration anyway, and the whole SAT runs once it has moved more.
class FeatureCache {
public:
    enum class Kind : std::uint32_t { None, FaceA, FaceB, EdgePair };
    FeatureCache() = default;
    FeatureCache(Kind kind, std::uint32_t index_a, std::uint32_t index_b, float separation = 0)
        : m_bits(static_cast<std::uint32_t>(kind) | (index_a & kIndexMask) << 2 | (index_b & kIndexMask) << 17),
          m_separation(separation) {}
    Kind kind() const noexcept { return static_cast<Kind>(m_bits & 3u); }
    std::uint32_t index_a() const noexcept { return m_bits >> 2 & kIndexMask; }
    std::uint32_t index_b() const noexcept { return m_bits >> 17 & kIndexMask; }
    // Along the feature's axis when the whole SAT chose it (negative: overlapping).
    float separation() const noexcept { return m_separation; }
    friend bool operator==(FeatureCache, FeatureCache) = default;

private:
    // Eight bytes, in every contact record: a hull has at most 762 edges, and a float
    // tells a slop (millimetres) apart from metres.
    static constexpr std::uint32_t kIndexMask = (1u << 15) - 1;
    std::uint32_t m_bits = 0;
    float m_separation = 0;
};

// One mesh triangle's FeatureCache against a box or hull, whole or a compound's part: a
// shape against a mesh meets many triangles, each a pair of its own to the SAT (the idea of
// Box3D's mesh contact, which keeps its triangles' caches between steps).
struct TriangleFeature {
    std::uint32_t part = 0;      // the compound part (0 for a whole shape)
    std::uint32_t triangle = 0;  // its index in the mesh
    FeatureCache feature;
};
// A contact's triangle features from its last collide, sorted by part, then triangle.
using TriangleFeatures = std::vector<TriangleFeature>;

// A shape's (or compound part's) mesh query kept across steps, as Box3D keeps its mesh
// contact's query bounds (b3RefreshCache): `box` is the query box it was made for, in the
// mesh's frame, enlarged so that a part resting or rocking in place stays inside it; the
// triangles whose bounds overlap it are MeshQueries::triangles[first, first + count), in
// increasing index. While a later query box lies inside `box`, its triangles are these,
// filtered by the same overlap test: the mesh is not queried again.
// A compound's part also keeps the manifolds it was last collided with (before the ranking
// chose among the parts'), as Box3D keeps each shape's contact: while the part's own points
// have moved less than the recycle distance since, they stand for a collide (recycled, moved
// with the part), whatever the body's other parts do. `centre` is then the part's centre in
// the world and `turn` its body's orientation when collided, and its manifolds (normals from
// the mesh to the part) are MeshQueries::manifolds[first_manifold, + manifold_count).
struct MeshQuery {
    std::uint32_t part = 0;
    std::uint32_t first = 0, count = 0;
    Aabb box;
    bool has_manifolds = false;
    std::uint32_t first_manifold = 0, manifold_count = 0;
    Vec3 centre = Vec3::Zero();
    Quat turn = Quat::Identity();
};
// A contact's mesh queries from its last collide, sorted by part, and the mesh they were
// made on (a contact's mesh stays its own, but a query on another would be wrong), at
// `pose` (a part's manifolds are kept in the world: they stand only while it stays).
struct MeshQueries {
    const void* mesh = nullptr;
    Transform pose;
    std::vector<MeshQuery> parts;
    std::vector<std::uint32_t> triangles;
    std::vector<Manifold> manifolds;
    std::uint32_t parts_collided = 0, parts_recycled = 0;  // by the last collide of a compound
};

// collide() with the pair's caches, for the narrowphase: box-hull and hull-hull pairs
// read and write `cache`; a box, hull or compound against a triangle mesh reads and
// rewrites `triangles` (the triangles it met this time, each with its feature); any other
// pair clears what it does not use. `feature_slop`: how far the separation along a cached
// touching feature may drift before the whole SAT runs again (the solver's linear slop;
// 0 never reuses a touching feature). `boxes` and `motion` as for collide(). `queries`,
// when given, keeps a mesh pair's mesh queries across calls (the same manifolds as
// without); null queries the mesh every call. With queries and a `recycle_distance` over
// 0, a compound's part against a mesh whose points have moved less than that since its
// manifolds were made keeps them (part_recycles), moved with it, instead of a collide.
int collide_cached(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative_distance,
                   Manifold* out, int capacity, FeatureCache& cache, TriangleFeatures& triangles, Real feature_slop,
                   const PartBoxes& boxes = {}, const PairMotion* motion = nullptr, MeshQueries* queries = nullptr,
                   Real recycle_distance = 0);

// Box3D's a x b with both crossed terms added: with a = |omega| (or a turn's |sin(angle / 2)
// axis|) and b a body's reach along the same axes, a bound on its farthest point's speed
// (or half its swing) per axis: a long body turning about its length counts its girth.
inline Vec3 modified_cross(const Vec3& a, const Vec3& b) {
    return {a.y() * b.z() + a.z() * b.y(), a.z() * b.x() + a.x() * b.z(), a.x() * b.y() + a.y() * b.x()};
}

// How far a turn may move a body's points along a manifold's normal, relative to its centre,
// before the manifold no longer stands for the pair (tilt_reach), in linear slops: half, so
// that no point of the body has come nearer the other shape than the manifold's points
// have by more than the slop.
inline constexpr Real kRecycleTiltSlops = 0.5;

// How far a body's turn since its manifold was collided can have moved any of its points
// along the manifold's normal n (world) relative to its centre: `turn` the body's turn in the
// world (then to now; |vec| = sin(angle / 2)), `then` its orientation when collided, its
// points within `reach` of its centre along each of its own axes. Only the turn's part
// about axes in the contact plane (its tilt t, of vec v = t + (v.n)n) moves a point along
// n: n.(turn r - r) = 2w n.(t x r) + 2(v.n)(t.r) - 2(n.r)|t|^2, bounded term by term, the
// first as Box3D's modified cross bounds |t x r|. A body spinning about the normal (a box
// turning where it lies) tilts nothing.
inline Real tilt_reach(const Quat& turn, const Quat& then, const Vec3& reach, const Vec3& n) {
    const Vec3 v = turn.vec();
    const Real along = v.dot(n);
    const Vec3 t = v - along * n;
    const Vec3 local = (then.conjugate() * t).cwiseAbs();
    return 2 * (std::abs(turn.w()) * modified_cross(local, reach).norm() + std::abs(along) * local.dot(reach) +
                t.squaredNorm() * reach.norm());
}

// Whether `turn` can have moved a point within `reach` of the centre `tolerance` along some
// normal: tilt_reach's bound for any normal, 4 |sin(angle / 2)| |reach| (squared). A resting
// body's turn is far below it, and no manifold need be asked.
inline bool may_tilt(const Quat& turn, const Vec3& reach, Real tolerance) {
    return 16 * turn.vec().squaredNorm() * reach.squaredNorm() >= tolerance * tolerance;
}

// Contact recycling keeps manifolds only while neither body has turned more than 10 degrees
// since they were made (their normals stay fixed in the world): cos(5 degrees)^2 against
// the square of the turn's quaternion's scalar part.
inline constexpr Real kRecycleCosHalfAngleSq = 0.99240388;

// The radius of a shape's round part (sphere, capsule; else 0): its surface point along
// any direction is the core's plus this much, so it does not move as the body turns
// about the core (a rolling ball's contact stays below its centre).
inline Real round_radius(const Shape& shape) {
    return shape.type == ShapeType::Sphere || shape.type == ShapeType::Capsule ? shape.radius : 0;
}

}  // namespace spindle
