// Ray casts, shape casts and overlap tests against one shape. Each query works in the
// frame of the shape it meets, so hulls, meshes and planes are used as stored; convex
// shapes are swept as a core (point set) plus a radius, the form gjk_distance() takes.
#include "collision/cast.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <utility>

#include <spindle/platform/assert.hpp>

#include "collision/collide.hpp"
#include "collision/compound.hpp"
#include "collision/convex_core.hpp"
#include "collision/convex_hull.hpp"
#include "collision/gjk.hpp"
#include "collision/polyhedron.hpp"
#include "collision/triangle_mesh.hpp"

namespace spindle {
namespace {

constexpr int kMeshStack = 128;            // the mesh tree's depth bound, as in TriangleMesh::query
constexpr int kMaxSweepSteps = 64;         // conservative advancement steps before giving up
constexpr Real kRelativeTolerance = 1e-4;  // of the translation's length
constexpr Real kMaxTolerance = 1e-5;       // m
constexpr Real kMinTolerance = 1e-9;       // m: far above gjk_distance's round-off
constexpr Real kTouching = 1e-12;          // m: below this gjk_distance reports overlap
constexpr Real kParallel = 1e-12;          // |cos| under which a segment lies in a triangle's plane
constexpr Real kSameFeature = 1e-9;        // m: core points this level with the lowest form its feature

// ---- Ray casts -----------------------------------------------------------------------

// The segment a + t d, t in [0, 1], in the frame of the shape it is cast against.
struct Segment {
    Vec3 a;
    Vec3 d;
};

struct LocalHit {
    Real t = kHuge;
    Vec3 normal = Vec3::UnitY();
    std::uint32_t part = 0;
};

// Entry into the ball (c, r); a start inside it is no entry.
bool enter_ball(const Segment& s, const Vec3& c, Real r, LocalHit& hit) {
    const Vec3 m = s.a - c;
    const Real b = m.dot(s.d);
    const Real outside = m.squaredNorm() - r * r;
    if (outside < 0 || b > 0) return false;
    const Real dd = s.d.squaredNorm();
    // The discriminant from the centre's distance to the line, not as b^2 - dd |m|^2: far
    // from the ball those terms cancel (a ray from a billion metres away loses r^2 in
    // |m|^2 and misses, or hits a metre off). The closest point is off by round-off of
    // |m| only (Haines et al., "Precision Improvements for Ray/Sphere Intersection").
    const Vec3 closest = m - (b / dd) * s.d;
    const Real discriminant = dd * (r * r - closest.squaredNorm());
    if (discriminant < 0) return false;
    const Real t = (-b - std::sqrt(discriminant)) / dd;
    if (t > 1) return false;
    hit.t = t;
    hit.normal = (m + t * s.d).normalized();
    return true;
}

// Entry through the side of the infinite cylinder of radius r about the y axis, kept only
// where it lies between the caps (beyond them the cap balls are met first).
bool enter_cylinder_side(const Segment& s, Real h, Real r, LocalHit& hit) {
    const Real dd = s.d.x() * s.d.x() + s.d.z() * s.d.z();
    if (dd == 0) return false;
    const Real b = s.a.x() * s.d.x() + s.a.z() * s.d.z();
    const Real outside = s.a.x() * s.a.x() + s.a.z() * s.a.z() - r * r;
    if (outside < 0 || b > 0) return false;
    // As enter_ball's: from the axis's distance to the line (in x-z), which does not cancel.
    const Real cx = s.a.x() - (b / dd) * s.d.x(), cz = s.a.z() - (b / dd) * s.d.z();
    const Real discriminant = dd * (r * r - (cx * cx + cz * cz));
    if (discriminant < 0) return false;
    const Real t = (-b - std::sqrt(discriminant)) / dd;
    const Vec3 p = s.a + t * s.d;
    if (t > 1 || std::abs(p.y()) > h) return false;
    hit.t = t;
    hit.normal = Vec3(p.x(), 0, p.z()).normalized();
    return true;
}

// The capsule is the union of a finite cylinder and two balls, so the first entry into
// it is the first entry into any of them.
bool ray_capsule(const Segment& s, Real h, Real r, LocalHit& hit) {
    const Vec3 on_axis(0, std::clamp(s.a.y(), -h, h), 0);
    if ((s.a - on_axis).squaredNorm() < r * r) return false;
    LocalHit best;
    LocalHit candidate;
    if (enter_cylinder_side(s, h, r, candidate)) best = candidate;
    for (const Real y : {-h, h}) {
        if (enter_ball(s, Vec3(0, y, 0), r, candidate) && candidate.t < best.t) best = candidate;
    }
    if (best.t == kHuge) return false;
    hit = best;
    return true;
}

// Clips the segment by the face planes: it enters at the last plane it crosses going in,
// unless it has left another before that. Entering before t = 0 means it starts inside.
bool ray_polyhedron(const Segment& s, const detail::PolyView& poly, LocalHit& hit) {
    Real enter = -kHuge;
    Real exit = kHuge;
    const HullFace* entry_face = nullptr;
    for (std::uint32_t f = 0; f < poly.face_count; ++f) {
        const HullFace& face = poly.faces[f];
        const Real outside = face.normal.dot(s.a) - face.offset;
        const Real speed = face.normal.dot(s.d);
        if (speed == 0) {
            if (outside > 0) return false;
            continue;
        }
        const Real t = -outside / speed;
        if (speed < 0 && t > enter) enter = t, entry_face = &face;
        if (speed > 0) exit = std::min(exit, t);
        if (enter > exit) return false;
    }
    if (entry_face == nullptr || enter < 0 || enter > 1) return false;
    hit.t = enter;
    hit.normal = entry_face->normal;
    return true;
}

// The solid is the side behind the normal.
bool ray_plane(const Segment& s, const Shape& plane, LocalHit& hit) {
    const Real outside = plane.normal.dot(s.a) - plane.offset;
    const Real speed = plane.normal.dot(s.d);
    if (outside < 0 || speed >= 0) return false;
    const Real t = -outside / speed;
    if (t > 1) return false;
    hit.t = t;
    hit.normal = plane.normal;
    return true;
}

// Where the segment enters the box, or kHuge when it misses it before max_t.
Real box_entry(const Segment& s, const Aabb& box, Real max_t) {
    Real enter = 0;
    Real exit = max_t;
    for (int i = 0; i < 3; ++i) {
        if (s.d[i] == 0) {
            if (s.a[i] < box.min[i] || s.a[i] > box.max[i]) return kHuge;
            continue;
        }
        Real t0 = (box.min[i] - s.a[i]) / s.d[i];
        Real t1 = (box.max[i] - s.a[i]) / s.d[i];
        if (t0 > t1) std::swap(t0, t1);
        enter = std::max(enter, t0);
        exit = std::min(exit, t1);
        if (enter > exit) return kHuge;
    }
    return enter;
}

// Moller-Trumbore, either side; t is written when the segment crosses the triangle.
bool cross_triangle(const Segment& s, const Vec3& v0, const Vec3& v1, const Vec3& v2, Real& t) {
    const Vec3 e1 = v1 - v0;
    const Vec3 e2 = v2 - v0;
    const Vec3 p = s.d.cross(e2);
    const Real det = e1.dot(p);
    // det is -cos(d, normal) |d| |e1 x e2|: near zero the hit parameter is round-off.
    if (std::abs(det) <= kParallel * s.d.norm() * e1.cross(e2).norm()) return false;
    const Real inverse = 1 / det;
    const Vec3 from_v0 = s.a - v0;
    const Real u = from_v0.dot(p) * inverse;
    if (u < 0 || u > 1) return false;
    const Vec3 q = from_v0.cross(e1);
    const Real v = s.d.dot(q) * inverse;
    if (v < 0 || u + v > 1) return false;
    const Real crossing = e2.dot(q) * inverse;
    if (crossing < 0 || crossing > 1) return false;
    t = crossing;
    return true;
}

void test_leaf(const Segment& s, const TriangleMesh& mesh, const MeshNode& leaf, LocalHit& best) {
    for (std::uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i) {
        const MeshTriangle& tri = mesh.triangles()[i];
        const auto v = mesh.vertices();
        Real t = 0;
        if (!cross_triangle(s, v[tri.v[0]], v[tri.v[1]], v[tri.v[2]], t) || t >= best.t) continue;
        const Vec3 n = mesh.normal(i);
        best = {t, n.dot(s.d) > 0 ? Vec3(-n) : n, i};
    }
}

// Walks the mesh tree nearest child first, skipping boxes entered after the best hit.
bool ray_mesh(const Segment& s, const TriangleMesh& mesh, LocalHit& hit) {
    const auto nodes = mesh.nodes();
    LocalHit best;
    std::uint32_t stack[kMeshStack];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const MeshNode& node = nodes[stack[--top]];
        if (box_entry(s, node.box, std::min(best.t, Real(1))) == kHuge) continue;
        if (node.count > 0) {
            test_leaf(s, mesh, node, best);
            continue;
        }
        SPINDLE_ASSERT(top + 2 <= kMeshStack, "mesh tree deeper than its build allows");
        const Real near = box_entry(s, nodes[node.first].box, 1);
        const Real far = box_entry(s, nodes[node.first + 1].box, 1);
        const bool first_is_nearer = near <= far;
        stack[top++] = first_is_nearer ? node.first + 1 : node.first;
        stack[top++] = first_is_nearer ? node.first : node.first + 1;
    }
    if (best.t == kHuge) return false;
    hit = best;
    return true;
}

bool ray_local(const Shape& shape, const Segment& s, LocalHit& hit);

// The nearest entry into any part, each met in its own frame; a part the segment starts
// inside is not entered, though another may be.
bool ray_compound(const Segment& s, const Compound& compound, LocalHit& hit) {
    bool found = false;
    for (std::uint32_t i = 0; i < compound.size(); ++i) {
        const Transform& pose = compound.pose(i);
        LocalHit local;
        if (!ray_local(compound.shape(i), {pose.apply_inverse(s.a), pose.rotate_inverse(s.d)}, local)) continue;
        if (found && local.t >= hit.t) continue;
        hit = {local.t, pose.rotate(local.normal), i};
        found = true;
    }
    return found;
}

bool ray_local(const Shape& shape, const Segment& s, LocalHit& hit) {
    switch (shape.type) {
        case ShapeType::Sphere: return enter_ball(s, Vec3::Zero(), shape.radius, hit);
        case ShapeType::Capsule: return ray_capsule(s, shape.half_height, shape.radius, hit);
        case ShapeType::Box: return ray_polyhedron(s, detail::BoxPoly(shape.half_extents).view(), hit);
        case ShapeType::ConvexHull: return ray_polyhedron(s, detail::view_of(*shape.hull), hit);
        case ShapeType::Plane: return ray_plane(s, shape, hit);
        case ShapeType::TriangleMesh: return ray_mesh(s, *shape.mesh, hit);
        case ShapeType::Compound: return ray_compound(s, *shape.parts, hit);
        case ShapeType::Count: break;
    }
    return false;
}

// ---- Convex cores --------------------------------------------------------------------

using Core = ConvexCore;

bool pose_is_finite(const Transform& x) { return is_finite(x.p) && is_finite(x.q); }

void make_triangle_core(const TriangleMesh& mesh, std::uint32_t t, Core& core) {
    const MeshTriangle& tri = mesh.triangles()[t];
    for (int k = 0; k < 3; ++k) core.points[k] = mesh.vertices()[tri.v[k]];
    core.count = 3;
    core.radius = 0;
}

bool cores_touch(const Core& a, const Core& b) {
    const detail::GjkResult g = detail::gjk_distance(a.points.data(), a.count, b.points.data(), b.count);
    return g.overlap || g.distance <= a.radius + b.radius + kTouching;
}

Real lowest_along(const Core& core, const Vec3& n) {
    Real lowest = kHuge;
    for (int i = 0; i < core.count; ++i) lowest = std::min(lowest, n.dot(core.points[i]));
    return lowest;
}

// ---- Shape casts ---------------------------------------------------------------------

enum class Sweep { Miss, Hit, Overlap };

Real sweep_tolerance(const Vec3& translation) {
    return std::clamp(kRelativeTolerance * translation.norm(), kMinTolerance, kMaxTolerance);
}

// Conservative advancement of core a along the translation toward core b: the gap along
// the current closest direction bounds the true gap, so each step to half the tolerance
// short of that plane cannot pass through b. The hit's point is on b's surface.
Sweep sweep_cores(const Core& a, const Vec3& translation, const Core& b, Real tolerance, Real max_fraction,
                  CastHit& hit) {
    std::array<Vec3, ConvexCore::kMaxPoints> moved;
    Real t = 0;
    for (int step = 0; step < kMaxSweepSteps; ++step) {
        for (int i = 0; i < a.count; ++i) moved[i] = a.points[i] + t * translation;
        const detail::GjkResult g = detail::gjk_distance(moved.data(), a.count, b.points.data(), b.count);
        const Real gap = g.distance - a.radius - b.radius;
        // After a step, round-off only: the previous step's hit stands.
        if (g.overlap || gap < 0) return step == 0 ? Sweep::Overlap : Sweep::Hit;
        const Vec3 normal = (g.point_a - g.point_b) / g.distance;
        hit = {t, g.point_b + normal * b.radius, normal, 0};
        const Real closing = -translation.dot(normal);
        if (gap <= tolerance) return step > 0 || closing > 0 ? Sweep::Hit : Sweep::Miss;
        // The plane through b's closest point separates the two for as long as a moves away.
        if (closing <= 0) return Sweep::Miss;
        t += (gap - Real(0.5) * tolerance) / closing;
        if (t > max_fraction) return Sweep::Miss;
    }
    return Sweep::Miss;
}

// Fraction 0 with collide()'s deepest contact, the direction of least separation;
// returns that contact's separation (kHuge when collide() finds none).
Real overlap_hit(const Shape& moving, const Transform& start, const Vec3& translation, const Shape& target,
                 const Transform& target_pose, Real tolerance, CastHit& hit) {
    hit.fraction = 0;
    Manifold m;
    if (collide(moving, start, target, target_pose, tolerance, &m, 1) == 0 || m.point_count == 0) {
        hit.normal = translation.squaredNorm() > 0 ? Vec3(-translation.normalized()) : Vec3::UnitY();
        hit.point = start.p;
        return kHuge;
    }
    const ManifoldPoint* deepest = &m.points[0];
    for (int i = 1; i < m.point_count; ++i) {
        if (m.points[i].separation < deepest->separation) deepest = &m.points[i];
    }
    hit.normal = -m.normal;
    hit.point = deepest->point + m.normal * (Real(0.5) * deepest->separation);
    return deepest->separation;
}

// Exact: the gap to a plane falls linearly with the fraction. The point is the middle of
// the core feature lowest along the normal, carried to the plane.
bool sweep_plane(const Core& a, const Vec3& translation, const Shape& plane, CastHit& hit) {
    const Vec3& n = plane.normal;
    const Real lowest = lowest_along(a, n);
    const Real gap = lowest - a.radius - plane.offset;
    const Real closing = -n.dot(translation);
    Real t = 0;
    if (gap > kTouching) {
        if (closing <= 0 || gap > closing) return false;
        t = gap / closing;
    }
    Vec3 sum = Vec3::Zero();
    int count = 0;
    for (int i = 0; i < a.count; ++i) {
        if (n.dot(a.points[i]) <= lowest + kSameFeature) sum += a.points[i], ++count;
    }
    const Vec3 q = sum / count + t * translation;
    hit = {t, q - n * (n.dot(q) - plane.offset), n, 0};
    return true;
}

// Triangle by triangle under the swept bounds, each a two-sided zero-radius core; later
// triangles are only swept up to the best fraction so far. Of several triangles
// overlapping at the start, the one with the deepest contact names the hit.
bool sweep_mesh(const Shape& moving, const Transform& start, const Core& a, const Vec3& translation,
                const TriangleMesh& mesh, Real tolerance, CastHit& hit) {
    const Transform end{start.p + translation, start.q};
    const Aabb swept = moving.bounds(start).merged(moving.bounds(end)).fattened(tolerance);
    bool found = false;
    Real deepest = kHuge;
    Core triangle;
    mesh.query(swept, [&](std::uint32_t t) {
        make_triangle_core(mesh, t, triangle);
        CastHit candidate;
        const Sweep result = sweep_cores(a, translation, triangle, tolerance, found ? hit.fraction : 1, candidate);
        if (result == Sweep::Miss) return;
        if (result == Sweep::Overlap) {
            // A mesh of this one triangle, so collide() reports its contact and no other's.
            const std::uint32_t indices[3] = {0, 1, 2};
            const Shape single = Shape::triangle_mesh(std::span<const Vec3>(triangle.points.data(), 3), indices);
            const Real separation = overlap_hit(moving, start, translation, single, Transform{}, tolerance, candidate);
            if (found && hit.fraction == 0 && separation >= deepest) return;
            deepest = separation;
        } else if (found && candidate.fraction >= hit.fraction) {
            return;
        }
        hit = candidate;
        hit.part = t;
        found = true;
    });
    return found;
}

// The query in the target's frame.
bool shape_cast_local(const Shape& moving, const Transform& start, const Vec3& translation, const Shape& target,
                      CastHit& hit) {
    const Real tolerance = sweep_tolerance(translation);
    Core a;
    make_core(moving, start, a);
    switch (target.type) {
        case ShapeType::Plane: return sweep_plane(a, translation, target, hit);
        case ShapeType::TriangleMesh: return sweep_mesh(moving, start, a, translation, *target.mesh, tolerance, hit);
        case ShapeType::Count: return false;
        default: break;
    }
    Core b;
    make_core(target, Transform{}, b);
    const Sweep result = sweep_cores(a, translation, b, tolerance, 1, hit);
    if (result == Sweep::Overlap) overlap_hit(moving, start, translation, target, Transform{}, tolerance, hit);
    return result != Sweep::Miss;
}

bool mesh_touches(const Shape& a, const Transform& xa, const Core& core, const TriangleMesh& mesh) {
    bool touching = false;
    Core triangle;
    mesh.query(a.bounds(xa).fattened(kTouching), [&](std::uint32_t t) {
        if (touching) return;
        make_triangle_core(mesh, t, triangle);
        touching = cores_touch(core, triangle);
    });
    return touching;
}

}  // namespace

bool ray_cast(const Shape& shape, const Transform& pose, const Vec3& from, const Vec3& to, CastHit& hit) {
    if (!is_finite(from) || !is_finite(to) || !pose_is_finite(pose) || from == to) return false;
    const Vec3 delta = to - from;
    const Segment s{pose.apply_inverse(from), pose.rotate_inverse(delta)};
    LocalHit local;
    if (!ray_local(shape, s, local)) return false;
    hit = {local.t, from + local.t * delta, pose.rotate(local.normal), local.part};
    return true;
}

namespace {

// The first hit of any part (the earliest part on a tie); for the target's parts, `part`
// names the one hit.
template <typename Cast>
bool first_part_hit(const Compound& compound, CastHit& hit, bool name_part, Cast cast) {
    bool found = false;
    for (std::uint32_t i = 0; i < compound.size(); ++i) {
        CastHit candidate;
        if (!cast(compound.shape(i), compound.pose(i), candidate)) continue;
        if (found && candidate.fraction >= hit.fraction) continue;
        hit = candidate;
        if (name_part) hit.part = i;
        found = true;
    }
    return found;
}

bool part_overlaps(const Compound& compound, const Transform& pose, const Shape& other, const Transform& other_pose) {
    for (std::uint32_t i = 0; i < compound.size(); ++i) {
        if (overlaps(compound.shape(i), pose * compound.pose(i), other, other_pose)) return true;
    }
    return false;
}

}  // namespace

bool shape_cast(const Shape& moving, const Transform& start, const Vec3& translation, const Shape& target,
                const Transform& target_pose, CastHit& hit) {
    if (moving.type == ShapeType::Compound && moving.parts) {
        return first_part_hit(*moving.parts, hit, false, [&](const Shape& part, const Transform& pose, CastHit& h) {
            return shape_cast(part, start * pose, translation, target, target_pose, h);
        });
    }
    if (target.type == ShapeType::Compound && target.parts) {
        return first_part_hit(*target.parts, hit, true, [&](const Shape& part, const Transform& pose, CastHit& h) {
            return shape_cast(moving, start, translation, part, target_pose * pose, h);
        });
    }
    if (!is_convex(moving) || target.type >= ShapeType::Count) return false;
    if (!is_finite(translation) || !pose_is_finite(start) || !pose_is_finite(target_pose)) return false;
    const Transform to_target = target_pose.inverse();
    CastHit local;
    if (!shape_cast_local(moving, to_target * start, to_target.rotate(translation), target, local)) return false;
    hit = {local.fraction, target_pose.apply(local.point), target_pose.rotate(local.normal), local.part};
    return true;
}

bool overlaps(const Shape& a, const Transform& pa, const Shape& b, const Transform& pb) {
    if (a.static_only() && b.static_only()) return false;
    if (a.static_only()) return overlaps(b, pb, a, pa);
    if (a.type == ShapeType::Compound && a.parts) return part_overlaps(*a.parts, pa, b, pb);
    if (b.type == ShapeType::Compound && b.parts) return part_overlaps(*b.parts, pb, a, pa);
    if (!pose_is_finite(pa) || !pose_is_finite(pb)) return false;
    const Transform a_in_b = pb.inverse() * pa;
    Core core;
    make_core(a, a_in_b, core);
    switch (b.type) {
        case ShapeType::Plane: return lowest_along(core, b.normal) - core.radius <= b.offset;
        case ShapeType::TriangleMesh: return mesh_touches(a, a_in_b, core, *b.mesh);
        case ShapeType::Count: return false;
        default: break;
    }
    Core other;
    make_core(b, Transform{}, other);
    return cores_touch(core, other);
}

}  // namespace spindle
