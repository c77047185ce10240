// SolverBody: what the solver reads and writes per awake body in a step, packed
// together because every constraint touches two of them at random (AoS beats SoA
// here). Deltas (dp, dq) are kept instead of poses so that separations are computed
// from small numbers even far from the origin.
#pragma once

#include <spindle/engine/math.hpp>

#include "solver/motion_locks.hpp"

namespace spindle {

struct SolverBody {
    Vec3 v = Vec3::Zero();
    Vec3 w = Vec3::Zero();
    Vec3 dp = Vec3::Zero();      // position change since the step began
    Quat dq = Quat::Identity();  // rotation change since the step began
    // Push-out velocities of the current substep (split impulse): they move the body out
    // of overlaps in integrate_positions and are then dropped, so pushing apart never
    // becomes real speed. Capped per body in integrate_positions: pushing never makes a
    // body move faster than the push-out speed or its own speed, whichever is larger.
    Vec3 push_v = Vec3::Zero();
    Vec3 push_w = Vec3::Zero();
    Mat3 inv_inertia = Mat3::Zero();  // world, fixed for the step; zero about locked axes
    Real inv_mass = 0;                // along the free axes: zero along a locked one (locks)
    // BodyDesc::gravity_scale of a dynamic body (else 0) and whether it damps: the passes
    // that read them once per body and substep or per contact stay off the cold
    // descriptions, each a cache miss.
    Real gravity_scale = 0;
    bool damped = false;
    bool dynamic = false;    // only dynamic bodies are written by constraints
    std::uint8_t locks = 0;  // motion lock bits (motion_locks.hpp), in the padding
    // Turns keeping its angular momentum (integrator.cpp): dynamic, BodyDesc::gyroscopic
    // and no rotation lock. Kept here so integrate_positions reads no body description.
    bool gyroscopic = false;
};

// The velocity change of an impulse (inverse mass times it): none along a locked axis.
inline Vec3 linear_response(const SolverBody& body, const Vec3& impulse) {
    return project_linear(body.inv_mass * impulse, body.locks);
}

// The velocities of a constraint's two bodies while it is solved: loaded once, changed
// by each row, stored once.
struct Velocities {
    Vec3 va, wa, vb, wb;
};

inline Velocities load(const SolverBody& A, const SolverBody& B) { return {A.v, A.w, B.v, B.w}; }
inline Velocities load_push(const SolverBody& A, const SolverBody& B) {
    return {A.push_v, A.push_w, B.push_v, B.push_w};
}

// Stores into the members v and w (the real or the push-out velocities). Only dynamic
// bodies are written: static and kinematic ones are shared by constraints of every colour.
template <Vec3 SolverBody::*V, Vec3 SolverBody::*W>
inline void store_into(SolverBody& A, SolverBody& B, const Velocities& s) {
    if (A.dynamic) {
        A.*V = s.va;
        A.*W = s.wa;
    }
    if (B.dynamic) {
        B.*V = s.vb;
        B.*W = s.wb;
    }
}
inline void store(SolverBody& A, SolverBody& B, const Velocities& s) {
    store_into<&SolverBody::v, &SolverBody::w>(A, B, s);
}
inline void store_push(SolverBody& A, SolverBody& B, const Velocities& s) {
    store_into<&SolverBody::push_v, &SolverBody::push_w>(A, B, s);
}

// An impulse at the anchors ra, rb (from each centre of mass): -impulse on A, +impulse on B.
inline void apply(const SolverBody& A, const SolverBody& B, Velocities& s, const Vec3& ra, const Vec3& rb,
                  const Vec3& impulse) {
    s.va -= linear_response(A, impulse);
    s.wa -= A.inv_inertia * ra.cross(impulse);
    s.vb += linear_response(B, impulse);
    s.wb += B.inv_inertia * rb.cross(impulse);
}

// An angular impulse: -impulse on A, +impulse on B.
inline void apply_angular(const SolverBody& A, const SolverBody& B, Velocities& s, const Vec3& impulse) {
    s.wa -= A.inv_inertia * impulse;
    s.wb += B.inv_inertia * impulse;
}

// 1 / (J M^-1 J^T) of one linear row along dir at the anchors ra, rb (0 if nothing can move).
inline Real effective_mass(const SolverBody& A, const SolverBody& B, const Vec3& ra, const Vec3& rb, const Vec3& dir) {
    const Vec3 rna = ra.cross(dir);
    const Vec3 rnb = rb.cross(dir);
    const Real k = inverse_mass_along(A.inv_mass, A.locks, dir) + inverse_mass_along(B.inv_mass, B.locks, dir) +
                   rna.dot(A.inv_inertia * rna) + rnb.dot(B.inv_inertia * rnb);
    return k > 0 ? 1 / k : 0;
}

// Velocity of B's anchor relative to A's.
inline Vec3 relative_velocity(const Velocities& s, const Vec3& ra, const Vec3& rb) {
    return s.vb + s.wb.cross(rb) - s.va - s.wa.cross(ra);
}

}  // namespace spindle
