// The swing-twist joint (ragdoll shoulders, hips, necks): the point constraint, a cone
// limit on the swing of B's twist axis away from A's, a range on the twist about it, and
// friction against both. One row along the swing axis for the cone, one per twist side.
// Solved one at a time in doubles for a body with motion locks, kLanes at a time in
// floats otherwise (the lanes below; joint_lanes.cpp runs them).
#include <algorithm>
#include <cmath>

#include "api/joint_store.hpp"
#include "solver/joint_lanes.hpp"

namespace spindle {
namespace {

// Below this the swing axis (a x b normalised) is noise, and a cone of any size is far off.
constexpr Real kMinSwingSine = 1e-9;

// Twist ranges that cover the whole turn have no limit (the angle wraps at pi).
bool limits_twist(const JointConstraint& jc) { return jc.lower > -kPi || jc.upper < kPi; }

SwingTwistAngles angles_now(const JointConstraint& jc, const SolverBody& A, const SolverBody& B) {
    return swing_twist_angles(A.dq * jc.axis_a, B.dq * jc.axis_b, A.dq * jc.ref_a, B.dq * jc.ref_b);
}

// The swing's sine and axis and the twist axis: all a warm start needs (no angle, so no
// arctangent and no reference turned).
void swing_twist_axes(const Vec3& axis_a, const Vec3& axis_b, SwingTwistAngles& r, Real& sine, Vec3& cross) {
    cross = axis_a.cross(axis_b);
    sine = cross.norm();
    if (sine > kMinSwingSine) r.swing_axis = cross / sine;
    const Vec3 halfway = axis_a + axis_b;
    r.twist_axis = halfway.norm() > 1e-6 ? Vec3(halfway.normalized()) : axis_a;
}

}  // namespace

SwingTwistAngles swing_twist_angles(const Vec3& axis_a, const Vec3& axis_b, const Vec3& ref_a, const Vec3& ref_b) {
    SwingTwistAngles r;
    Real sine;
    Vec3 cross;
    swing_twist_axes(axis_a, axis_b, r, sine, cross);
    r.swing = std::atan2(sine, axis_a.dot(axis_b));
    // Undo the swing on B's reference: what is left is a turn about A's axis, the twist.
    const Vec3 unswung = Quat::FromTwoVectors(axis_b, axis_a) * ref_b;
    r.twist = std::atan2(axis_a.dot(ref_a.cross(unswung)), ref_a.dot(unswung));
    return r;
}

Real swing_twist_violation(const SwingTwistAngles& angles, const SwingTwistParams& params) {
    return std::max({Real(0), angles.swing - params.cone_half_angle, params.twist_min - angles.twist,
                     angles.twist - params.twist_max});
}

void prepare_swing_twist(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb,
                         Real h, JointConstraint& jc) {
    const SwingTwistParams& p = j.swing_twist;
    jc.axis_a = qa * j.axis_a;
    jc.axis_b = qb * j.axis_b;
    jc.ref_a = qa * j.ref_a;
    jc.ref_b = qb * j.ref_b;
    jc.cone = p.cone_half_angle;
    jc.lower = p.twist_min;
    jc.upper = p.twist_max;
    jc.swing_impulse = jc.cone < kPi ? j.swing_impulse : 0;
    jc.lower_impulse = limits_twist(jc) ? j.lower_impulse : 0;
    jc.upper_impulse = limits_twist(jc) ? j.upper_impulse : 0;
    jc.max_friction_impulse = p.max_friction_torque * h;
    jc.angular_impulse = p.max_friction_torque > 0 ? j.angular_impulse : Vec3::Zero();
    if (p.max_friction_torque > 0) {
        jc.rotation_mass = inverse_or_pseudo(Mat3(A.inv_inertia + B.inv_inertia), has_locks(A, B));
    }
}

void warm_start_swing_twist(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s) {
    SwingTwistAngles angles;
    Real sine;
    Vec3 cross;
    swing_twist_axes(A.dq * jc.axis_a, B.dq * jc.axis_b, angles, sine, cross);
    apply_angular(A, B, s,
                  jc.angular_impulse - jc.swing_impulse * angles.swing_axis +
                      (jc.lower_impulse - jc.upper_impulse) * angles.twist_axis);
}

// Friction first (it is not error correction: the same in solve and relax), then the
// limits, then the point, which matters most.
void solve_swing_twist(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                       const JointSolveParams& p) {
    if (jc.max_friction_impulse > 0) {
        const Vec3 old = jc.angular_impulse;
        Vec3 total = old - jc.rotation_mass * (s.wb - s.wa);
        const Real norm = total.norm();
        if (norm > jc.max_friction_impulse) total *= jc.max_friction_impulse / norm;
        jc.angular_impulse = total;
        apply_angular(A, B, s, total - old);
    }
    const SwingTwistAngles angles = angles_now(jc, A, B);
    if (limits_twist(jc)) {
        const Vec3& axis = angles.twist_axis;
        const Real mass = angular_mass(A, B, axis);
        const Real lower = limit_impulse(angles.twist - jc.lower, axis.dot(s.wb - s.wa), mass, jc.lower_impulse, p);
        apply_angular(A, B, s, lower * axis);
        const Real upper = limit_impulse(jc.upper - angles.twist, axis.dot(s.wa - s.wb), mass, jc.upper_impulse, p);
        apply_angular(A, B, s, -upper * axis);
    }
    if (jc.cone < kPi && angles.swing_axis != Vec3::Zero()) {
        // The swing grows along a x b: the row allows swing <= cone.
        const Vec3& axis = angles.swing_axis;
        const Real impulse = limit_impulse(jc.cone - angles.swing, axis.dot(s.wa - s.wb), angular_mass(A, B, axis),
                                           jc.swing_impulse, p);
        apply_angular(A, B, s, -impulse * axis);
    }
    solve_point(jc, A, B, s, p);
}

// The lanes: the rows above, per lane. A lane without a twist range or a cone has no mass
// along its row, so it pushes nothing there.
namespace {

struct WideAxes {
    Wide3 a, b;         // the twist axes now
    Wide3 cross;        // a x b
    Wide sine{};        // |a x b|
    Wide3 swing_axis;   // unit; zero where there is no swing to speak of
    Wide3 twist_axis;   // halfway between the two twist axes
    WideMask swings{};  // lanes with a swing axis
};

WideAxes wide_axes(const WideSwingTwist& w, const WideMotion& m) {
    WideAxes r;
    r.a = rotate(m.dqa, w.axis_a);
    r.b = rotate(m.dqb, w.axis_b);
    r.cross = spindle::cross(r.a, r.b);
    r.sine = length(r.cross);
    r.swings = r.sine > splat(kMinSwingSine);
    r.swing_axis = select(r.swings, splat(1) / r.sine, splat(0)) * r.cross;
    const Wide3 halfway = r.a + r.b;
    const Wide norm = length(halfway);
    const WideMask apart = norm > splat(1e-6);
    const Wide inv = select(apart, splat(1) / norm, splat(0));
    r.twist_axis = {select(apart, inv * halfway.x, r.a.x), select(apart, inv * halfway.y, r.a.y),
                    select(apart, inv * halfway.z, r.a.z)};
    return r;
}

}  // namespace

void prepare_swing_twist_lane(WideSwingTwist& w, int lane, const JointConstraint& jc) {
    w.axis_a.set_lane(lane, jc.axis_a);
    w.axis_b.set_lane(lane, jc.axis_b);
    w.ref_a.set_lane(lane, jc.ref_a);
    w.ref_b.set_lane(lane, jc.ref_b);
    w.cone[lane] = static_cast<float>(jc.cone);
    w.lower[lane] = static_cast<float>(jc.lower);
    w.upper[lane] = static_cast<float>(jc.upper);
    w.limits_cone[lane] = jc.cone < kPi ? -1 : 0;
    w.limits_twist[lane] = limits_twist(jc) ? -1 : 0;
    w.max_friction_impulse[lane] = static_cast<float>(jc.max_friction_impulse);
    w.rotation_mass.set_lane(lane, jc.max_friction_impulse > 0 ? jc.rotation_mass : Mat3::Zero());
    w.friction_impulse.set_lane(lane, jc.angular_impulse);
    w.swing_impulse[lane] = static_cast<float>(jc.swing_impulse);
    w.lower_impulse[lane] = static_cast<float>(jc.lower_impulse);
    w.upper_impulse[lane] = static_cast<float>(jc.upper_impulse);
}

void warm_start_swing_twist_lanes(const WideSwingTwist& w, const WideMotion& m, WideVelocities& s) {
    const WideAxes axes = wide_axes(w, m);
    apply_angular(m, s,
                  w.friction_impulse - w.swing_impulse * axes.swing_axis +
                      (w.lower_impulse - w.upper_impulse) * axes.twist_axis);
}

void solve_swing_twist_lanes(WideSwingTwist& w, const WideMotion& m, WideVelocities& s, const JointSolveParams& p) {
    {
        const Wide3 old = w.friction_impulse;
        Wide3 total = old - w.rotation_mass * (s.wb - s.wa);
        const Wide norm = length(total);
        total = select(norm > w.max_friction_impulse, w.max_friction_impulse / norm, splat(1)) * total;
        w.friction_impulse = total;
        apply_angular(m, s, total - old);
    }
    const WideAxes axes = wide_axes(w, m);
    const Wide cosine = dot(axes.a, axes.b);
    const Wide swing = wide_atan2(axes.sine, cosine);
    // Undo the swing on B's reference (the shortest arc from b to a by Rodrigues' formula,
    // its axis k = b x a): what is left is a turn about A's axis, the twist. Where b is
    // opposite a the arc has no axis, and the lanes take no twist.
    const Wide3 ref_a = rotate(m.dqa, w.ref_a), ref_b = rotate(m.dqb, w.ref_b);
    const Wide3 k = {-axes.cross.x, -axes.cross.y, -axes.cross.z};
    const Wide one_plus = splat(1) + cosine;
    const WideMask turns = one_plus > splat(1e-6);
    const Wide3 unswung = cosine * ref_b + spindle::cross(k, ref_b) +
                          select(turns, dot(k, ref_b) / one_plus, splat(0)) * k;
    const Wide twist = select(turns, wide_atan2(dot(axes.a, spindle::cross(ref_a, unswung)), dot(ref_a, unswung)),
                              splat(0));
    const WideSoftness violated = violated_softness(p);
    if (any(w.limits_twist)) {
        const WideAngularRow row = angular_row(m, axes.twist_axis);
        const Wide mass = select(w.limits_twist, row.mass, splat(0));
        const Wide lower = limit_impulse(twist - w.lower, angular_speed(s, row.axis), mass, w.lower_impulse, violated,
                                         p);
        apply_row(s, row, lower);
        const Wide upper = limit_impulse(w.upper - twist, -angular_speed(s, row.axis), mass, w.upper_impulse, violated,
                                         p);
        apply_row(s, row, -upper);
    }
    const WideMask cone = w.limits_cone & axes.swings;
    if (any(cone)) {
        // The swing grows along a x b: the row allows swing <= cone.
        const WideAngularRow row = angular_row(m, axes.swing_axis);
        const Wide impulse = limit_impulse(w.cone - swing, -angular_speed(s, row.axis),
                                           select(cone, row.mass, splat(0)), w.swing_impulse, violated, p);
        apply_row(s, row, -impulse);
    }
}

void store_swing_twist_lane(const WideSwingTwist& w, int lane, JointConstraint& jc) {
    jc.angular_impulse = w.friction_impulse.lane(lane);
    jc.swing_impulse = w.swing_impulse[lane];
    jc.lower_impulse = w.lower_impulse[lane];
    jc.upper_impulse = w.upper_impulse[lane];
}

}  // namespace spindle
