// Contact constraints of the soft-step solver, eight manifolds at a time: each colour's
// manifolds are packed kLanes to a WideContact (structure of arrays, one manifold per
// lane) and every pass works on the lanes together in floats (wide.hpp). The lanes of a
// WideContact share no dynamic body, so gathering their velocities, solving and
// scattering them back is the same as solving them one after another.
//
// Per pass: the manifold's central friction (Box3D's): a twist row about the normal and
// two coupled tangent rows at the points' centre, inside Coulomb's cone of the manifold's
// touching normal impulse; and each point's normal row (soft push-out of resting overlap
// while biased, speculative for a gap). The biased pass solves friction before its normal
// rows, the relax pass after them. Each body is pushed at its own anchor of
// a point (the manifold may be recycled, and the anchors moved apart with their bodies:
// narrowphase.cpp). Overlap deeper than the recovery depth (or than the point's load
// holds it) is pushed out by a split impulse on separate push-out velocities, per lane
// (rare: bodies created or teleported inside each other).
#include <algorithm>
#include <cstddef>
#include <cstring>
#include <type_traits>

#include <spindle/platform/assert.hpp>

#include "collision/compound.hpp"
#include "collision/convex_hull.hpp"
#include "solver/body_lanes.hpp"
#include "solver/constraints.hpp"
#include "solver/joint_rows.hpp"
#include "stages/capacity.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

constexpr Real kEmptySeparation = 1e18;  // an empty point slot: far apart, never touching
// Wide contacts per job when packing: each writes a few lines of its wide contact, so
// blocks are long enough that a job's overhead stays small beside them.
constexpr std::uint32_t kPackGrain = 256;

// Fills a row's angular terms and returns its effective mass.
Real make_row(const SolverBody& A, const SolverBody& B, const Vec3& ra, const Vec3& rb, const Vec3& dir,
              ContactRow& row) {
    row.ra_x = ra.cross(dir);
    row.rb_x = rb.cross(dir);
    row.ia = A.inv_inertia * row.ra_x;
    row.ib = B.inv_inertia * row.rb_x;
    const Real k = inverse_mass_along(A.inv_mass, A.locks, dir) + inverse_mass_along(B.inv_mass, B.locks, dir) +
                   row.ra_x.dot(row.ia) + row.rb_x.dot(row.ib);
    return k > 0 ? 1 / k : 0;
}

// Relative speed along a row's direction, and an impulse of size L along it (one lane).
inline Real row_speed(const Velocities& s, const Vec3& dir, const ContactRow& row) {
    return dir.dot(s.vb - s.va) + row.rb_x.dot(s.wb) - row.ra_x.dot(s.wa);
}
inline void apply_row(const SolverBody& A, const SolverBody& B, Velocities& s, const Vec3& dir, const ContactRow& row,
                      Real L) {
    s.va -= project_linear((A.inv_mass * L) * dir, A.locks);
    s.wa -= L * row.ia;
    s.vb += project_linear((B.inv_mass * L) * dir, B.locks);
    s.wb += L * row.ib;
}

// The lanes' inverse masses per world axis (zero along a locked one), for a wide
// contact with a locked body; the unlocked passes never build them. From the lanes'
// own inverse masses: a support contact may scale one (support_scales.cpp).
struct WideAxisMasses {
    Wide3 a, b;
};

inline WideAxisMasses axis_masses(const WideContact& wc, const SolverBody* bodies) {
    WideAxisMasses m;
    for (int l = 0; l < kLanes; ++l) {
        const SolverBody& A = bodies[wc.a[l]];
        const SolverBody& B = bodies[wc.b[l]];
        m.a.set_lane(l, project_linear(Vec3::Constant(wc.inv_mass_a[l]), A.locks));
        m.b.set_lane(l, project_linear(Vec3::Constant(wc.inv_mass_b[l]), B.locks));
    }
    return m;
}

// (m L) d per axis: for a body without locks the same bits as the scalar (m L) d.
inline Wide3 scaled(const Wide3& m, Wide L, const Wide3& dir) {
    return {(m.x * L) * dir.x, (m.y * L) * dir.y, (m.z * L) * dir.z};
}

template <bool kLocked>
inline void apply_row(const WideContact& wc, const WideAxisMasses& m, WideVelocities& s, const Wide3& dir,
                      const WideRow& row, Wide L) {
    if constexpr (kLocked) {
        s.va -= scaled(m.a, L, dir);
    } else {
        s.va -= (wc.inv_mass_a * L) * dir;
    }
    s.wa -= L * row.ia;
    if constexpr (kLocked) {
        s.vb += scaled(m.b, L, dir);
    } else {
        s.vb += (wc.inv_mass_b * L) * dir;
    }
    s.wb += L * row.ib;
}

// An angular impulse L about a row's axis (the twist row): no linear part.
inline void apply_angular_row(WideVelocities& s, const WideRow& row, Wide L) {
    s.wa -= L * row.ia;
    s.wb += L * row.ib;
}

// A row's angular terms for the lanes; returns the effective masses (0 where nothing moves).
Wide make_row(const WideMat3& inv_inertia_a, const WideMat3& inv_inertia_b, Wide inv_mass_sum, const Wide3& ra,
              const Wide3& rb, const Wide3& dir, WideRow& row) {
    const Wide3 ra_x = cross(ra, dir);
    const Wide3 rb_x = cross(rb, dir);
    const Wide3 ia = inv_inertia_a * ra_x;
    const Wide3 ib = inv_inertia_b * rb_x;
    row = {ia, ib};
    const Wide k = inv_mass_sum + dot(ra_x, ia) + dot(rb_x, ib);
    return select(k > splat(0), splat(1) / k, splat(0));
}

// A unit quaternion per lane, in double.
struct WideDQuat {
    WideD3 v;
    WideD w{};
};

// q v q^-1 for each lane's unit q: v + w t + u x t, with u q's vector part and t = 2 u x v.
WideD3 rotate(const WideDQuat& q, const WideD3& v) {
    const WideD3 half = cross(q.v, v);
    const WideD3 t = half + half;
    return v + q.w * t + cross(q.v, t);
}

// What central friction reads of the lanes' manifolds and bodies, gathered in double by
// prepare_wide. Lanes and point slots without a manifold or point are zero, and lie
// kEmptySeparation apart. Not zeroed when default-built: prepare_wide writes each field
// once, a lane at a time.
struct FrictionLanes {
    WideD3 anchor_a[kMaxManifoldPoints], anchor_b[kMaxManifoldPoints];  // each point from A's and B's centre
    WideD separation[kMaxManifoldPoints];
    WideDMask filled[kMaxManifoldPoints];  // lanes with a point in the slot
    WideD3 normal, tangent[2];
    WideD3 friction_impulse;
    WideDMat3 inv_inertia_a, inv_inertia_b;
    WideD inv_mass_a, inv_mass_b;
    // Per world axis, lanes whose body has its translation along it locked.
    WideDMask locked_a[3], locked_b[3];
    // Lanes whose bodies turned since their manifold was collided (any_turned: some lane),
    // each body's turn since (the identity where neither turned), and each body's round
    // part (ContactManifold::radius_a, radius_b).
    WideDMask turned;
    bool any_turned = false;
    WideDQuat turn_a, turn_b;
    WideD radius_a, radius_b;
    // Each body's angular velocity as the step begins (prepare_friction's turning surfaces).
    WideD3 spin_a, spin_b;
};

// The friction centre of the lanes whose bodies turned since their manifold was collided,
// turned with them: the anchors are the points' offsets when collided, and a body carried
// on a turning one is carried by the velocity of the point under it now (10 degrees behind,
// the cube on a turntable coasted straight off it). A round part's surface point stays on
// the normal, as recycle() keeps it. Only friction's: the normal rows keep their anchors
// fixed under their fixed normal while the manifold is recycled (Box3D's); turning those
// under it moved the supports of a tilting box under its load, and a tall stack fell.
void turn_centers(const FrictionLanes& in, WideD3& center_a, WideD3& center_b) {
    const WideD3 round_a = in.radius_a * in.normal, round_b = in.radius_b * in.normal;
    center_a = select(in.turned, rotate(in.turn_a, center_a - round_a) + round_a, center_a);
    center_b = select(in.turned, rotate(in.turn_b, center_b + round_b) - round_b, center_b);
}

// The free part of v (without_axes, motion_locks.hpp): a locked axis is an exact zero.
WideD3 free_part(const WideD3& v, const WideDMask (&locked)[3]) {
    const WideD zero{};
    return {select(locked[0], zero, v.x), select(locked[1], zero, v.y), select(locked[2], zero, v.z)};
}

// inverse_mass_along (motion_locks.hpp) for the lanes: inv_mass, or where the body has a
// translation lock (`locked_body`) its share along the free axes.
WideD inverse_mass_along(WideD inv_mass, WideDMask locked_body, const WideDMask (&locked)[3], const WideD3& dir) {
    if (!any(locked_body)) return inv_mass;
    const WideD3 free = free_part(dir, locked);
    return select(locked_body, inv_mass * dot(free, free), inv_mass);
}

// A tangent basis for each lane's unit normal, the same for the same normal every time:
// t1 normalized from (n.y, -n.x, 0) where |n.x| >= 0.57735, else from (0, n.z, -n.y), and
// t2 = n x t1, made as Eigen's normalized() and cross() make them on one lane (a sum of
// three squares by halves, a division by the root). Lanes not in `live` are zero.
void tangent_basis(const WideD3& n, WideDMask live, WideD3& t1, WideD3& t2) {
    const WideD zero{}, bound = splat_d(0.57735);
    const WideDMask steep = abs_at_least(n.x, bound);
    const WideD3 raw = select(steep, WideD3{n.y, -n.x, zero}, WideD3{zero, n.z, -n.y});
    const WideD squared = dot(raw, raw);
    const WideDMask positive = squared > zero;
    t1 = raw / wide_sqrt(squared);
    if (!all(positive)) t1 = select(positive, t1, raw);
    t2 = cross(n, t1);
    if (!all(live)) {
        t1 = select(live, t1, WideD3{});
        t2 = select(live, t2, WideD3{});
    }
}

// w x (w x r) for each lane's spin w and arm r: how fast the velocity of the surface point
// at r changes as the body turns it. The point's offset is taken to turn on a straight
// line, r + t w x r: through a step of length dt that holds while it turns less than a
// radian about the arm's own length (a top's tip, on its spin axis, barely turns; a box's
// corner tumbling at 60 rad/s would); beyond, the pull is scaled down to that radian.
WideD3 turning_pull(const WideD3& w, const WideD3& r, Real dt) {
    const WideD3 moving = cross(w, r);
    const WideD moving_sq = dot(moving, moving) * splat_d(dt * dt), arm_sq = dot(r, r);
    const WideDMask far = moving_sq > arm_sq;
    WideD3 pull = cross(w, moving);
    if (any(far)) pull = select(far, wide_sqrt(arm_sq / moving_sq) * pull, pull);
    return pull;
}

// Central friction of the lanes (Box3D's): the friction centre is the points' mean,
// weighted down for points farther apart than friction_distance (up to twice that they
// fade out, so the centre moves smoothly as points come and go); the two tangent rows at
// the centre with their coupled 2x2 effective mass; the twist row about the normal. In
// double, every lane as the scalar products would make it.
void prepare_friction(const FrictionLanes& in, Real friction_distance, Real dt, WideContact& wc) {
    const WideD zero{}, one = splat_d(1), min_weight = splat_d(1e-3), distance = splat_d(friction_distance);
    WideD3 center_a, center_b;
    WideD total{};
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        // std::clamp's order: the lower bound where the weight is below it, then the upper.
        const WideD weight = wide_min(one, wide_max(min_weight, splat_d(2) - in.separation[j] / distance));
        if (j == 0) {  // every manifold has a first point (a lane without one weighs a zero anchor)
            center_a = WideD3{} + weight * in.anchor_a[0];
            center_b = WideD3{} + weight * in.anchor_b[0];
            total = zero + weight;
            continue;
        }
        // A slot without a point adds weight 0 and its zero anchor: the sums are never -0
        // after the first point (+0 + x is not), so adding +0 leaves each as it was.
        const WideD filled_weight = select(in.filled[j], weight, zero);
        center_a = center_a + filled_weight * in.anchor_a[j];
        center_b = center_b + filled_weight * in.anchor_b[j];
        total = total + filled_weight;
    }
    const WideDMask weighed = total > zero;
    if (all(weighed)) {
        center_a = center_a / total;
        center_b = center_b / total;
    } else {
        center_a = select(weighed, center_a / total, center_a);
        center_b = select(weighed, center_b / total, center_b);
    }
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        const WideD3 arm = in.anchor_a[j] - center_a;
        wc.points[j].lever_arm = narrow(select(in.filled[j], wide_sqrt(dot(arm, arm)), zero));
    }
    if (in.any_turned) turn_centers(in, center_a, center_b);
    wc.center_a = narrow(center_a);
    wc.center_b = narrow(center_b);
    // The friction centre's anchors are fixed offsets through the step, but the surface
    // points under them turn with their bodies: a point at offset r on a body turning at w
    // is, a time t on, at r + t w x r, and moves at w x r + t w x (w x r). Friction reads
    // the surfaces at that time (ContactSolveParams::turn_time), or a body carried by a
    // turning one moves on the tangent, not the circle, and drifts out a little every
    // step (a cube on a turntable slid 74 mm in 3 s), and a fast top's tip, which the body
    // turns about, slides off as the step's turn carries it (turning_pull). A round part's
    // surface point stays on the normal (turn_centers): only its centre's offset turns.
    // Nil at rest.
    const WideD3 turning_a = center_a - in.radius_a * in.normal, turning_b = center_b + in.radius_b * in.normal;
    const WideD3 pull = turning_pull(in.spin_b, turning_b, dt) - turning_pull(in.spin_a, turning_a, dt);
    wc.friction_turn[0] = narrow(dot(in.tangent[0], pull));
    wc.friction_turn[1] = narrow(dot(in.tangent[1], pull));
    WideD3 ia[2], ib[2], ra_x[2], rb_x[2];
    for (int t = 0; t < 2; ++t) {
        ra_x[t] = cross(center_a, in.tangent[t]);
        rb_x[t] = cross(center_b, in.tangent[t]);
        ia[t] = in.inv_inertia_a * ra_x[t];
        ib[t] = in.inv_inertia_b * rb_x[t];
        wc.friction_row[t] = {narrow(ia[t]), narrow(ib[t])};
    }
    // k(s, t) = ms (Ps ts).(Ps tt) summed over both bodies (P: the free axes) + the angular terms.
    WideD3 locked_free_a[2], locked_free_b[2];
    const WideD3* free_a = in.tangent;
    const WideD3* free_b = in.tangent;
    if (wc.locked) {
        for (int t = 0; t < 2; ++t) {
            locked_free_a[t] = free_part(in.tangent[t], in.locked_a);
            locked_free_b[t] = free_part(in.tangent[t], in.locked_b);
        }
        free_a = locked_free_a;
        free_b = locked_free_b;
    }
    auto linear = [&](int s, int t) {
        return in.inv_mass_a * dot(free_a[s], free_a[t]) + in.inv_mass_b * dot(free_b[s], free_b[t]);
    };
    const WideD k00 = linear(0, 0) + dot(ra_x[0], ia[0]) + dot(rb_x[0], ib[0]);
    const WideD k11 = linear(1, 1) + dot(ra_x[1], ia[1]) + dot(rb_x[1], ib[1]);
    const WideD k01 = linear(0, 1) + dot(ra_x[0], ia[1]) + dot(rb_x[0], ib[1]);
    // The inverse; where a motion lock leaves a tangent no give (K of rank one, K = t u u^T
    // with t its trace), the pseudo-inverse u u^T / t = K / t^2, so the free tangent still rubs.
    const WideD det = k00 * k11 - k01 * k01;
    const WideD trace = k00 + k11;
    const WideDMask invertible = det > splat_d(1e-9) * trace * trace;
    if (all(invertible)) {
        wc.friction_mass[0] = narrow(k11 / det);
        wc.friction_mass[1] = narrow(-k01 / det);
        wc.friction_mass[2] = narrow(k00 / det);
    } else {
        const WideDMask pseudo = ~invertible & (trace > zero);
        const WideD inv_sq = one / (trace * trace);
        wc.friction_mass[0] = narrow(select(invertible, k11 / det, select(pseudo, k00 * inv_sq, zero)));
        wc.friction_mass[1] = narrow(select(invertible, -k01 / det, select(pseudo, k01 * inv_sq, zero)));
        wc.friction_mass[2] = narrow(select(invertible, k00 / det, select(pseudo, k11 * inv_sq, zero)));
    }
    wc.friction_impulse[0] = narrow(dot(in.tangent[0], in.friction_impulse));
    wc.friction_impulse[1] = narrow(dot(in.tangent[1], in.friction_impulse));
    const WideD3 twist_a = in.inv_inertia_a * in.normal, twist_b = in.inv_inertia_b * in.normal;
    wc.twist_row = {narrow(twist_a), narrow(twist_b)};
    const WideD k_twist = dot(in.normal, twist_a + twist_b);
    wc.twist_mass = narrow(select(k_twist > zero, one / k_twist, zero));
}

// The reach of a shape's rolling resistance (Box3D's): a sphere's or capsule's radius, a
// quarter of a box's or hull's inner radius (the flat faces already resist rolling); none
// for a plane or mesh, which only the other shape rolls on.
Real rolling_radius(const Shape& shape) {
    switch (shape.type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule: return shape.radius;
        case ShapeType::Box: return Real(0.25) * shape.half_extents.minCoeff();
        case ShapeType::ConvexHull: return Real(0.25) * shape.hull->inner_radius();
        default: return 0;
    }
}

// Lane l's rolling row, where its contact has rolling resistance (Box3D's, per shape pair:
// here per manifold, so a compound's parts each brake with their own radius and normal
// impulse). The first rolling lane clears `rolling`, the wide contact's, and points it there.
void prepare_rolling(const World& world, const Contact& contact, const ContactManifold& m, const SolverBody& A,
                     const SolverBody& B, Real kept, WideContact& wc, WideRolling& rolling, int l) {
    const Bodies& b = world.bodies;
    const Real radius = std::max(rolling_radius(part_shape(b.traits[contact.body_a].shape, m.part_a)),
                                 rolling_radius(part_shape(b.traits[contact.body_b].shape, m.part_b)));
    const Real cap = contact.rolling_resistance * radius;
    if (!(cap > 0)) return;
    if (!wc.rolls) {
        rolling = WideRolling{};
        wc.rolling = &rolling;
        wc.rolls = true;
    }
    rolling.cap[l] = static_cast<float>(cap);
    rolling.mass.set_lane(l, inverse_or_pseudo(Mat3(A.inv_inertia + B.inv_inertia), has_locks(A, B)));
    rolling.inv_inertia_a.set_lane(l, A.inv_inertia);
    rolling.inv_inertia_b.set_lane(l, B.inv_inertia);
    rolling.impulse.set_lane(l, kept * Vec3(m.rolling_impulse[0], m.rolling_impulse[1], m.rolling_impulse[2]));
}

// The share of a manifold's stored impulses its warm start keeps: the push they give the
// lower body of a support contact as it was solved (its inverse mass scaled by the stored
// support_scale), now at this step's scale, and never more than whole. A light box holding
// up a heavy ball is solved as heavy as the ball (support_scales.cpp); when the ball rolls
// off it, the contact is no longer a support and the box is solved at its own mass, and
// its last impulse, which held up the ball, launched the box at 23 m/s.
Real kept_share(const ContactManifold& m, const SupportScale& scale) {
    const Real now = scale.lower();
    return m.support_scale < now ? m.support_scale / now : Real(1);
}

// The body, or (scale != 1) a copy of it in `copy` with its inverse mass and inertia scaled.
const SolverBody& scaled(const SolverBody& body, Real scale, SolverBody& copy) {
    if (scale == 1) return body;
    copy = body;
    copy.inv_mass *= scale;
    copy.inv_inertia *= scale;
    return copy;
}

// A WideContact from its lanes' manifolds, with rows from the bodies at the step's
// start. Every field is written, so the array is reused from step to step as it is.
// `rolling`: the wide contact's rolling rows, written only where a lane rolls; null where
// no listed manifold rolls (size_rolling_rows), so no lane can.
void prepare_wide(const World& world, const SolverScratch& scratch, const ContactSolveParams& params, WideContact& wc,
                  WideRolling* rolling) {
    const Bodies& b = world.bodies;
    const Vec3 g = world.settings.gravity;
    // Gathered lane by lane; lanes and points without a manifold keep zero mass and lie
    // far apart. Lanes without a manifold are zeroed here, empty point slots of a lane and
    // the lock masks of an unlocked lane in the loop.
    FrictionLanes in;
    if (wc.lanes < kLanes) {
        in = FrictionLanes{};
        for (WideD& gap : in.separation) gap = splat_d(kEmptySeparation);
    }
    for (int axis = 0; axis < 3; ++axis) in.locked_a[axis] = in.locked_b[axis] = WideDMask{};
    in.any_turned = false;
    Wide normal_impulse[kMaxManifoldPoints]{};
    WideD gravity_scale_a{}, gravity_scale_b{};
    WideDMask live{}, locks_a{}, locks_b{};  // lanes with a manifold; lanes whose body has a translation lock
    wc.locked = false;
    wc.tracks_push = false;
    wc.rolls = false;
    wc.sweep_lanes = 0;
    wc.friction = wc.restitution = wc.against_static = Wide{};
    wc.radius_a = wc.radius_b = Wide{};
    wc.twist_impulse = Wide{};
    for (std::uint8_t& points : wc.slot_points) points = 0;
    const Real friction_distance = std::max(world.settings.solver.speculative_distance, Real(1e-3));
    SolverBody scaled_a, scaled_b;  // a lane's bodies where a support scale is not 1
    for (int l = 0; l < wc.lanes; ++l) {
        const ManifoldRef& ref = scratch.manifolds[wc.ref[l]];
        const Contact& contact = world.contacts[ref.contact];
        const ContactManifold& m = contact.manifold_at(static_cast<int>(ref.manifold));
        // A light body carrying a heavier one is solved heavier here (support_scales.cpp).
        const SupportScale scale = support_scale(scratch, wc.ref[l]);
        const SolverBody& A = scaled(scratch.bodies[ref.a], scale.a, scaled_a);
        const SolverBody& B = scaled(scratch.bodies[ref.b], scale.b, scaled_b);
        live[l] = -1;
        in.normal.set_lane(l, m.normal);
        in.inv_mass_a[l] = A.inv_mass;
        in.inv_mass_b[l] = B.inv_mass;
        if (((A.locks | B.locks) & kLockTranslation) != 0) {  // else the lane's masks stay clear
            wc.locked = true;
            locks_a[l] = (A.locks & kLockTranslation) != 0 ? -1 : 0;
            locks_b[l] = (B.locks & kLockTranslation) != 0 ? -1 : 0;
            for (int axis = 0; axis < 3; ++axis) {
                in.locked_a[axis][l] = (A.locks & (1u << axis)) != 0 ? -1 : 0;
                in.locked_b[axis][l] = (B.locks & (1u << axis)) != 0 ? -1 : 0;
            }
        }
        in.inv_inertia_a.set_lane(l, A.inv_inertia);
        in.inv_inertia_b.set_lane(l, B.inv_inertia);
        const Real kept = kept_share(m, scale);
        in.friction_impulse.set_lane(l, kept * m.friction_impulse);
        wc.twist_impulse[l] = static_cast<float>(kept * m.twist_impulse);
        wc.friction[l] = contact.friction;
        wc.against_static[l] =
            b.type[contact.body_a] == MotionType::Static || b.type[contact.body_b] == MotionType::Static ? 1 : 0;
        wc.restitution[l] = contact.restitution;
        wc.tracks_push = wc.tracks_push || contact.restitution > 0 || (contact.events & kContactReports) != 0;
        wc.radius_a[l] = m.radius_a;
        wc.radius_b[l] = m.radius_b;
        gravity_scale_a[l] = scratch.gravity_scales[ref.a];
        gravity_scale_b[l] = scratch.gravity_scales[ref.b];
        // A manifold of two points or more whose bodies are about to touch, closing faster
        // than the settled speed as the step begins (their velocities in the world: the
        // solver's may be integrating already): the passes sweep its rows until they settle
        // (solve_wide). One point's row is settled by one sweep.
        bool landing = m.point_count > 1;
        for (int j = 0; j < m.point_count && landing; ++j) landing = m.points[j].separation > 0;
        if (landing && m.normal.dot(b.v[contact.body_b] - b.v[contact.body_a]) < -params.settled_speed)
            wc.sweep_lanes |= 1u << l;
        // A recycled manifold's bodies may have turned since it was collided: its friction
        // centre turns with them (prepare_friction).
        const Quat& qa = b.q[contact.body_a];
        const Quat& qb = b.q[contact.body_b];
        const bool turned_a = !(qa.coeffs() == contact.cached_qa.coeffs());
        const bool turned_b = !(qb.coeffs() == contact.cached_qb.coeffs());
        in.turned[l] = turned_a || turned_b ? -1 : 0;
        in.any_turned = in.any_turned || turned_a || turned_b;
        const Quat turn_a = turned_a ? Quat(qa * contact.cached_qa.conjugate()) : Quat::Identity();
        const Quat turn_b = turned_b ? Quat(qb * contact.cached_qb.conjugate()) : Quat::Identity();
        in.turn_a.v.set_lane(l, turn_a.vec());
        in.turn_a.w[l] = turn_a.w();
        in.turn_b.v.set_lane(l, turn_b.vec());
        in.turn_b.w[l] = turn_b.w();
        in.radius_a[l] = m.radius_a;
        in.radius_b[l] = m.radius_b;
        in.spin_a.set_lane(l, A.w);
        in.spin_b.set_lane(l, B.w);
        for (int j = 0; j < m.point_count; ++j) {
            const ContactPoint& src = m.points[j];
            in.anchor_a[j].set_lane(l, contact.anchor_a(src));
            in.anchor_b[j].set_lane(l, contact.anchor_b(src));
            in.separation[j][l] = src.separation;
            in.filled[j][l] = -1;
            normal_impulse[j][l] = static_cast<float>(kept * src.normal_impulse);
            ++wc.slot_points[j];
        }
        for (int j = m.point_count; j < kMaxManifoldPoints; ++j) {
            in.anchor_a[j].set_lane(l, Vec3::Zero());
            in.anchor_b[j].set_lane(l, Vec3::Zero());
            in.separation[j][l] = kEmptySeparation;
            in.filled[j][l] = 0;
        }
        if (contact.rolling_resistance > 0) {
            SPINDLE_ASSERT(rolling != nullptr, "solver: a lane rolls without rolling rows");
            prepare_rolling(world, contact, m, A, B, kept, wc, *rolling, l);
        }
    }
    tangent_basis(in.normal, live, in.tangent[0], in.tangent[1]);
    // Inverse mass sum of both bodies along the normal (the share of the free axes for a
    // locked body, inverse_mass_along) and gravity's pull along it, as the scalar
    // expressions make them on each lane: a lock zeroes the axes as project_linear does.
    const Wide linear_sum = narrow(inverse_mass_along(in.inv_mass_a, locks_a, in.locked_a, in.normal) +
                                   inverse_mass_along(in.inv_mass_b, locks_b, in.locked_b, in.normal));
    const WideD3 gravity{splat_d(g.x()), splat_d(g.y()), splat_d(g.z())};
    const WideD3 pull = wc.locked ? free_part(gravity_scale_b * gravity, in.locked_b) -
                                        free_part(gravity_scale_a * gravity, in.locked_a)
                                  : gravity_scale_b * gravity - gravity_scale_a * gravity;
    wc.gravity_normal = narrow(select(live, dot(in.normal, pull), WideD{}));
    wc.inv_mass_a = narrow(in.inv_mass_a);
    wc.inv_mass_b = narrow(in.inv_mass_b);
    wc.normal = narrow(in.normal);
    wc.tangent[0] = narrow(in.tangent[0]);
    wc.tangent[1] = narrow(in.tangent[1]);
    prepare_friction(in, friction_distance, params.step, wc);
    const WideMat3 inv_inertia_a = narrow(in.inv_inertia_a), inv_inertia_b = narrow(in.inv_inertia_b);
    Wide3 ra[kMaxManifoldPoints], rb[kMaxManifoldPoints];
    Wide separation[kMaxManifoldPoints];  // the gathered doubles, each rounded as a float cast rounds it
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        ra[j] = narrow(in.anchor_a[j]);
        rb[j] = narrow(in.anchor_b[j]);
        separation[j] = narrow(in.separation[j]);
    }
    WideVelocities s{};  // for the approach speeds
    if (wc.tracks_push) s = gather(wc, scratch.bodies.data());
    // How deep a point's last impulse holds its soft row at rest, per lane (stiffer
    // against a static body).
    const WideMask stiff = wc.against_static > splat(0);
    const Wide held_per_impulse = select(stiff, splat(params.static_held_per_impulse), splat(params.held_per_impulse));
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        WidePoint& p = wc.points[j];
        WidePointRow& r = wc.point_rows[j];
        p.ra = ra[j];
        p.rb = rb[j];
        p.adjusted_separation = separation[j] - dot(wc.normal, rb[j] - ra[j]);
        // A slot no manifold fills gets no mass: it can never push or rub.
        const WideMask filled = separation[j] < splat(kEmptySeparation);
        p.normal_mass = make_row(inv_inertia_a, inv_inertia_b, select(filled, linear_sum, splat(0)), ra[j], rb[j],
                                 wc.normal, r.normal_row);
        r.normal_impulse = normal_impulse[j];
        const Wide mass = p.normal_mass;
        const Wide held = select(mass > splat(0), held_per_impulse * normal_impulse[j] / mass, splat(0));
        wc.recovery[j] = wide_max(splat(params.recovery_depth), held);
        wc.max_normal_impulse[j] = Wide{};
        wc.relative_velocity[j] = wc.tracks_push ? dot(wc.normal, point_velocity(s, ra[j], rb[j])) : Wide{};
    }
    for (float& impulse : wc.push_impulse) impulse = 0;
}

// The lanes' contact records are read at random, each a few cache lines: asked for one
// wide contact ahead, their misses overlap the preparing of the one before.
void prefetch_contacts(const World& world, const SolverScratch& scratch, const WideContact& wc) {
    for (int l = 0; l < wc.lanes; ++l) {
        const auto* record = reinterpret_cast<const char*>(&world.contacts[scratch.manifolds[wc.ref[l]].contact]);
        for (std::size_t line = 0; line < sizeof(Contact); line += 64) __builtin_prefetch(record + line);
    }
}

}  // namespace

// Lays the colours' manifold refs out kLanes at a time, then the overflow one per
// WideContact (its manifolds may share bodies, so they are solved one at a time), in
// jobs: each wide contact's place follows from the colours' sizes alone.
void pack_contacts(JobSystem& jobs, SolverScratch& scratch) {
    std::uint32_t count = 0;
    for (int c = 0; c < kColorCount; ++c) {
        scratch.wide_begin[c] = count;
        count += static_cast<std::uint32_t>((scratch.colors[c].size() + kLanes - 1) / kLanes);
    }
    scratch.wide_begin[kColorCount] = count;
    count += static_cast<std::uint32_t>(scratch.overflow.size());
    // Kept from step to step (prepare_wide writes every field, push_out a row before it
    // is read), at about the size of the step's. A first step's are megabytes of new
    // pages: mapped in jobs, and not zeroed by the resizes (raw room).
    reserve_for(scratch.wide, count);
    map_room(jobs, scratch.wide, count);
    scratch.wide.resize(count);
    if (far_above_use(scratch.wide.capacity(), count)) fit_capacity(scratch.wide);
    reserve_for(scratch.push_anchors, std::size_t{count} * kLanes);
    map_room(jobs, scratch.push_anchors, std::size_t{count} * kLanes);
    scratch.push_anchors.resize(std::size_t{count} * kLanes);
    if (far_above_use(scratch.push_anchors.capacity(), std::size_t{count} * kLanes)) fit_capacity(scratch.push_anchors);
    const auto immovable = static_cast<std::uint32_t>(scratch.bodies.size() - 1);
    jobs.parallel_for("PackContacts", 0, count, kPackGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        int c = 0;
        for (std::uint32_t k = lo; k < hi; ++k) {
            while (c < kColorCount && k >= scratch.wide_begin[c + 1]) ++c;
            const std::uint32_t* refs;
            int lanes = 1;
            if (c < kColorCount) {
                const std::vector<std::uint32_t>& color = scratch.colors[c];
                const std::size_t first = std::size_t{k - scratch.wide_begin[c]} * kLanes;
                refs = color.data() + first;
                lanes = static_cast<int>(std::min<std::size_t>(kLanes, color.size() - first));
            } else {
                refs = &scratch.overflow[k - scratch.wide_begin[kColorCount]];
            }
            WideContact& wc = scratch.wide[k];
            wc.lanes = lanes;
            for (int l = 0; l < kLanes; ++l) {
                wc.ref[l] = l < lanes ? refs[l] : 0;
                wc.a[l] = l < lanes ? scratch.manifolds[refs[l]].a : immovable;
                wc.b[l] = l < lanes ? scratch.manifolds[refs[l]].b : immovable;
            }
        }
    });
}

namespace {

// A lane's body (side 0: A, 1: B) with the masses the lane's rows see: a support contact
// may scale one (support_scales.cpp). For the rare per-lane push-out rows.
const SolverBody& lane_body(const WideContact& wc, int lane, int side, const SolverBody& body, SolverBody& copy) {
    const Real lane_inv_mass = side == 0 ? wc.inv_mass_a[lane] : wc.inv_mass_b[lane];
    return scaled(body, body.inv_mass > 0 ? lane_inv_mass / body.inv_mass : 1, copy);
}

// Deep overlap is pushed out by a soft constraint on the push-out velocities (split
// impulse), never by real speed, so a chain of deep overlaps separates without
// launching anything. One row per manifold, through the overlap's depth-weighted centre,
// so a face pushes straight and a tilted corner turns back.
void push_out(WideContact& wc, PushAnchors& anchors, int lane, SolverBody* bodies, PushVelocity* push_velocities,
              Real excess, const Vec3& ra, const Vec3& rb, const ContactSolveParams& params) {
    SolverBody& A = bodies[wc.a[lane]];
    SolverBody& B = bodies[wc.b[lane]];
    const Vec3 normal = wc.normal.lane(lane);
    float& impulse = wc.push_impulse[lane];
    SolverBody copy_a, copy_b;
    const SolverBody& Am = lane_body(wc, lane, 0, A, copy_a);
    const SolverBody& Bm = lane_body(wc, lane, 1, B, copy_b);
    ContactRow row;
    const Real mass = make_row(Am, Bm, ra, rb, normal, row);
    anchors = {ra, rb};
    PushVelocity& push_a = push_velocities[wc.a[lane]];
    PushVelocity& push_b = push_velocities[wc.b[lane]];
    Velocities push = load_push(push_a, push_b);
    const Real target = std::max(params.soft.bias_rate * excess, -params.push_out);
    const Real speed = row_speed(push, normal, row);
    const auto total = static_cast<float>(std::max(
        impulse - mass * params.soft.mass_scale * (speed + target) - params.soft.impulse_scale * impulse, Real(0)));
    apply_row(Am, Bm, push, normal, row, Real(total) - Real(impulse));
    impulse = total;
    store_push(A, B, push_a, push_b, push);
}

// Rolling resistance (Box3D's): the angular impulse that stops the relative spin, kept
// within the cap x the manifold's normal impulse. A lane without it has a zero cap, so
// its impulse stays zero.
inline void solve_rolling(WideRolling& r, WideVelocities& s, Wide pressed) {
    const Wide3 old = r.impulse;
    const Wide3 wanted = old - r.mass * (s.wb - s.wa);
    const Wide limit = r.cap * pressed;
    const Wide length_sq = dot(wanted, wanted);
    const Wide scale = select(length_sq > limit * limit, limit / wide_sqrt(length_sq), splat(1));
    r.impulse = scale * wanted;
    const Wide3 delta = r.impulse - old;
    s.wa -= r.inv_inertia_a * delta;
    s.wb += r.inv_inertia_b * delta;
}

// The lanes' normal impulses of the touching points only, summed (the friction cone) and
// weighted by each point's lever arm from the friction centre (the twist's): a
// speculative point far from the body (a fast sphere's, metres ahead) would spin it up
// through the lever arm.
struct TouchingImpulses {
    Wide pressed, twist_reach;
};

inline TouchingImpulses touching_impulses(const WideContact& wc, const Wide (&gap)[kMaxManifoldPoints],
                                          const ContactSolveParams& params) {
    const Wide slop = splat(params.slop);
    TouchingImpulses t{splat(0), splat(0)};
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        const Wide touching_impulse = select(gap[j] <= slop, wc.point_rows[j].normal_impulse, splat(0));
        t.pressed += touching_impulse;
        t.twist_reach += wc.points[j].lever_arm * touching_impulse;
    }
    return t;
}

// The two tangent rows' impulse changes d0, d1 at the friction centre applied as one: a
// linear impulse along d0 t0 + d1 t1 and both rows' angular terms.
template <bool kLocked>
inline void apply_tangents(const WideContact& wc, const WideAxisMasses& m, WideVelocities& s, Wide d0, Wide d1) {
    const Wide3 impulse = d0 * wc.tangent[0] + d1 * wc.tangent[1];
    if constexpr (kLocked) {
        s.va -= Wide3{m.a.x * impulse.x, m.a.y * impulse.y, m.a.z * impulse.z};
        s.vb += Wide3{m.b.x * impulse.x, m.b.y * impulse.y, m.b.z * impulse.z};
    } else {
        s.va -= wc.inv_mass_a * impulse;
        s.vb += wc.inv_mass_b * impulse;
    }
    s.wa -= d0 * wc.friction_row[0].ia + d1 * wc.friction_row[1].ia;
    s.wb += d0 * wc.friction_row[0].ib + d1 * wc.friction_row[1].ib;
}

// Central friction of the lanes (Box3D's): the twist about the normal within friction x
// the touching impulses' moments, then the two tangent rows at the centre, solved
// together by their 2x2 mass, within Coulomb's cone of friction x the touching impulse.
// A lane without friction has an empty cone.
template <bool kLocked>
[[gnu::always_inline]] inline void solve_friction(WideContact& wc, const WideAxisMasses& masses, WideVelocities& s,
                                                  const TouchingImpulses& touching, Wide turn_time,
                                                  EffectCounts& counts) {
    counts.friction += static_cast<std::uint64_t>(wc.lanes);
    {
        const Wide speed = dot(wc.normal, s.wb - s.wa);
        const Wide limit = wc.friction * touching.twist_reach;
        const Wide old = wc.twist_impulse;
        const Wide total = wide_min(wide_max(old - wc.twist_mass * speed, -limit), limit);
        wc.twist_impulse = total;
        apply_angular_row(s, wc.twist_row, total - old);
    }
    const Wide3 dv = point_velocity(s, wc.center_a, wc.center_b);
    // The surfaces' velocities at the pass's time in the step (prepare_friction).
    const Wide v0 = dot(wc.tangent[0], dv) + turn_time * wc.friction_turn[0];
    const Wide v1 = dot(wc.tangent[1], dv) + turn_time * wc.friction_turn[1];
    const Wide old0 = wc.friction_impulse[0], old1 = wc.friction_impulse[1];
    const Wide m00 = wc.friction_mass[0], m01 = wc.friction_mass[1], m11 = wc.friction_mass[2];
    Wide new0 = old0 - (m00 * v0 + m01 * v1);
    Wide new1 = old1 - (m01 * v0 + m11 * v1);
    const Wide limit = wc.friction * touching.pressed;
    const Wide length_sq = new0 * new0 + new1 * new1;
    const Wide scale = select(length_sq > limit * limit, limit / wide_sqrt(length_sq), splat(1));
    new0 *= scale;
    new1 *= scale;
    wc.friction_impulse[0] = new0;
    wc.friction_impulse[1] = new1;
    apply_tangents<kLocked>(wc, masses, s, new0 - old0, new1 - old1);
}

// The warm start's velocity changes: the impulses the contact has so far applied to `s`.
template <bool kLocked>
[[gnu::always_inline]] inline void apply_warm_start(const WideContact& wc, const WideAxisMasses& masses,
                                                    WideVelocities& s) {
    for (const WidePointRow& r : wc.point_rows) {
        apply_row<kLocked>(wc, masses, s, wc.normal, r.normal_row, r.normal_impulse);
    }
    if (any(wc.friction > splat(0))) {  // else the friction impulses are all zero
        apply_tangents<kLocked>(wc, masses, s, wc.friction_impulse[0], wc.friction_impulse[1]);
        apply_angular_row(s, wc.twist_row, wc.twist_impulse);
    }
    if (wc.rolls) {
        const WideRolling& r = *wc.rolling;
        s.wa -= r.inv_inertia_a * r.impulse;
        s.wb += r.inv_inertia_b * r.impulse;
    }
}

// The warm start of the lanes' push-out impulses on the push-out velocities.
void warm_start_push_lanes(const WideContact& wc, const PushAnchors* push_anchors, SolverBody* bodies,
                           PushVelocity* push_velocities) {
    for (int l = 0; l < kLanes; ++l) {
        if (wc.push_impulse[l] <= 0) continue;
        SolverBody& A = bodies[wc.a[l]];
        SolverBody& B = bodies[wc.b[l]];
        SolverBody copy_a, copy_b;
        const SolverBody& Am = lane_body(wc, l, 0, A, copy_a);
        const SolverBody& Bm = lane_body(wc, l, 1, B, copy_b);
        const Vec3 normal = wc.normal.lane(l);
        ContactRow row;
        make_row(Am, Bm, push_anchors[l].ra, push_anchors[l].rb, normal, row);
        PushVelocity& push_a = push_velocities[wc.a[l]];
        PushVelocity& push_b = push_velocities[wc.b[l]];
        Velocities push = load_push(push_a, push_b);
        apply_row(Am, Bm, push, normal, row, wc.push_impulse[l]);
        store_push(A, B, push_a, push_b, push);
    }
}

// The same where a lane has any (rare: deep overlap).
[[gnu::always_inline]] inline void warm_start_push(const WideContact& wc, const PushAnchors* push_anchors,
                                                   SolverBody* bodies, PushVelocity* push_velocities) {
    Wide impulses;
    std::memcpy(&impulses, wc.push_impulse, sizeof impulses);
    if (any(impulses > splat(0))) warm_start_push_lanes(wc, push_anchors, bodies, push_velocities);
}

// A lane's contact softness: stiffer against a static body.
struct LaneSoftness {
    Wide bias_rate, mass_scale, impulse_scale;
};

// A point row's bias and softness from its gap, fixed for a pass: a speculative point may
// close its gap, no more; resting overlap is corrected by the contact's own soft bias
// (soft step), deeper overlap left to push_out. The relax pass has no bias but the gap.
struct NormalTerms {
    Wide bias, mass_scale, impulse_scale;
};

template <bool kBias>
[[gnu::always_inline]] inline NormalTerms normal_terms(Wide separation, Wide recovery, const LaneSoftness& soft,
                                                       const ContactSolveParams& params) {
    const Wide zero = splat(0);
    const WideMask speculative = separation > zero;
    const Wide closing = separation * splat(params.inv_h);
    if constexpr (kBias) {
        const Wide soft_bias = wide_max(soft.bias_rate * wide_max(separation, -recovery), splat(-params.push_out));
        return {select(speculative, closing, soft_bias), select(speculative, splat(1), soft.mass_scale),
                select(speculative, zero, soft.impulse_scale)};
    } else {
        return {select(speculative, closing, zero), splat(1), zero};
    }
}

// Point j's normal row solved once on `s`; the impulse it applied. `fallen`: the lanes'
// relative speed along the normal gravity has added since the step began (see below).
// kMasked: in the lanes of `active` only (a lane's result never depends on which lanes
// share its wide contact).
template <bool kBias, bool kLocked, bool kMasked = false>
[[gnu::always_inline]] inline Wide solve_normal_row(WideContact& wc, const WideAxisMasses& masses, WideVelocities& s,
                                                    int j, const NormalTerms& terms, Wide fallen,
                                                    WideMask active = WideMask()) {
    const WidePoint& p = wc.points[j];
    WidePointRow& r = wc.point_rows[j];
    const Wide zero = splat(0);
    const Wide vn = dot(wc.normal, point_velocity(s, p.ra, p.rb));
    Wide impulse;
    if constexpr (kBias) {
        impulse = -p.normal_mass * terms.mass_scale * (vn + terms.bias) - terms.impulse_scale * r.normal_impulse;
    } else {
        impulse = -p.normal_mass * (vn + terms.bias);
    }
    const Wide total = wide_max(r.normal_impulse + impulse, zero);
    impulse = total - r.normal_impulse;
    if constexpr (kMasked) impulse = select(active, impulse, zero);
    // Restitution bounces off the approach speed at impact: the step's start's, with what
    // gravity added by the substep the point first pushes in. Not `vn`, the speed the
    // iteration has reached: that holds the other contacts' impulses not yet settled (the
    // warm start of a contact about to let go), and a ball struck into a row of touching
    // balls bounced the next one off at twice its speed (a Newton's cradle gained energy).
    if (wc.tracks_push) {
        Wide& approach = wc.relative_velocity[j];
        Wide& max_impulse = wc.max_normal_impulse[j];
        const WideMask first_push = (impulse > zero) & (max_impulse == zero);
        approach = select(first_push, wide_min(approach, approach + fallen), approach);
        max_impulse = wide_max(max_impulse, impulse);
    }
    if constexpr (kMasked) {
        r.normal_impulse = select(active, total, r.normal_impulse);
    } else {
        r.normal_impulse = total;
    }
    apply_row<kLocked>(wc, masses, s, wc.normal, r.normal_row, impulse);
    return impulse;
}

// At most this many sweeps over a wide contact's normal rows per pass, the first included.
constexpr int kNormalSweeps = 3;

// The sweeps after the first in the lanes whose bodies close fast (see solve_wide), each
// lane's until no row of it changes its point's speed by more than the settled speed. The
// rows' terms are the first sweep's. Rare: solve_wide's build with kSweeps, which only
// such wide contacts run.
template <bool kBias, bool kLocked>
[[gnu::always_inline]] inline void sweep_normal_rows(WideContact& wc, const WideAxisMasses& masses, WideVelocities& s,
                                                     const Wide (&gap)[kMaxManifoldPoints], const LaneSoftness& soft,
                                                     const ContactSolveParams& params) {
    NormalTerms terms[kMaxManifoldPoints];
    for (int j = 0; j < kMaxManifoldPoints; ++j) terms[j] = normal_terms<kBias>(gap[j], wc.recovery[j], soft, params);
    const Wide settled = splat(params.settled_speed);
    const Wide fallen = wc.gravity_normal * splat(params.fall_time);
    WideMask active;
    for (int l = 0; l < kLanes; ++l) active[l] = (wc.sweep_lanes >> l) & 1u ? -1 : 0;
    for (int sweep = 1; sweep < kNormalSweeps && any(active); ++sweep) {
        WideMask moved = splat(0) > splat(1);
        for (int j = 0; j < kMaxManifoldPoints; ++j) {
            const Wide impulse = solve_normal_row<kBias, kLocked, true>(wc, masses, s, j, terms[j], fallen, active);
            moved = moved | (wide_max(impulse, -impulse) > wc.points[j].normal_mass * settled);
        }
        active = active & moved;
    }
}

// kSweeps: the build that sweeps landing lanes again (wc.sweep_lanes). The passes pick it
// for the wide contacts with such lanes; the locked build, rare, always has it and asks.
template <bool kBias, bool kLocked, bool kWarm = false, bool kSweeps = kLocked>
void solve_wide(WideContact& wc, PushAnchors* push_anchors, SolverBody* bodies, PushVelocity* push,
                const ContactSolveParams& params, EffectCounts& counts, PushVelocity* warm = nullptr) {
    WideVelocities s = gather(wc, bodies);
    WideAxisMasses masses;
    if constexpr (kLocked) masses = axis_masses(wc, bodies);
    // Current separation from the bodies' motion since the step began:
    // n.(dpB - dpA + dqB rb - dqA ra), with n.(dq r) = (dq^-1 n).r so each body's
    // rotation is applied once per lane rather than once per point.
    Wide ma[kLanes], mb[kLanes];
    gather_rows(bodies, wc.a, kMotionRow, ma);
    gather_rows(bodies, wc.b, kMotionRow, mb);
    const Wide3 dpa{ma[0], ma[1], ma[2]}, dpb{mb[0], mb[1], mb[2]};
    const WideQuat dqa{{ma[3], ma[4], ma[5]}, ma[6]}, dqb{{mb[3], mb[4], mb[5]}, mb[6]};
    const Wide3 na = rotate_inverse(dqa, wc.normal);
    const Wide3 nb = rotate_inverse(dqb, wc.normal);
    const Wide zero = splat(0), one = splat(1);
    // The anchors turn with their bodies, but a round part's surface point along the
    // normal stays on the normal: a rolling ball's contact stays below its centre (with
    // the anchor alone it would seem to lift away as the ball turns, and sink).
    const Wide moved = dot(wc.normal, dpb - dpa) + wc.radius_a * (dot(na, wc.normal) - one) +
                       wc.radius_b * (dot(nb, wc.normal) - one);
    const WideMask stiff = wc.against_static > zero;
    const LaneSoftness soft{select(stiff, splat(params.static_soft.bias_rate), splat(params.soft.bias_rate)),
                            select(stiff, splat(params.static_soft.mass_scale), splat(params.soft.mass_scale)),
                            select(stiff, splat(params.static_soft.impulse_scale), splat(params.soft.impulse_scale))};
    // Overlap deeper than the recovery depth, per lane: its depth-weighted excess and centre.
    Wide deep_weight = zero, deep_excess = zero;
    Wide3 deep_ra, deep_rb;
    Wide gap[kMaxManifoldPoints];
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        gap[j] = moved + dot(nb, wc.points[j].rb) - dot(na, wc.points[j].ra) + wc.points[j].adjusted_separation;
    }
    // Friction comes first in the biased pass, within the cones of the normal impulses the
    // pass starts with (the warm start's or the last relax pass's): after the normal rows
    // their soft push would swell and shrink the cones, and a light body pushed against a
    // heavy one would be tied to it sideways. Without friction here the positions move
    // with the biased pass's frictionless velocities, and a pile resting on saturated
    // friction (a log in the groove of two) keeps whatever self-stress the order of the
    // colours left it.
    const bool rubs = any(wc.friction > zero);
    const Wide fallen = wc.gravity_normal * splat(params.fall_time);  // solve_normal_row's
    if constexpr (kBias) {
        if (rubs)
            solve_friction<kLocked>(wc, masses, s, touching_impulses(wc, gap, params), splat(params.turn_time), counts);
    }
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        counts.contact_points += wc.slot_points[j];
        if constexpr (kBias) {
            const WidePoint& p = wc.points[j];
            const Wide depth = select(gap[j] + wc.recovery[j] < zero, -(gap[j] + wc.recovery[j]), zero);
            deep_weight += depth;
            deep_excess -= depth * depth;
            deep_ra += depth * p.ra;
            deep_rb += depth * p.rb;
        }
        solve_normal_row<kBias, kLocked>(wc, masses, s, j, normal_terms<kBias>(gap[j], wc.recovery[j], soft, params),
                                         fallen);
    }
    // The points of a lane push on one pair of bodies, so each row's impulse changes the
    // others' speeds: one sweep in order leaves the later points a share of the earlier
    // ones' work. At rest, warm started, that share is small and the next substep takes
    // it up; where the points close fast it is not (a cube landing flat took 24, 18, 32
    // and 19 N s at its four corners and came off the floor turning), and the rows are
    // swept again until they settle (Gauss-Seidel on the manifold alone).
    if constexpr (kSweeps) {
        if (wc.sweep_lanes != 0) sweep_normal_rows<kBias, kLocked>(wc, masses, s, gap, soft, params);
    }
    // The relax pass: rolling resistance first (Box3D's), then friction, both within the
    // touching impulses the normal rows have just solved.
    if constexpr (!kBias) {
        if (rubs || wc.rolls) {
            const TouchingImpulses touching = touching_impulses(wc, gap, params);
            if (wc.rolls) {
                counts.rolling += static_cast<std::uint64_t>(wc.lanes);
                solve_rolling(*wc.rolling, s, touching.pressed);
            }
            if (rubs) solve_friction<kLocked>(wc, masses, s, touching, splat(params.turn_time), counts);
        }
    }
    scatter(wc, bodies, s);
    if constexpr (kWarm) {
        static_assert(!kBias, "the next substep's warm start follows its relax pass");
        WideVelocities change;
        apply_warm_start<kLocked>(wc, masses, change);
        scatter_add(wc, bodies, warm, change);
        warm_start_push(wc, push_anchors, bodies, push);
    }
    if constexpr (kBias) {
        if (!any(deep_weight > zero)) return;
        for (int l = 0; l < kLanes; ++l) {
            if (deep_weight[l] <= 0) continue;
            const Real w = deep_weight[l];
            push_out(wc, push_anchors[l], l, bodies, push, deep_excess[l] / w, deep_ra.lane(l) / w, deep_rb.lane(l) / w,
                     params);
        }
    }
}

template <bool kLocked>
void warm_start_wide(WideContact& wc, const PushAnchors* push_anchors, SolverBody* bodies,
                     PushVelocity* push_velocities) {
    WideVelocities s = gather(wc, bodies);
    WideAxisMasses masses;
    if constexpr (kLocked) masses = axis_masses(wc, bodies);
    apply_warm_start<kLocked>(wc, masses, s);
    scatter(wc, bodies, s);
    warm_start_push(wc, push_anchors, bodies, push_velocities);
}

// Sweeps of the restitution pass over a bouncing manifold's points (restitution_wide).
constexpr int kRestitutionSweeps = 4;

template <bool kLocked>
void restitution_wide(WideContact& wc, SolverBody* bodies, Real threshold, Real max_speed, Real h,
                      EffectCounts& counts) {
    const Wide zero = splat(0);
    const WideMask bouncy = wc.restitution > zero;
    if (!any(bouncy)) return;
    for (std::uint8_t points : wc.slot_points) counts.restitution += points;
    WideVelocities s = gather(wc, bodies);
    WideAxisMasses masses;
    if constexpr (kLocked) masses = axis_masses(wc, bodies);
    // The points bounce one after another (Gauss-Seidel), each changing the others' speeds:
    // in one sweep a box landing flat on four points left the last one its bounce and the
    // first ones less, so it rose short and turning. A few sweeps over the manifolds where
    // more than one point bounces bring them all to their bounce together (one point's
    // bounce is whole after one sweep: its manifold is swept once, as before).
    WideMask sweeping = bouncy;
    Wide bouncing = zero;  // per lane, the points that bounced in the first sweep
    for (int sweep = 0; sweep < kRestitutionSweeps; ++sweep) {
        if (sweep == 1) sweeping = sweeping & (bouncing > splat(1));
        if (!any(sweeping)) break;
        for (int j = 0; j < kMaxManifoldPoints; ++j) {
            const WidePoint& p = wc.points[j];
            WidePointRow& r = wc.point_rows[j];
            Wide& max_impulse = wc.max_normal_impulse[j];
            // Only points that approached fast enough and actually pushed bounce.
            const WideMask bounce = sweeping & (wc.relative_velocity[j] <= splat(-threshold)) & (max_impulse > zero);
            if (!any(bounce)) continue;
            if (sweep == 0) bouncing = bouncing + select(bounce, splat(1), zero);
            const Wide vn = dot(wc.normal, point_velocity(s, p.ra, p.rb));
            // Semi-implicit Euler conserves v^2/2 - a.x - h a.v/2, not the plain energy;
            // reversing v at an impact costs h a v of it unless the bounce speed gains a h.
            const Wide approach = wc.relative_velocity[j] + wc.gravity_normal * splat(h);
            // The bounce's speed no more than the speed limit: the step holds the stored
            // velocities to it, and the impulse is the next step's warm start too (a
            // restitution of 1e9 would hurl the bodies that far in its first substep).
            const Wide speed = -wide_min(approach, zero);
            const Wide rebound = select(speed > zero, wide_min(wc.restitution * speed, splat(max_speed)), zero);
            const Wide impulse = -p.normal_mass * (vn - rebound);
            const Wide total = wide_max(r.normal_impulse + impulse, zero);
            const Wide applied = select(bounce, total - r.normal_impulse, zero);
            r.normal_impulse += applied;
            max_impulse = wide_max(max_impulse, applied);
            apply_row<kLocked>(wc, masses, s, wc.normal, r.normal_row, applied);
        }
    }
    scatter(wc, bodies, s);
}

}  // namespace

void size_rolling_rows(SolverScratch& scratch) {
    // Not mapped ahead: few scenes write it, and most of its pages stay untouched.
    const std::size_t count = (scratch.listed_materials & kSummaryRolls) != 0 ? scratch.wide.size() : 0;
    reserve_for(scratch.rolling, count);
    scratch.rolling.resize(count);
    if (far_above_use(scratch.rolling.capacity(), count)) fit_capacity(scratch.rolling);
}

void prepare_contacts(const World& world, SolverScratch& scratch, const ContactSolveParams& params, std::uint32_t lo,
                      std::uint32_t hi) {
    WideRolling* const rolling = scratch.rolling.empty() ? nullptr : scratch.rolling.data();
    for (std::uint32_t k = lo; k < hi; ++k) {
        if (k + 1 < hi) prefetch_contacts(world, scratch, scratch.wide[k + 1]);
        prepare_wide(world, scratch, params, scratch.wide[k], rolling != nullptr ? rolling + k : nullptr);
    }
}

// Each pass in two builds: with per-axis inverse masses where a lane's body has a
// translation lock, with the scalar ones (no extra work) everywhere else.
void warm_start_contact(WideContact& wc, const PushAnchors* push_anchors, SolverBody* bodies, PushVelocity* push) {
    if (wc.locked) {
        warm_start_wide<true>(wc, push_anchors, bodies, push);
    } else {
        warm_start_wide<false>(wc, push_anchors, bodies, push);
    }
}

void solve_contact(WideContact& wc, PushAnchors* push_anchors, SolverBody* bodies, PushVelocity* push,
                   const ContactSolveParams& params, EffectCounts& counts) {
    if (wc.locked) {
        params.use_bias ? solve_wide<true, true>(wc, push_anchors, bodies, push, params, counts)
                        : solve_wide<false, true>(wc, push_anchors, bodies, push, params, counts);
    } else {
        if (wc.sweep_lanes != 0) {
            params.use_bias ? solve_wide<true, false, false, true>(wc, push_anchors, bodies, push, params, counts)
                            : solve_wide<false, false, false, true>(wc, push_anchors, bodies, push, params, counts);
        } else {
            params.use_bias ? solve_wide<true, false>(wc, push_anchors, bodies, push, params, counts)
                            : solve_wide<false, false>(wc, push_anchors, bodies, push, params, counts);
        }
    }
}

void relax_and_warm_start_contact(WideContact& wc, PushAnchors* push_anchors, SolverBody* bodies, PushVelocity* push,
                                  PushVelocity* warm, const ContactSolveParams& params, EffectCounts& counts) {
    SPINDLE_ASSERT(!params.use_bias, "solver: the warm start follows the relax pass, not the biased one");
    if (wc.locked) {
        solve_wide<false, true, true>(wc, push_anchors, bodies, push, params, counts, warm);
    } else if (wc.sweep_lanes != 0) {
        solve_wide<false, false, true, true>(wc, push_anchors, bodies, push, params, counts, warm);
    } else {
        solve_wide<false, false, true>(wc, push_anchors, bodies, push, params, counts, warm);
    }
}

void apply_restitution(WideContact& wc, SolverBody* bodies, Real threshold, Real max_speed, Real h,
                       EffectCounts& counts) {
    if (wc.locked) {
        restitution_wide<true>(wc, bodies, threshold, max_speed, h, counts);
    } else {
        restitution_wide<false>(wc, bodies, threshold, max_speed, h, counts);
    }
}

void store_contact_impulses(World& world, const SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi) {
    for (std::uint32_t k = lo; k < hi; ++k) {
        const WideContact& wc = scratch.wide[k];
        for (int l = 0; l < wc.lanes; ++l) {
            const ManifoldRef& ref = scratch.manifolds[wc.ref[l]];
            ContactManifold& m = world.contacts[ref.contact].manifold_at(static_cast<int>(ref.manifold));
            m.friction_impulse = wc.friction_impulse[0][l] * wc.tangent[0].lane(l) +
                                 wc.friction_impulse[1][l] * wc.tangent[1].lane(l);
            m.twist_impulse = wc.twist_impulse[l];
            m.support_scale = static_cast<float>(support_scale(scratch, wc.ref[l]).lower());
            m.pushed_point = -1;
            m.pushed_speed = 0;
            for (int j = 0; j < m.point_count; ++j) {
                m.points[j].normal_impulse = wc.point_rows[j].normal_impulse[l];
                if (!wc.tracks_push) continue;  // nothing reads which point pushed
                const float approach = -wc.relative_velocity[j][l];
                if (wc.max_normal_impulse[j][l] > 0 && (m.pushed_point < 0 || approach > m.pushed_speed)) {
                    m.pushed_point = static_cast<std::int8_t>(j);
                    m.pushed_speed = approach;
                }
            }
        }
        if (!wc.rolls) continue;
        for (int l = 0; l < wc.lanes; ++l) {
            const ManifoldRef& ref = scratch.manifolds[wc.ref[l]];
            ContactManifold& m = world.contacts[ref.contact].manifold_at(static_cast<int>(ref.manifold));
            m.rolling_impulse[0] = wc.rolling->impulse.x[l];
            m.rolling_impulse[1] = wc.rolling->impulse.y[l];
            m.rolling_impulse[2] = wc.rolling->impulse.z[l];
        }
    }
}

}  // namespace spindle
