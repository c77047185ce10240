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

// The spin of angular momentum L at orientation q: L into the body's frame, through the
// inverse inertia and back (three matrix-vector products, not the world inverse inertia's
// two matrix products).
Vec3 spin_at(const Quat& q, const Mat3& inv_inertia_local, const Vec3& momentum) {
    const Mat3 r = q.toRotationMatrix();
    return r * (inv_inertia_local * (r.transpose() * momentum));
}

// Gyroscopic motion that keeps angular momentum. Without torque, a body's world angular
// momentum L = I(q) w is constant while its spin w changes as it turns (the torque-free
// precession and flips of an asymmetric body). The spin is set before the constraints
// are solved, so that joints and contacts see and correct the spin the body turns by:
// set after them (as this once was), it moved jointed thin bodies' anchors apart faster
// than the relax pass and the position bias brought them back (a 20-link chain of
// gyroscopic links kept a 0.15 m joint error, JointAccuracy tests). The spin the body
// brings is the one it turned by over the last substep, so L is taken at that turn's
// middle orientation, half a substep back; the new spin is L through the middle
// orientation of this substep's turn (the implicit midpoint: two fixed-point passes).
// A free body keeps L within half a percent over 20 s and its energy does not grow; the
// implicit Newton step this replaced lost 22 % of L in 20 s.
void keep_momentum(SolverBody& sb, const Quat& start, const Mat3& inertia_local, const Mat3& inv_inertia_local,
                   Real h) {
    const Quat q0 = (sb.dq * start).normalized();
    const Mat3 r = integrate_rotation(q0, sb.w, -h / 2).toRotationMatrix();
    const Vec3 momentum = r * (inertia_local * (r.transpose() * sb.w));
    Vec3 mid_spin = sb.w;
    for (int pass = 0; pass < 2; ++pass) {
        mid_spin = spin_at(integrate_rotation(q0, mid_spin, h / 2), inv_inertia_local, momentum);
    }
    sb.w = mid_spin;
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
            keep_momentum(sb, b.q[i], b.inertia_local[i], b.inv_inertia_local[i], h);
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
