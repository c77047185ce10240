// Continuous stage: the bodies the solver listed (moved far for their size this step, or
// flagged `fast`) get a swept test against static geometry after the solver has moved
// them. Speculative contacts reach only as far as the linear closing speed, so a
// fast-spinning body's far end can sweep through a thin wall or a mesh within one step;
// conservative advancement on GJK distances (translation plus angle times the farthest
// reach) finds the first time of impact and stops the body there. Box3D's choice
// (b3FinalizeBodiesTask, b3SolveContinuous): static geometry only, shape by shape.
#include <algorithm>
#include <cmath>

#include <spindle/platform/assert.hpp>

#include "collision/compound.hpp"
#include "collision/convex_core.hpp"
#include "collision/convex_hull.hpp"
#include "collision/gjk.hpp"
#include "collision/triangle_mesh.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/continuous.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

constexpr int kMaxIterations = 32;

// The body's motion through the step: centre of mass along a segment, orientation by slerp.
struct BodyPath {
    Vec3 x0, x1;  // centre of mass
    Quat q0, q1;
    Vec3 local_com;
    Vec3 moved;  // x1 - x0
    // The turn from q0 to q1 as an angle times its axis, in the body's frame, each
    // coordinate's size: a point at r in that frame moves at most |turn x r| as the body
    // turns about that fixed axis, bounded per axis by modified_cross(turn, |r|).
    Vec3 turn;
    Transform start, end;  // at(0), at(1)
    Transform at(Real t) const {
        const Quat q = q0.slerp(t, q1);
        return {x0 + t * moved - q * local_com, q};
    }
};

// The box of the segment from a to b, fattened by margin: what a point within margin of
// something moving from a to b can touch.
Aabb segment_box(const Vec3& a, const Vec3& b, Real margin) {
    return Aabb{a.cwiseMin(b), a.cwiseMax(b)}.fattened(margin);
}

// A convex part of the body (or its whole convex shape) as a core in the body's shape frame.
struct SweptPart {
    ConvexCore core;
    Vec3 centre = Vec3::Zero();
    Real half_size = 0;  // the farthest core point from the centre, plus the radius
    Real thinnest = 0;
    Real swing = 0;  // the most any point of the part moves as the body turns about its centre of mass
    Real spin = 0;   // the most any point of the part moves as it turns about its own centre
};

// Part `shape` posed by `pose` in the body's frame, swept along `path`; `thinnest` is the
// shape's thinnest_half_size.
void make_part(const Shape& shape, const Transform& pose, const BodyPath& path, Real thinnest, SweptPart& part) {
    make_core(shape, pose, part.core);
    part.centre = pose.apply(shape.type == ShapeType::ConvexHull ? shape.hull->centroid() : Vec3::Zero());
    Vec3 from_com = Vec3::Zero();
    Vec3 from_centre = Vec3::Zero();
    Real half = 0;
    for (int i = 0; i < part.core.count; ++i) {
        from_com = from_com.cwiseMax((part.core.points[i] - path.local_com).cwiseAbs());
        from_centre = from_centre.cwiseMax((part.core.points[i] - part.centre).cwiseAbs());
        half = std::max(half, (part.core.points[i] - part.centre).squaredNorm());
    }
    part.half_size = std::sqrt(half) + part.core.radius;
    part.thinnest = thinnest;
    part.swing = modified_cross(path.turn, from_com + Vec3::Constant(part.core.radius)).norm();
    // The rounding turns onto itself about the core: a ball's spin moves none of its surface.
    part.spin = modified_cross(path.turn, from_centre).norm();
}

void pose_core(const ConvexCore& local, const Transform& x, ConvexCore& out) {
    for (int i = 0; i < local.count; ++i) out.points[i] = x.apply(local.points[i]);
    out.count = local.count;
    out.radius = local.radius;
}

// The least separation between two shapes and its direction, from the swept one toward
// the static one (-kHuge: the cores overlap).
struct Gap {
    Real distance = kHuge;
    Vec3 normal = Vec3::UnitY();
};

Gap core_gap(const ConvexCore& a, const Vec3* b, int b_count, Real b_radius) {
    const detail::GjkResult g = detail::gjk_distance(a.points.data(), a.count, b, b_count);
    if (g.overlap) return {-kHuge, Vec3::UnitY()};
    return {g.distance - a.radius - b_radius, (g.point_b - g.point_a) / g.distance};
}

// First time of impact in [0, before) of the swept part against one static target whose
// gap to the part at a pose of the body gap_at(pose, target, reach) gives (it may return
// any gap under `target` as soon as it finds one: that ends the sweep; and it may forget
// for good what lies farther than `reach`, more than any point of the part can move in
// the rest of the sweep); `before` when none. A part touching it at the start is left to
// the contacts.
template <typename GapAt>
Real time_of_impact(const BodyPath& path, const SweptPart& part, Real target, Real before, GapAt&& gap_at) {
    Real t = 0;
    for (int iter = 0; iter < kMaxIterations; ++iter) {
        const Real reach = (before - t) * (path.moved.norm() + part.swing) + target;
        const Gap gap = gap_at(path.at(t), target, reach);
        if (gap.distance < target) return iter == 0 ? before : t;  // touching at the start: contacts handle it
        const Real bound = std::max(Real(0), path.moved.dot(gap.normal)) + part.swing;
        if (bound < 1e-12) return before;            // not closing in
        t += (gap.distance - 0.5 * target) / bound;  // the surfaces cannot meet before this
        if (t >= before) return before;
    }
    return t;
}

// Whether the static body `wall` stops nothing the body i meets: a sensor, or filtered out.
bool passes_through(const World& world, std::uint32_t i, std::uint32_t wall) {
    return world.bodies.traits[wall].sensor || filter_blocks_pair(world, i, wall);
}

// How far the core's lowest point along the unit normal n lies above the plane through v
// (negative: below): no triangle in that plane is nearer.
Real height_above(const ConvexCore& core, const Vec3& n, const Vec3& v) {
    Real lowest = kHuge;
    for (int i = 0; i < core.count; ++i) lowest = std::min(lowest, n.dot(core.points[i]));
    return lowest - core.radius - n.dot(v);
}

Aabb box_of(const ConvexCore& core) {
    Aabb box;
    for (int i = 0; i < core.count; ++i) box = box.merged({core.points[i], core.points[i]});
    return box.fattened(core.radius);
}

// A lower bound on the gap between the core (its box: core_box) and a mesh triangle (its
// corners, then its normal): the height of the core above the triangle's plane, or the gap
// between their boxes.
Real gap_bound(const ConvexCore& core, const Aabb& core_box, const std::array<Vec3, 4>& tri) {
    const Vec3 lo = tri[0].cwiseMin(tri[1]).cwiseMin(tri[2]), hi = tri[0].cwiseMax(tri[1]).cwiseMax(tri[2]);
    const Vec3 apart = (lo - core_box.max).cwiseMax(core_box.min - hi).cwiseMax(Vec3::Zero());
    return std::max(height_above(core, tri[3], tri[0]), apart.norm());
}

// Whether the part, its centre h0 in front of a plane at the start of the step and h1 at
// its end, cannot pass through the plane: no point of it comes nearer than half its
// thinnest half-size within the step (its centre's approach plus its turn about its
// centre) and its centre ends farther in front than that. What it can sink into the plane
// in a step is less than that half, and the contacts push it out; sweeping it would stop
// a body settling onto a floor while it rolls or slides fast short of where the solver put
// it. Box3D's early out for parallel movement (b3MeshTimeOfImpactFcn) measures the centre
// alone, and so would let a spinning pole's end through.
bool stays_in_front(const SweptPart& part, Real h0, Real h1) {
    const Real shallow = Real(0.5) * part.thinnest;
    return h1 > shallow && h0 - h1 + part.spin < shallow;
}

// The part against a triangle mesh posed by xw. The triangles are gathered once, under
// the box the part can reach from its start: those whose plane has the part's centre
// behind it at the start are left out (Box3D's b3CollideTriangleAndHull culls so, and
// collide_mesh.cpp gives a shape with its centre behind no contact from a triangle it lies
// across), and so are those whose plane it stays in front of (stays_in_front) or cannot
// reach within the step.
// At each pose the triangle nearest by a cheap bound (its plane's distance, or its box's
// from the part's) is measured first; a triangle whose bound is no nearer than the best
// gap found is not measured at all.
Real sweep_against_mesh(const BodyPath& path, const SweptPart& part, const TriangleMesh& mesh, const Transform& xw,
                        Real target, Real before, SweepScratch& scratch) {
    const Transform to_mesh = xw.inverse();
    ConvexCore posed;
    pose_core(part.core, to_mesh * path.start, posed);
    Aabb core_box = box_of(posed);
    const Vec3 c0 = to_mesh.apply(path.start.apply(part.centre));
    const Vec3 c1 = to_mesh.apply(path.end.apply(part.centre));
    const Real travel = path.moved.norm() + part.swing + target;
    // gap_bound keeps no triangle whose box lies farther than `travel` from the core's, so
    // the mesh is asked only for that box (a hair more, for the boxes' rounding) within the
    // part's swept box about its centre: the same triangles kept, far fewer met.
    const Real hair = Real(1e-9) * (1 + travel + core_box.min.cwiseAbs().cwiseMax(core_box.max.cwiseAbs()).maxCoeff());
    const Aabb near = core_box.fattened(travel + hair), swept = segment_box(c0, c1, part.half_size + travel);
    const Aabb box{near.min.cwiseMax(swept.min), near.max.cwiseMin(swept.max)};
    std::vector<std::array<Vec3, 4>>& triangles = scratch.triangles;
    triangles.clear();
    mesh.query(box, [&](std::uint32_t t) {
        const MeshTriangle& tri = mesh.triangles()[t];
        const std::array<Vec3, 4> corners{mesh.vertices()[tri.v[0]], mesh.vertices()[tri.v[1]],
                                          mesh.vertices()[tri.v[2]], mesh.normal(t)};
        const Real h0 = corners[3].dot(c0 - corners[0]);
        if (h0 < 0 || stays_in_front(part, h0, corners[3].dot(c1 - corners[0]))) return;
        if (gap_bound(posed, core_box, corners) > travel) return;
        triangles.push_back(corners);
    });
    if (triangles.empty()) return before;
    std::vector<Real>& heights = scratch.heights;
    heights.resize(triangles.size());
    return time_of_impact(path, part, target, before, [&](const Transform& pose, Real touching, Real reach) {
        pose_core(part.core, to_mesh * pose, posed);
        core_box = box_of(posed);
        // Triangles out of reach for the rest of the sweep are dropped, the others kept in order.
        std::size_t kept = 0;
        for (std::size_t k = 0; k < triangles.size(); ++k) {
            const Real h = gap_bound(posed, core_box, triangles[k]);
            if (h > reach) continue;
            triangles[kept] = triangles[k];
            heights[kept++] = h;
        }
        triangles.resize(kept);
        if (kept == 0) return Gap{};
        const auto nearest =
            static_cast<std::size_t>(std::min_element(heights.begin(), heights.begin() + kept) - heights.begin());
        Gap best = core_gap(posed, triangles[nearest].data(), 3, 0);
        for (std::size_t k = 0; k < triangles.size() && best.distance >= touching; ++k) {
            if (k == nearest || heights[k] >= best.distance) continue;
            const Gap gap = core_gap(posed, triangles[k].data(), 3, 0);
            if (gap.distance < best.distance) best = gap;
        }
        best.normal = xw.rotate(best.normal);
        return best;
    });
}

// The part against one static shape (posed by xw) of the body `wall`; `before` when it
// meets none of it before then.
Real sweep_against(const BodyPath& path, const SweptPart& part, const Shape& wall, const Transform& xw, Real target,
                   Real before, SweepScratch& scratch) {
    ConvexCore posed;
    switch (wall.type) {
        case ShapeType::Plane: {
            const Vec3 n = xw.rotate(wall.normal);
            const Real offset = wall.offset + n.dot(xw.p);
            const Real h0 = n.dot(path.start.apply(part.centre)) - offset;
            if (stays_in_front(part, h0, n.dot(path.end.apply(part.centre)) - offset)) return before;
            return time_of_impact(path, part, target, before, [&](const Transform& pose, Real, Real) {
                Real lowest = kHuge;
                for (int i = 0; i < part.core.count; ++i)
                    lowest = std::min(lowest, n.dot(pose.apply(part.core.points[i])));
                return Gap{lowest - part.core.radius - offset, -n};
            });
        }
        case ShapeType::TriangleMesh: return sweep_against_mesh(path, part, *wall.mesh, xw, target, before, scratch);
        case ShapeType::Compound: {
            const Compound& parts = *wall.parts;
            for (std::uint32_t p = 0; p < parts.size(); ++p) {
                before = sweep_against(path, part, parts.shape(p), xw * parts.pose(p), target, before, scratch);
            }
            return before;
        }
        default: {
            ConvexCore other;
            make_core(wall, xw, other);
            return time_of_impact(path, part, target, before, [&](const Transform& pose, Real, Real) {
                pose_core(part.core, pose, posed);
                return core_gap(posed, other.points.data(), other.count, other.radius);
            });
        }
    }
}

// The first time of impact in [0, 1) of the listed body against static geometry, or 1.
// A compound is swept part by part (Box3D sweeps each shape): one part resting on the
// ground, touching at the start, must not hide another coming down. A part whose own
// centre moved, plus the most the turn moves its points about it, less than half its
// thinnest half-size cannot pass through anything (a pole's end pivoting on the ground, a
// tree's part spinning about the tree's long axis) and is not swept.
Real sweep_body(World& world, const FastStart& start, SweepScratch& scratch) {
    Bodies& b = world.bodies;
    const std::uint32_t i = start.slot;
    const Real target = world.settings.solver.linear_slop;
    // The static bodies near the centre of mass's path, within its farthest reach: no
    // shape bounds, no slerp, for a body with no static body near.
    const Aabb swept = segment_box(start.x0, b.x[i], b.extents[i].reach_length + target);
    std::vector<std::uint32_t>& statics = scratch.statics;
    statics.clear();
    const BroadphaseState& bp = *world.broadphase;
    bp.tree.static_tree().query(swept, [&](std::int32_t id) {
        const auto wall = static_cast<std::uint32_t>(bp.tree.static_tree().user(id));
        if (!passes_through(world, i, wall)) statics.push_back(wall);
        return true;
    });
    if (statics.empty()) return 1;
    std::sort(statics.begin(), statics.end());                         // the same order whatever the tree's shape
    const Eigen::AngleAxis<Real> turn(start.q0.conjugate() * b.q[i]);  // the shortest way round
    const Vec3& com = b.local_com[i];
    const BodyPath path{start.x0,
                        b.x[i],
                        start.q0,
                        b.q[i],
                        com,
                        b.x[i] - start.x0,
                        (turn.angle() * turn.axis()).cwiseAbs(),
                        {start.x0 - start.q0 * com, start.q0},
                        {b.x[i] - b.q[i] * com, b.q[i]}};

    const Shape& shape = b.traits[i].shape;
    const bool compound = shape.type == ShapeType::Compound;
    const std::uint32_t part_count = compound ? shape.parts->size() : 1;
    Real first = 1;
    SweptPart part;
    for (std::uint32_t p = 0; p < part_count; ++p) {
        if (compound) {
            // Every point of the part lies within its box's half-extents of the box's centre.
            const Aabb& local = shape.parts->part_bounds(p);
            const Vec3 b0 = path.start.apply(local.center()), b1 = path.end.apply(local.center());
            const Real twist = modified_cross(path.turn, local.extents()).norm();
            const Real thinnest = thinnest_half_size(shape.parts->shape(p));
            if ((b1 - b0).norm() + twist < Real(0.5) * thinnest) continue;
            // Nor is its core made when its swept box meets no static body.
            const Vec3 lever = (local.center() - path.local_com).cwiseAbs() + local.extents();
            const Real reach = local.extents().norm() + path.moved.norm() + modified_cross(path.turn, lever).norm();
            const Aabb box = segment_box(b0, b1, reach + target);
            if (std::none_of(statics.begin(), statics.end(),
                             [&](std::uint32_t wall) { return box.overlaps(b.bounds[wall]); }))
                continue;
            make_part(shape.parts->shape(p), shape.parts->pose(p), path, thinnest, part);
        } else {
            make_part(shape, Transform{}, path, thinnest_half_size(shape), part);
        }
        const Vec3 c0 = path.start.apply(part.centre);
        const Vec3 c1 = path.end.apply(part.centre);
        const Real travel = path.moved.norm() + part.swing + target;
        const Aabb part_box = segment_box(c0, c1, part.half_size + travel);
        for (const std::uint32_t wall : statics) {
            if (!part_box.overlaps(b.bounds[wall])) continue;
            first = sweep_against(path, part, b.traits[wall].shape, b.transform(wall), target, first, scratch);
            scratch.tests += 1;
        }
    }
    return first;
}

}  // namespace

bool bodies_to_sweep(const World& world) {
    return std::any_of(world.fast_lists.begin(), world.fast_lists.end(),
                       [](const std::vector<FastStart>& list) { return !list.empty(); });
}

void sweep_fast_bodies(World& world) {
    std::vector<FastStart>& listed = world.fast_starts;
    listed.clear();
    for (std::vector<FastStart>& list : world.fast_lists) {
        listed.insert(listed.end(), list.begin(), list.end());
        list.clear();
    }
    const unsigned workers = world.jobs->worker_count();
    if (world.sweep_scratch.size() < workers) world.sweep_scratch.resize(workers);
    for (SweepScratch& s : world.sweep_scratch) s.tests = 0;
    Bodies& b = world.bodies;
    // A sweep writes only its own body and reads only static ones: the result does not
    // depend on the order or on the worker.
    world.jobs->parallel_for("Sweep", 0, static_cast<std::uint32_t>(listed.size()), 1,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
                                 for (std::uint32_t k = lo; k < hi; ++k) {
                                     const FastStart& start = listed[k];
                                     const Real first = sweep_body(world, start, world.sweep_scratch[worker]);
                                     if (first >= 1) continue;
                                     // Stop at the impact pose; the velocity stays, and next step's contact (now
                                     // within reach) takes it out.
                                     const std::uint32_t i = start.slot;
                                     const Quat q = start.q0.slerp(first, b.q[i]);
                                     Vec3 x = start.x0 + first * (b.x[i] - start.x0);
                                     // A locked coordinate is the same at both ends of the sweep: kept exactly.
                                     for (int axis = 0; axis < 3; ++axis) {
                                         if ((b.locks[i] & (1u << axis)) != 0) x[axis] = b.x[i][axis];
                                     }
                                     b.q[i] = q;
                                     b.x[i] = x;
                                 }
                             });
    for (const SweepScratch& s : world.sweep_scratch) world.counters.swept_tests += s.tests;
    listed.clear();
}

}  // namespace spindle
