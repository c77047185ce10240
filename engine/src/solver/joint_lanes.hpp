// What the joints solved kLanes at a time share: joint_lanes.cpp packs and runs their
// blocks and solves the point row every lane joint has; joint_swing_twist.cpp and
// joint_hinge.cpp add their types' angular rows, with the helpers below.
#pragma once

#include "solver/body_lanes.hpp"
#include "solver/joint_rows.hpp"

namespace spindle {

// The lanes' rotations and motion since the step began.
struct WideMotion {
    Wide3 dpa, dpb;
    WideQuat dqa, dqb;
    // The bodies' inverse inertias now: the step's start's (WideJoint's) turned by dqa, dqb,
    // or the start's where no lane's body turns them (WideJoint::turns_a, turns_b); why:
    // solver_body.hpp's turned().
    const WideSym3& inv_inertia_a;
    const WideSym3& inv_inertia_b;
};

// An angular row about `axis` (not necessarily unit): the turn an impulse along it gives
// each body, and 1 / (axis.(Ia^-1 + Ib^-1) axis), 0 where nothing can turn.
struct WideAngularRow {
    Wide3 axis, ia, ib;  // axis, Ia^-1 axis, Ib^-1 axis
    Wide mass{};
};

inline WideAngularRow angular_row(const WideMotion& m, const Wide3& axis) {
    WideAngularRow r{axis, m.inv_inertia_a * axis, m.inv_inertia_b * axis, {}};
    const Wide k = dot(axis, r.ia) + dot(axis, r.ib);
    r.mass = select(k > splat(0), splat(1) / k, splat(0));
    return r;
}

// An angular impulse `impulse` x axis: -on A, +on B.
inline void apply_row(WideVelocities& s, const WideAngularRow& r, const Wide& impulse) {
    s.wa -= impulse * r.ia;
    s.wb += impulse * r.ib;
}
inline void apply_angular(const WideMotion& m, WideVelocities& s, const Wide3& impulse) {
    s.wa -= m.inv_inertia_a * impulse;
    s.wb += m.inv_inertia_b * impulse;
}

// The rows' relative angular speed along a row: axis.(wb - wa).
inline Wide angular_speed(const WideVelocities& s, const Wide3& axis) { return dot(axis, s.wb - s.wa); }

// The softness of a violated limit, per lane (a soft limit's spring, or the pass's).
struct WideSoftness {
    Wide bias_rate{}, mass_scale{}, impulse_scale{};
};
inline WideSoftness splat(const Softness& s) {
    return {splat(s.bias_rate), splat(s.mass_scale), splat(s.impulse_scale)};
}
inline WideSoftness violated_softness(const JointSolveParams& p) { return splat(pass_softness(p)); }

// joint_rows.hpp's limit_impulse per lane: speculative while apart, `violated` while the
// limit is. Returns the impulse to apply (the total stays >= 0); lanes with no mass push
// nothing.
inline Wide limit_impulse(const Wide& c, const Wide& cdot, const Wide& mass, Wide& accumulated,
                          const WideSoftness& violated, const JointSolveParams& p) {
    const WideMask apart = c > splat(0);
    const Wide bias_rate = select(apart, splat(p.inv_h), violated.bias_rate);
    const Wide mass_scale = select(apart, splat(1), violated.mass_scale);
    const Wide impulse_scale = select(apart, splat(0), violated.impulse_scale);
    const Wide impulse = -mass_scale * mass * (cdot + bias_rate * c) - impulse_scale * accumulated;
    const Wide total = wide_max(accumulated + impulse, splat(0));
    const Wide applied = total - accumulated;
    accumulated = total;
    return applied;
}

// atan2 per lane, in (-pi, pi], to within a few float roundings: the arctangent of the
// smaller over the larger of |y|, |x| by Abramowitz and Stegun's 4.4.49 (error below 2e-8
// on [0, 1]), then put in its octant. 0 for (0, 0).
inline Wide wide_atan2(const Wide& y, const Wide& x) {
    const Wide zero = splat(0);
    const Wide ax = select(x < zero, -x, x), ay = select(y < zero, -y, y);
    const Wide big = wide_max(ax, ay), small = wide_min(ax, ay);
    const Wide t = select(big > zero, small / big, zero);
    const Wide t2 = t * t;
    Wide p = splat(0.0028662257);
    for (const double a :
         {-0.0161657367, 0.0429096138, -0.0752896400, 0.1065626393, -0.1420889944, 0.1999355085, -0.3333314528, 1.0})
        p = p * t2 + splat(a);
    Wide r = t * p;
    r = select(ay > ax, splat(kPi / 2) - r, r);
    r = select(x < zero, splat(kPi) - r, r);
    return select(y < zero, -r, r);
}

inline Wide length(const Wide3& v) { return wide_sqrt(dot(v, v)); }

// Swing-twist lanes (joint_swing_twist.cpp): a lane from the prepared constraint, the
// rows' warm start and solve (before the point row), and the lane's impulses back.
void prepare_swing_twist_lane(WideSwingTwist& w, int lane, const JointConstraint& jc);
void warm_start_swing_twist_lanes(const WideSwingTwist& w, const WideMotion& m, WideVelocities& s);
void solve_swing_twist_lanes(WideSwingTwist& w, const WideMotion& m, WideVelocities& s, const JointSolveParams& p);
void store_swing_twist_lane(const WideSwingTwist& w, int lane, JointConstraint& jc);

// Hinge lanes (joint_hinge.cpp), the same.
void prepare_hinge_lane(WideHinge& w, int lane, const JointConstraint& jc);
void warm_start_hinge_lanes(const WideHinge& w, const WideMotion& m, WideVelocities& s);
void solve_hinge_lanes(WideHinge& w, const WideMotion& m, WideVelocities& s, const JointSolveParams& p);
void store_hinge_lane(const WideHinge& w, int lane, JointConstraint& jc);

}  // namespace spindle
