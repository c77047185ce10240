// Exact shape-level queries the scene queries are built on: a segment against one posed
// shape, a convex shape swept (translated, not turned) against one posed shape, and a
// boolean overlap test. One shape at a time; finding candidate bodies is the caller's.
#pragma once

#include <cstdint>

#include <spindle/engine/math.hpp>
#include <spindle/engine/shape.hpp>

namespace spindle {

struct CastHit {
    Real fraction = 0;            // of the segment or translation, in [0, 1]
    Vec3 point = Vec3::Zero();    // world, on the surface of the shape that was hit
    Vec3 normal = Vec3::UnitY();  // world, unit, from the hit shape toward the caster
    std::uint32_t part = 0;       // triangle index into TriangleMesh::triangles(), part index of a compound; else 0
};

// First point where the segment from -> to enters the shape (posed by `pose`); `hit` is
// written only when this returns true.
// - Solids (sphere, capsule, box, hull, and a plane, whose solid is the side behind its
//   normal): a segment that starts strictly inside gives no hit, as in Jolt and Box2D; one
//   that starts on the surface and goes in hits at fraction 0. Grazing contact is a hit.
// - Triangle meshes are two-sided: the nearest triangle crossed, with the normal turned to
//   face the segment's start. A segment lying in a triangle's plane does not hit it.
// - Compounds: the nearest entry into any part, `part` naming it; a part the segment
//   starts inside is not entered (another may be).
// - A zero-length segment never hits; non-finite from, to or pose gives false.
bool ray_cast(const Shape& shape, const Transform& pose, const Vec3& from, const Vec3& to, CastHit& hit);

// First contact of `moving` (sphere, capsule, box, hull or compound, posed by `start`)
// translated by `translation` against `target` (any shape, posed by `target_pose`); `hit`
// is written only when this returns true. The point is on the target's surface. A
// compound is swept part by part: the first part to hit (the lowest index on a tie)
// gives the hit, and for a compound target `part` names the target's part.
// - Conservative advancement on the GJK distance: the fraction is never past the contact
//   and the gap left there is below the tolerance (1e-4 of the translation's length,
//   clamped to [1e-9, 1e-5] m), so the fraction is short by at most that gap over the
//   closing speed along the normal: a grazing sweep's fraction is the least exact. A
//   plane target is solved exactly. A mesh is met triangle by triangle (two-sided) under
//   the swept bounds; `part` names the triangle.
// - Overlapping at the start (touching counts: a GJK distance within 1e-12 m): fraction 0,
//   with the normal and point of the deepest contact collide() finds, the direction of
//   least separation (if it finds none: against the translation, or +y, and the caster's
//   origin). Apart but within the tolerance: fraction 0 when moving closer, else no hit.
// - A moving plane or mesh, non-finite input, or a sweep not converged within its step
//   limit gives false.
bool shape_cast(const Shape& moving, const Transform& start, const Vec3& translation, const Shape& target,
                const Transform& target_pose, CastHit& hit);

// Whether the two posed shapes share a point: touching counts (GJK distance within
// 1e-12 m, exact for a plane). Two static-only shapes (plane, mesh) give false: they
// never meet in a Space.
bool overlaps(const Shape& a, const Transform& pa, const Shape& b, const Transform& pb);

}  // namespace spindle
