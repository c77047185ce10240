// Hinge joints kLanes at a time in floats (joint_lanes.cpp runs them, before the point
// row): the rows of joint_solver.cpp's solve_hinge per lane, a motor and a limit about
// A's axis and two rows that keep B's axis on it. A lane without a motor has no torque
// to give, one without a limit no mass along the limit's row: they push nothing there.
#include "solver/joint_lanes.hpp"

namespace spindle {
namespace {

// The alignment rows now: C = (a1.b2, a1.c2) with a1 A's axis and b2, c2 perpendicular
// to B's; Cdot = u.(wB - wA) with u = b2 x a1, c2 x a1.
struct WideAlignRows {
    Wide3 axis;
    Wide3 u[2];
    Wide c[2];
};

WideAlignRows align_rows(const WideHinge& w, const WideMotion& m) {
    WideAlignRows r;
    r.axis = rotate(m.dqa, w.axis_a);
    const Wide3 b2 = rotate(m.dqb, w.perp_b[0]), c2 = rotate(m.dqb, w.perp_b[1]);
    r.u[0] = cross(b2, r.axis);
    r.u[1] = cross(c2, r.axis);
    r.c[0] = dot(r.axis, b2);
    r.c[1] = dot(r.axis, c2);
    return r;
}

// The two alignment rows as one soft 2x2 block, its inverse scaled by K's trace as
// joint_lanes.cpp's 3x3 is (0 where K is: nothing can turn).
void solve_alignment(const WideMotion& m, WideHinge& w, const WideAlignRows& rows, WideVelocities& s,
                     const JointSolveParams& p) {
    const Softness soft = pass_softness(p);
    const Wide3 ia0 = m.inv_inertia_a * rows.u[0], ib0 = m.inv_inertia_b * rows.u[0];
    const Wide3 ia1 = m.inv_inertia_a * rows.u[1], ib1 = m.inv_inertia_b * rows.u[1];
    const Wide zero = splat(0);
    const Wide trace = dot(rows.u[0], ia0 + ib0) + dot(rows.u[1], ia1 + ib1);
    const Wide scale = select(trace > zero, splat(1) / trace, zero);
    const Wide k00 = dot(rows.u[0], ia0 + ib0) * scale, k01 = dot(rows.u[0], ia1 + ib1) * scale;
    const Wide k11 = dot(rows.u[1], ia1 + ib1) * scale;
    const Wide det = k00 * k11 - k01 * k01;
    const Wide inv = select(det > zero, scale / det, zero);
    const Wide3 dw = s.wb - s.wa;
    const Wide bias = splat(soft.bias_rate);
    const Wide r0 = dot(rows.u[0], dw) + bias * rows.c[0], r1 = dot(rows.u[1], dw) + bias * rows.c[1];
    const Wide mass_scale = splat(soft.mass_scale), impulse_scale = splat(soft.impulse_scale);
    const Wide x0 = -mass_scale * (inv * (k11 * r0 - k01 * r1)) - impulse_scale * w.align_impulse[0];
    const Wide x1 = -mass_scale * (inv * (k00 * r1 - k01 * r0)) - impulse_scale * w.align_impulse[1];
    w.align_impulse[0] += x0;
    w.align_impulse[1] += x1;
    s.wa -= x0 * ia0 + x1 * ia1;
    s.wb += x0 * ib0 + x1 * ib1;
}

}  // namespace

void prepare_hinge_lane(WideHinge& w, int lane, const JointConstraint& jc) {
    w.axis_a.set_lane(lane, jc.axis_a);
    w.perp_b[0].set_lane(lane, jc.perp_b[0]);
    w.perp_b[1].set_lane(lane, jc.perp_b[1]);
    w.ref_a.set_lane(lane, jc.ref_a);
    w.ref_b.set_lane(lane, jc.ref_b);
    w.lower[lane] = static_cast<float>(jc.lower);
    w.upper[lane] = static_cast<float>(jc.upper);
    w.limited[lane] = jc.enable_limit ? -1 : 0;
    w.soft_limit[lane] = jc.soft_limit ? -1 : 0;
    w.spring_bias_rate[lane] = static_cast<float>(jc.limit_spring.bias_rate);
    w.spring_mass_scale[lane] = static_cast<float>(jc.limit_spring.mass_scale);
    w.spring_impulse_scale[lane] = static_cast<float>(jc.limit_spring.impulse_scale);
    w.motor_speed[lane] = static_cast<float>(jc.motor_speed);
    w.max_motor_impulse[lane] = jc.enable_motor ? static_cast<float>(jc.max_motor_impulse) : 0.0f;
    w.align_impulse[0][lane] = static_cast<float>(jc.align_impulse.x());
    w.align_impulse[1][lane] = static_cast<float>(jc.align_impulse.y());
    w.motor_impulse[lane] = static_cast<float>(jc.motor_impulse);
    w.lower_impulse[lane] = static_cast<float>(jc.lower_impulse);
    w.upper_impulse[lane] = static_cast<float>(jc.upper_impulse);
}

void warm_start_hinge_lanes(const WideHinge& w, const WideMotion& m, WideVelocities& s) {
    const WideAlignRows rows = align_rows(w, m);
    const Wide axial = w.motor_impulse + w.lower_impulse - w.upper_impulse;
    apply_angular(m, s, w.align_impulse[0] * rows.u[0] + w.align_impulse[1] * rows.u[1] + axial * rows.axis);
}

void solve_hinge_lanes(WideHinge& w, const WideMotion& m, WideVelocities& s, const JointSolveParams& p) {
    const WideAlignRows rows = align_rows(w, m);
    const WideAngularRow axial = angular_row(m, rows.axis);
    {
        const Wide cdot = angular_speed(s, axial.axis) - w.motor_speed;
        const Wide old = w.motor_impulse;
        w.motor_impulse = wide_min(wide_max(old - axial.mass * cdot, -w.max_motor_impulse), w.max_motor_impulse);
        apply_row(s, axial, w.motor_impulse - old);
    }
    if (any(w.limited)) {
        const Wide3 ra = rotate(m.dqa, w.ref_a), rb = rotate(m.dqb, w.ref_b);
        const Wide angle = wide_atan2(dot(rows.axis, cross(ra, rb)), dot(ra, rb));
        const WideSoftness pass = violated_softness(p);
        const WideSoftness violated{select(w.soft_limit, w.spring_bias_rate, pass.bias_rate),
                                    select(w.soft_limit, w.spring_mass_scale, pass.mass_scale),
                                    select(w.soft_limit, w.spring_impulse_scale, pass.impulse_scale)};
        const Wide mass = select(w.limited, axial.mass, splat(0));
        const Wide lower = limit_impulse(angle - w.lower, angular_speed(s, axial.axis), mass, w.lower_impulse, violated,
                                         p);
        apply_row(s, axial, lower);
        const Wide upper = limit_impulse(w.upper - angle, -angular_speed(s, axial.axis), mass, w.upper_impulse,
                                         violated, p);
        apply_row(s, axial, -upper);
    }
    solve_alignment(m, w, rows, s, p);
}

void store_hinge_lane(const WideHinge& w, int lane, JointConstraint& jc) {
    jc.align_impulse = Vec2(w.align_impulse[0][lane], w.align_impulse[1][lane]);
    jc.motor_impulse = w.motor_impulse[lane];
    jc.lower_impulse = w.lower_impulse[lane];
    jc.upper_impulse = w.upper_impulse[lane];
}

}  // namespace spindle
