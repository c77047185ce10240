// The prismatic joint (a slider): three angular rows hold the relative rotation, two
// linear rows keep B's anchor on A's axis, and along the axis a spring, a motor and
// limits, each optional. The axis turns with A, so every linear row's lever on A reaches
// B's anchor (ra + d), as in Box2D's prismatic joint.
#include <algorithm>
#include <cmath>

#include "api/joint_store.hpp"
#include "solver/joint_rows.hpp"

namespace spindle {
namespace {

// The joint's frames now, from the deltas of the substeps so far.
struct SliderFrame {
    Vec3 axis;
    Vec3 perp[2];
    Vec3 la, rb;  // levers: A's reaches B's anchor (ra + d), B's is its anchor
    Real translation = 0;
};

SliderFrame frame_now(const JointConstraint& jc, const SolverBody& A, const SolverBody& B) {
    SliderFrame f;
    f.axis = A.dq * jc.axis_a;
    f.perp[0] = A.dq * jc.perp_a[0];
    f.perp[1] = A.dq * jc.perp_a[1];
    const Vec3 ra = A.dq * jc.ra;
    f.rb = B.dq * jc.rb;
    const Vec3 d = (B.dp - A.dp) + (f.rb - ra) + jc.delta_center;  // small deltas: exact far from the origin
    f.la = ra + d;
    f.translation = f.axis.dot(d) - jc.rest_length;
    return f;
}

Real row_speed(const Velocities& s, const SliderFrame& f, const Vec3& dir) {
    return dir.dot(s.vb - s.va) + s.wb.dot(f.rb.cross(dir)) - s.wa.dot(f.la.cross(dir));
}

bool any_axial(const JointConstraint& jc) { return jc.enable_spring || jc.enable_motor || jc.enable_limit; }

}  // namespace

PrismaticOffset prismatic_offset(const Joint& j, const Vec3& axis, const Vec3& anchor_a, const Vec3& anchor_b) {
    const Vec3 d = anchor_b - anchor_a;
    const Real along = axis.dot(d);
    return {along - j.rest_length, (d - along * axis).norm()};
}

void prepare_prismatic(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb, Real h,
                       JointConstraint& jc) {
    const PrismaticParams& p = j.prismatic;
    prepare_rotation_lock(j, A, B, qa, qb, jc);
    jc.axis_a = qa * j.axis_a;
    jc.perp_a[0] = qa * j.ref_a;
    jc.perp_a[1] = jc.axis_a.cross(jc.perp_a[0]);
    jc.align_impulse = onto_rows(jc.perp_a, j.linear_impulse);
    jc.rest_length = j.rest_length;
    jc.enable_limit = p.enable_limit;
    jc.lower = p.lower_translation;
    jc.upper = p.upper_translation;
    jc.enable_spring = p.enable_spring && p.spring_hertz > 0;
    jc.spring = make_softness(p.spring_hertz, p.spring_damping_ratio, h);
    jc.target_translation = p.target_translation;
    jc.enable_motor = p.enable_motor;
    jc.motor_speed = p.motor_speed;
    jc.max_motor_impulse = p.max_motor_force * h;
    jc.axial_impulse = jc.enable_spring ? j.axial_impulse : 0;
    jc.motor_impulse = p.enable_motor ? j.motor_impulse : 0;
    jc.lower_impulse = p.enable_limit ? j.lower_impulse : 0;
    jc.upper_impulse = p.enable_limit ? j.upper_impulse : 0;
}

void warm_start_prismatic(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s) {
    const SliderFrame f = frame_now(jc, A, B);
    const Real axial = jc.axial_impulse + jc.motor_impulse + jc.lower_impulse - jc.upper_impulse;
    apply_angular(A, B, s, jc.angular_impulse);
    apply(A, B, s, f.la, f.rb, axial * f.axis + jc.align_impulse.x() * f.perp[0] + jc.align_impulse.y() * f.perp[1]);
}

// Along the axis first (spring, motor, limits), then the rotation, then the two rows
// that keep B on the axis: what holds the slider matters most and goes last.
void solve_prismatic(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                     const JointSolveParams& p) {
    SliderFrame f = frame_now(jc, A, B);
    if (any_axial(jc)) {
        const Real mass = effective_mass(A, B, f.la, f.rb, f.axis);
        if (jc.enable_spring) {
            // The spring is physics, not error correction: the same in solve and relax.
            const Real c = f.translation - jc.target_translation;
            const Real impulse = -jc.spring.mass_scale * mass * (row_speed(s, f, f.axis) + jc.spring.bias_rate * c) -
                                 jc.spring.impulse_scale * jc.axial_impulse;
            jc.axial_impulse += impulse;
            apply(A, B, s, f.la, f.rb, impulse * f.axis);
        }
        if (jc.enable_motor) {
            const Real old = jc.motor_impulse;
            jc.motor_impulse = std::clamp(old - mass * (row_speed(s, f, f.axis) - jc.motor_speed),
                                          -jc.max_motor_impulse, jc.max_motor_impulse);
            apply(A, B, s, f.la, f.rb, (jc.motor_impulse - old) * f.axis);
        }
        if (jc.enable_limit) {
            const Real lower = limit_impulse(f.translation - jc.lower, row_speed(s, f, f.axis), mass, jc.lower_impulse,
                                             p);
            apply(A, B, s, f.la, f.rb, lower * f.axis);
            const Real upper = limit_impulse(jc.upper - f.translation, -row_speed(s, f, f.axis), mass, jc.upper_impulse,
                                             p);
            apply(A, B, s, f.la, f.rb, -upper * f.axis);
        }
    }
    solve_rotation_lock(jc, A, B, s, p);
    {
        const Softness soft = pass_softness(p);
        const Vec3 linear = project_linear(Vec3::Constant(A.inv_mass), A.locks) +
                            project_linear(Vec3::Constant(B.inv_mass), B.locks);
        Vec3 lever_a[2], lever_b[2];
        Vec2 c, cdot;
        const Vec3 d = f.la - A.dq * jc.ra;
        for (int r = 0; r < 2; ++r) {
            lever_a[r] = f.la.cross(f.perp[r]);
            lever_b[r] = f.rb.cross(f.perp[r]);
            c[r] = f.perp[r].dot(d);
            cdot[r] = row_speed(s, f, f.perp[r]);
        }
        Mat2 k;
        for (int r = 0; r < 2; ++r) {
            for (int q = 0; q < 2; ++q) {
                k(r, q) = f.perp[r].dot(linear.cwiseProduct(f.perp[q])) + lever_a[r].dot(A.inv_inertia * lever_a[q]) +
                          lever_b[r].dot(B.inv_inertia * lever_b[q]);
            }
        }
        const Vec2 impulse = -soft.mass_scale * (inverse_or_pseudo(k, has_locks(A, B)) * (cdot + soft.bias_rate * c)) -
                             soft.impulse_scale * jc.align_impulse;
        jc.align_impulse += impulse;
        apply(A, B, s, f.la, f.rb, impulse.x() * f.perp[0] + impulse.y() * f.perp[1]);
    }
}

}  // namespace spindle
