// SolverBody: what the solver reads and writes per awake body in a step, packed
// together because every constraint touches two of them at random (AoS beats SoA
// here). Deltas (dp, dq) are kept instead of poses so that separations are computed
// from small numbers even far from the origin.
#pragma once

#include <cstddef>

#include <spindle/engine/math.hpp>

#include "solver/motion_locks.hpp"

namespace spindle {

// 192 bytes, aligned to a cache line: what the passes over the constraints read and
// write (v, w, dp, dq, the dynamic flag) fills its first two lines, and three lines a
// body is not a power-of-two stride, whose bodies would crowd a quarter of the cache
// sets (a 256-byte body did). What the passes never read lives in arrays of its own
// (PushVelocity, SolverScratch::gravity_scales).
struct alignas(64) SolverBody {
    Vec3 v = Vec3::Zero();
    Vec3 w = Vec3::Zero();
    Vec3 dp = Vec3::Zero();      // position change since the step began
    Quat dq = Quat::Identity();  // rotation change since the step began
    Real inv_mass = 0;           // along the free axes: zero along a locked one (locks)
    bool dynamic = false;        // only dynamic bodies are written by constraints
    std::uint8_t locks = 0;      // motion lock bits (motion_locks.hpp)
    bool damped = false;         // damps: integrate_velocities reads the description only then
    // Turns keeping its angular momentum (integrate_velocities): dynamic, BodyDesc::gyroscopic
    // or elongated (Bodies::elongated), and no rotation lock. Kept here so the integrator
    // reads no body description.
    bool gyroscopic = false;
    std::uint8_t sweep = 0;  // kSweepNever, kSweepWhenFast or kSweepAlways (stages/continuous.hpp)
    // Its inertia is the same about every axis (a ball, a cube), or it does not turn (not
    // dynamic): turning it changes nothing (turned()).
    bool isotropic = true;
    Mat3 inv_inertia = Mat3::Zero();  // world, at the step's start; zero about locked axes
};
static_assert(sizeof(SolverBody) == 192 && offsetof(SolverBody, gyroscopic) < 128,
              "a solver body is three cache lines, with what the passes touch in the first two");

// The body with its inverse inertia as it is now: the step's start's turned by dq. A joint's
// anchors and axes turn with its bodies through the step, and an impulse at a turned anchor
// applied through the start's inertia would turn a body about an axis it does not: a disc
// spinning on a pivot gained spin, and energy, in every step that it precessed. A body with
// motion locks keeps the start's (its zero rows are the locked world axes); an isotropic one
// has nothing to turn: the body itself is returned, else `copy`, turned (as contact_solver.cpp's
// scaled() does for support scales).
inline const SolverBody& turned(const SolverBody& body, SolverBody& copy) {
    if (body.isotropic || body.locks != 0) return body;
    copy = body;
    const Mat3 r = body.dq.toRotationMatrix();
    copy.inv_inertia = r * body.inv_inertia * r.transpose();
    return copy;
}

// Push-out velocities of a solver body in the current substep (split impulse), at the
// same index: they move the body out of overlaps in integrate_positions and are then
// dropped, so pushing apart never becomes real speed. Capped per body in
// integrate_positions: pushing never makes a body move faster than the push-out speed
// or its own speed, whichever is larger. Only deep overlap writes them (rare), so the
// passes' body lines stay without them.
struct PushVelocity {
    Vec3 v = Vec3::Zero();
    Vec3 w = Vec3::Zero();
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
inline Velocities load_push(const PushVelocity& A, const PushVelocity& B) { return {A.v, A.w, B.v, B.w}; }

// Stores the velocities of a constraint's bodies. Only dynamic bodies are written: static
// and kinematic ones are shared by constraints of every colour.
inline void store(SolverBody& A, SolverBody& B, const Velocities& s) {
    if (A.dynamic) {
        A.v = s.va;
        A.w = s.wa;
    }
    if (B.dynamic) {
        B.v = s.vb;
        B.w = s.wb;
    }
}
// The same for their push-out velocities (A and B: the bodies at the same index).
inline void store_push(const SolverBody& A, const SolverBody& B, PushVelocity& push_a, PushVelocity& push_b,
                       const Velocities& s) {
    if (A.dynamic) push_a = {s.va, s.wa};
    if (B.dynamic) push_b = {s.vb, s.wb};
}

// Adds a constraint's velocity changes to rows apart from its bodies' velocities, at the
// same indices (SolverScratch::warm_velocities): only the dynamic bodies', as store writes.
inline void add_to(const SolverBody& A, const SolverBody& B, PushVelocity& a, PushVelocity& b, const Velocities& s) {
    if (A.dynamic) {
        a.v += s.va;
        a.w += s.wa;
    }
    if (B.dynamic) {
        b.v += s.vb;
        b.w += s.wb;
    }
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
