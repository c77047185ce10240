// The rows every joint is built from (joint_solver.cpp), and each joint type's own
// prepare, warm start and solve (joint_<type>.cpp); joint_solver.cpp dispatches by type.
#pragma once

#include <Eigen/Eigenvalues>

#include "solver/constraints.hpp"

namespace spindle {

struct Joint;

// Inline, as the point row's effective mass below: the point row is most of a chain's
// solve, and these inlined into it when they were local to joint_solver.cpp.
inline Mat3 skew(const Vec3& v) {
    Mat3 m;
    m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    return m;
}

// Inverse of an effective-mass matrix, or zero when nothing can move along it. With a
// dynamic body in the joint K is positive definite (however heavy the body).
template <typename M>
M inverse_or_zero(const M& k) {
    return k.isZero(0) ? M(M::Zero()) : M(k.inverse());
}

// The same for a joint of a body with motion locks, where K may be singular (a direction
// along which neither body can move): the pseudo-inverse, which pushes only where
// something can move and leaves the locked directions alone.
template <typename M>
M inverse_or_pseudo(const M& k, bool locked) {
    if (!locked) return inverse_or_zero(k);
    const Eigen::SelfAdjointEigenSolver<M> eigen(k);
    const auto& values = eigen.eigenvalues();
    const Real cutoff = 1e-12 * values.cwiseAbs().maxCoeff();
    M inverse = M::Zero();
    for (int i = 0; i < M::RowsAtCompileTime; ++i) {
        if (values[i] > cutoff)
            inverse += (1 / values[i]) * eigen.eigenvectors().col(i) * eigen.eigenvectors().col(i).transpose();
    }
    return inverse;
}

inline bool has_locks(const SolverBody& A, const SolverBody& B) { return (A.locks | B.locks) != 0; }

// 1 / (a.(Ia^-1 + Ib^-1) a): one angular row about a unit axis (0 if nothing can turn).
inline Real angular_mass(const SolverBody& A, const SolverBody& B, const Vec3& axis) {
    const Real k = axis.dot((A.inv_inertia + B.inv_inertia) * axis);
    return k > 0 ? 1 / k : 0;
}

// The softness of one pass: full strength with use_bias, none (relax) without.
inline Softness pass_softness(const JointSolveParams& p) { return p.use_bias ? p.soft : Softness{0, 1, 0}; }

// One side of a limit that allows C >= 0: speculative while apart (may close the gap,
// no more), soft while violated: the pass's joint softness, or the limit's own `spring`
// (physics, not error correction: the same in solve and relax). Returns the impulse to
// apply (the total stays >= 0).
Real limit_impulse(Real c, Real cdot, Real mass, Real& accumulated, const JointSolveParams& p,
                   const Softness* spring = nullptr);

// Point constraint (ball-socket, and the point part of the other joints): the anchors
// coincide, solved as one 3x3 block.
void solve_point(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                 const JointSolveParams& p);

// The 3x3 effective mass of a point row with levers ra, rb (pseudo-inverse with locks).
inline Mat3 point_mass(const SolverBody& A, const SolverBody& B, const Vec3& ra, const Vec3& rb) {
    const Mat3 sa = skew(ra), sb = skew(rb);
    // Inverse masses per world axis: zero along a locked one.
    const Vec3 linear = project_linear(Vec3::Constant(A.inv_mass), A.locks) +
                        project_linear(Vec3::Constant(B.inv_mass), B.locks);
    const Mat3 k = Mat3(linear.asDiagonal()) + sa * A.inv_inertia * sa.transpose() +
                   sb * B.inv_inertia * sb.transpose();
    return inverse_or_pseudo(k, has_locks(A, B));
}
// Rotation vector of B away from its target orientation relative to A (jc.rotation_error
// at the step's start, turned by the substeps' deltas).
Vec3 rotation_error(const JointConstraint& jc, const Quat& dqa, const Quat& dqb);

// Three angular rows that hold B's orientation relative to A's (fixed, prismatic), from
// jc.rotation_error and jc.rotation_mass, accumulated in jc.angular_impulse.
void solve_rotation_lock(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                         const JointSolveParams& p);
// jc.rotation_error, rotation_mass and angular_impulse for the step.
void prepare_rotation_lock(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb,
                           JointConstraint& jc);

// Some unit vector perpendicular to a unit vector.
Vec3 perpendicular(const Vec3& n);

// Swing-twist (joint_swing_twist.cpp). The decomposition of B's pose relative to A's,
// from the twist axes and twist references in world: the swing takes A's twist axis to
// B's by the shortest arc, the twist turns about B's axis after it.
struct SwingTwistAngles {
    Real swing = 0;                   // rad, in [0, pi]
    Real twist = 0;                   // rad, in (-pi, pi]
    Vec3 swing_axis = Vec3::Zero();   // unit; zero while there is no swing to speak of
    Vec3 twist_axis = Vec3::UnitY();  // halfway between the two twist axes
};
SwingTwistAngles swing_twist_angles(const Vec3& axis_a, const Vec3& axis_b, const Vec3& ref_a, const Vec3& ref_b);
// How far the pose is outside the cone or the twist range (rad, the larger).
Real swing_twist_violation(const SwingTwistAngles& angles, const SwingTwistParams& params);
// qa, qb: the bodies' orientations at the step's start.
void prepare_swing_twist(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb,
                         Real h, JointConstraint& jc);
void warm_start_swing_twist(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s);
void solve_swing_twist(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                       const JointSolveParams& p);

// Prismatic (joint_prismatic.cpp).
void prepare_prismatic(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb, Real h,
                       JointConstraint& jc);
void warm_start_prismatic(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s);
void solve_prismatic(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                     const JointSolveParams& p);
// The translation and how far B's anchor is off the axis, from the anchors in world.
struct PrismaticOffset {
    Real translation = 0;  // along the axis, from the pose at creation
    Real off_axis = 0;     // m
};
PrismaticOffset prismatic_offset(const Joint& j, const Vec3& axis, const Vec3& anchor_a, const Vec3& anchor_b);
// The world impulse the two perpendicular rows carried, back to the rows (warm starting:
// the rows turn between steps).
Vec2 onto_rows(const Vec3 (&rows)[2], const Vec3& impulse);

// Motor (joint_motor.cpp).
void prepare_motor(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb, Real h,
                   JointConstraint& jc);
void warm_start_motor(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s);
void solve_motor(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                 const JointSolveParams& p);

}  // namespace spindle
