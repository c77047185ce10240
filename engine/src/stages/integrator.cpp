// Integration, once per substep over the awake bodies: velocities (gravity, user
// forces, damping -- each only for bodies that use it) and then positions as deltas
// from the start of the step (semi-implicit Euler). Gyroscopic bodies' spin is set to
// keep their angular momentum with the velocities, before the solve.
#include <algorithm>
#include <cmath>
#include <ranges>
#include <span>

#include "solver/solver_body.hpp"
#include "solver/speed_limit.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

// `v` turned back about `w` by half the turn integrate_rotation makes with spin `w` over
// `h`. That turn is the unit quaternion t = (1, h w / 2) / n, n = sqrt(1 + h^2 |w|^2 / 4),
// and its half is normalize(1 + t) = (n + 1, h w / 2) / sqrt(2 n (n + 1)): no trigonometry,
// and exactly the middle of the turn the body makes (two half turns are the turn).
Vec3 half_turn_back(const Vec3& w, const Vec3& v, Real h) {
    const Real n = std::sqrt(1 + Real(0.25) * h * h * w.squaredNorm());
    const Vec3 c = w.cross(v);
    return v - (h / (2 * n)) * c + (h * h / (4 * n * (n + 1))) * w.cross(c);
}

// Gyroscopic motion that keeps angular momentum. Without torque, a body's world angular
// momentum L = I(q) w is constant while its spin w changes as it turns (the torque-free
// precession and flips of an asymmetric body). The spin is set before the constraints
// are solved, so that joints and contacts see and correct the spin the body turns by:
// set after them (as this once was), it moved jointed thin bodies' anchors apart faster
// than the relax pass and the position bias brought them back (a 20-link chain of
// gyroscopic links kept a 0.15 m joint error, JointAccuracy tests).
// The spin the body brings is the one it turned by over the last substep, so L is taken
// at that turn's middle; the new spin w' is the one whose own turn's middle has the same
// L (the implicit midpoint). Both middles are the exact halves of the turns the body
// makes (half_turn_back), so L is kept exactly once w' is found: taken at two middles
// that were not (integrate_rotation by -h/2 and +h/2), L drifted 5 % in 2 s at 0.2 rad
// a substep. All in the body's frame at the substep's start: there L is l, the last
// middle's I w turned back by half the last turn, and w' solves
// I w' = half_turn_back(w', l): two Newton passes from w with the Jacobian I - h/2 [l]x
// (the half turn to first order), which converge where fixed-point passes crawl (a thin
// body's small inertia amplifies each pass's error). Free bodies keep L within 0.03 %
// (OutsideSpin tests); an implicit Euler step (Box3D's), which this once was, lost 22 %
// of L in 20 s.
void keep_momentum(SolverBody& sb, const Quat& start, const Mat3& inertia_local, Real h) {
    const Mat3 r = (sb.dq * start).toRotationMatrix();  // both unit: their product is to rounding
    const Vec3 spin = r.transpose() * sb.w;
    const Vec3 l = half_turn_back(spin, inertia_local * spin, h);
    const Vec3 hl = (h / 2) * l;
    Mat3 jacobian = inertia_local;
    jacobian(0, 1) += hl.z();
    jacobian(0, 2) -= hl.y();
    jacobian(1, 0) -= hl.z();
    jacobian(1, 2) += hl.x();
    jacobian(2, 0) += hl.y();
    jacobian(2, 1) -= hl.x();
    const Mat3 inverse = jacobian.inverse();  // I is positive definite, [l]x skew: never singular
    Vec3 w = spin;
    for (int pass = 0; pass < 2; ++pass) w -= inverse * (inertia_local * w - half_turn_back(w, l, h));
    sb.w = r * w;
}

// Over awake bodies `ks`: a range of them, or a list (a folded step's, solver.cpp); with
// `warm`, each body's row of it added last and cleared (SolverScratch::warm_velocities).
template <typename Indices>
void integrate_velocities_of(World& world, SolverBody* bodies, const Real* gravity_scales, Real h, const Indices& ks,
                             EffectCounts& c, PushVelocity* warm = nullptr) {
    const Bodies& b = world.bodies;
    const Vec3 gravity = world.settings.gravity;
    const Real max_linear = world.settings.solver.max_linear_speed;
    const Real max_angular = world.settings.solver.max_angular_speed;
    for (const std::uint32_t k : ks) {
        SolverBody& sb = bodies[k];
        if (!sb.dynamic) continue;  // a kinematic body's velocities were limited once, by prepare_bodies
        const std::uint32_t i = world.awake[k];
        if (gravity_scales[k] != 0) {
            sb.v += project_linear(h * gravity_scales[k] * gravity, sb.locks);
            ++c.gravity;
        }
        // At worst infinite components, which the limit turns back.
        sb.v += project_linear(h * sb.inv_mass * b.force[i], sb.locks);
        sb.w = add_angular(sb.w, h, sb.inv_inertia, b.torque[i], max_angular);  // locked axes: zero inertia rows
        // The momentum-keeping spin knows nothing of the locks: a body with a rotation lock
        // keeps its (projected) spin, which about a single free axis is exact anyway
        // (SolverBody::gyroscopic is false for it).
        if (sb.gyroscopic) {
            keep_momentum(sb, b.q[i], b.inertia_local[i], h);
            ++c.gyro;
        }
        sb.v = limit_speed(sb.v, max_linear);
        sb.w = limit_speed(sb.w, max_angular);
        if (sb.damped) {
            // Implicit (Pade) damping: stable for any h.
            const BodyTraits& d = b.traits[i];
            sb.v *= 1 / (1 + h * d.linear_damping);
            sb.w *= 1 / (1 + h * d.angular_damping);
            ++c.damping;
        }
        if (warm != nullptr) {
            sb.v += warm[k].v;
            sb.w += warm[k].w;
            warm[k] = PushVelocity{};
        }
    }
}

template <typename Indices>
void integrate_positions_of(World& world, SolverBody* bodies, PushVelocity* push, Real h, const Indices& ks) {
    const Real push_out = world.settings.solver.push_out_speed;
    for (const std::uint32_t k : ks) {
        SolverBody& sb = bodies[k];
        PushVelocity& pv = push[k];
        // The push-out velocity is capped per body, not only per contact: a chain of
        // overlaps would otherwise add up each contact's push-out speed.
        const Vec3 moving = sb.v + pv.v;
        const Real limit_sq = std::max(sb.v.squaredNorm(), push_out * push_out);
        const Real moving_sq = moving.squaredNorm();
        if (moving_sq > limit_sq) pv.v = std::sqrt(limit_sq / moving_sq) * moving - sb.v;
        sb.dp += h * (sb.v + pv.v);
        sb.dq = integrate_rotation(sb.dq, sb.w + pv.w, h);
        pv = PushVelocity{};
    }
}

}  // namespace

void integrate_velocities(World& world, SolverBody* bodies, const Real* gravity_scales, Real h, std::uint32_t lo,
                          std::uint32_t hi, EffectCounts& counts) {
    integrate_velocities_of(world, bodies, gravity_scales, h, std::views::iota(lo, hi), counts);
}
void integrate_velocities(World& world, SolverBody* bodies, const Real* gravity_scales, Real h,
                          std::span<const std::uint32_t> ks, EffectCounts& counts, PushVelocity* warm) {
    integrate_velocities_of(world, bodies, gravity_scales, h, ks, counts, warm);
}
void integrate_positions(World& world, SolverBody* bodies, PushVelocity* push, Real h, std::uint32_t lo,
                         std::uint32_t hi) {
    integrate_positions_of(world, bodies, push, h, std::views::iota(lo, hi));
}
void integrate_positions(World& world, SolverBody* bodies, PushVelocity* push, Real h,
                         std::span<const std::uint32_t> ks) {
    integrate_positions_of(world, bodies, push, h, ks);
}

}  // namespace spindle
