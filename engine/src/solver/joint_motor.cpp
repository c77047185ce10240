// The motor joint (and the mouse joint built on it): a point row pulling B's anchor
// toward its target and three angular rows turning B toward its target orientation,
// each a soft-step spring (or the solver's joint softness) whose accumulated impulse is
// capped by the maximum force or torque, as Box2D's motor joint caps its own.
#include <algorithm>
#include <cmath>

#include "api/joint_store.hpp"
#include "solver/joint_rows.hpp"

namespace spindle {
namespace {

// Keeps an accumulated impulse within a ball of radius `max`: returns the part to apply.
Vec3 capped(Vec3& accumulated, const Vec3& impulse, Real max) {
    const Vec3 old = accumulated;
    Vec3 total = old + impulse;
    const Real norm = total.norm();
    if (norm > max) total *= max / norm;
    accumulated = total;
    return total - old;
}

// The drive is physics, not error correction: the same in solve and relax (as Box2D's
// motor joint, which biases in both). Unbiased in relax, a capped pull would undo there
// the speed it gave in the solve pass, and a body far from its target would never move.
Softness softness_of(bool spring, const Softness& own, const JointSolveParams& p) { return spring ? own : p.soft; }

}  // namespace

void prepare_motor(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb, Real h,
                   JointConstraint& jc) {
    const MotorParams& m = j.motor;
    jc.target = qa * m.linear_offset;
    jc.enable_spring = m.linear_hertz > 0;
    jc.spring = make_softness(m.linear_hertz, m.linear_damping_ratio, h);
    jc.max_motor_impulse = m.max_force * h;
    jc.linear_impulse = m.max_force > 0 ? j.linear_impulse : Vec3::Zero();
    jc.enable_angular_spring = m.angular_hertz > 0;
    jc.angular_spring = make_softness(m.angular_hertz, m.angular_damping_ratio, h);
    jc.max_torque_impulse = m.max_torque * h;
    jc.angular_impulse = Vec3::Zero();
    if (m.max_torque > 0) {
        jc.rotation_error = qb * (m.angular_offset * j.reference).conjugate() * qa.conjugate();
        jc.rotation_mass = inverse_or_pseudo(Mat3(A.inv_inertia + B.inv_inertia), has_locks(A, B));
        jc.angular_impulse = j.angular_impulse;
    }
}

// The target turns with A, so A's lever reaches it: ra + target.
void warm_start_motor(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s) {
    apply_angular(A, B, s, jc.angular_impulse);
    apply(A, B, s, A.dq * (jc.ra + jc.target), B.dq * jc.rb, jc.linear_impulse);
}

void solve_motor(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                 const JointSolveParams& p) {
    if (jc.max_torque_impulse > 0) {
        const Softness soft = softness_of(jc.enable_angular_spring, jc.angular_spring, p);
        const Vec3 c = rotation_error(jc, A.dq, B.dq);
        const Vec3 impulse = -soft.mass_scale * (jc.rotation_mass * (s.wb - s.wa + soft.bias_rate * c)) -
                             soft.impulse_scale * jc.angular_impulse;
        apply_angular(A, B, s, capped(jc.angular_impulse, impulse, jc.max_torque_impulse));
    }
    if (jc.max_motor_impulse > 0) {
        const Softness soft = softness_of(jc.enable_spring, jc.spring, p);
        const Vec3 ra = A.dq * jc.ra, rb = B.dq * jc.rb, target = A.dq * jc.target;
        const Vec3 la = ra + target;
        const Vec3 c = (B.dp - A.dp) + (rb - ra) + jc.delta_center - target;
        const Vec3 cdot = relative_velocity(s, la, rb);
        const Vec3 impulse = -soft.mass_scale * (point_mass(A, B, la, rb) * (cdot + soft.bias_rate * c)) -
                             soft.impulse_scale * jc.linear_impulse;
        apply(A, B, s, la, rb, capped(jc.linear_impulse, impulse, jc.max_motor_impulse));
    }
}

}  // namespace spindle
