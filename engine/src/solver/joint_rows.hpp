// The rows every joint is built from (joint_solver.cpp), and each joint type's own
// prepare, warm start and solve (joint_<type>.cpp); joint_solver.cpp dispatches by type.
#pragma once

#include <Eigen/Eigenvalues>

#include "solver/constraints.hpp"

namespace spindle {

struct Joint;

Mat3 skew(const Vec3& v);

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
// no more), soft while violated (`soft`: the pass's joint softness, or the limit's own
// spring). Returns the impulse to apply (the total stays >= 0).
Real limit_impulse(Real c, Real cdot, Real mass, Real& accumulated, const JointSolveParams& p);

// Point constraint (ball-socket, and the point part of the other joints): the anchors
// coincide, solved as one 3x3 block.
void solve_point(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                 const JointSolveParams& p);

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

}  // namespace spindle
