// Integration, once per substep over the awake bodies: velocities (gravity, user
// forces, damping, gyroscopic torque -- each only for bodies that use it) and then
// positions as deltas from the start of the step (semi-implicit Euler).
#include <algorithm>
#include <cmath>

#include "solver/solver_body.hpp"
#include "solver/speed_limit.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

Mat3 skew(const Vec3& v) {
    Mat3 m;
    m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    return m;
}

// Implicit gyroscopic torque (one Newton step on I(w2 - w1) + h w2 x I w2 = 0, in
// the body frame): a fast-spinning asymmetric body neither gains energy nor explodes.
Vec3 solve_gyroscopic(const Quat& q, const Mat3& inertia_local, const Vec3& w_world, Real h) {
    const Vec3 wb = q.conjugate() * w_world;
    const Vec3 iw = inertia_local * wb;
    const Vec3 f = h * wb.cross(iw);
    const Mat3 jacobian = inertia_local + h * (skew(wb) * inertia_local - skew(iw));
    const Vec3 corrected = wb - jacobian.inverse() * f;  // closed-form 3x3: far cheaper than a pivoting LU
    return q * corrected;
}

}  // namespace

void integrate_velocities(World& world, SolverBody* bodies, Real h, std::uint32_t lo, std::uint32_t hi,
                          EffectCounts& c) {
    const Bodies& b = world.bodies;
    const Vec3 gravity = world.settings.gravity;
    const Real max_linear = world.settings.solver.max_linear_speed;
    const Real max_angular = world.settings.solver.max_angular_speed;
    for (std::uint32_t k = lo; k < hi; ++k) {
        SolverBody& sb = bodies[k];
        if (!sb.dynamic) {
            // A kinematic body moves by its velocity alone: limited all the same.
            sb.v = limit_speed(sb.v, max_linear);
            sb.w = limit_speed(sb.w, max_angular);
            continue;
        }
        const std::uint32_t i = world.awake[k];
        const BodyDesc& d = b.desc[i];
        if (d.gravity_scale != 0) {
            sb.v += h * d.gravity_scale * gravity;
            ++c.gravity;
        }
        sb.v += h * sb.inv_mass * b.force[i];  // at worst infinite components, which the limit turns back
        sb.w = add_angular(sb.w, h, sb.inv_inertia, b.torque[i], max_angular);
        // Before the gyroscopic step, which needs a finite spin.
        sb.v = limit_speed(sb.v, max_linear);
        sb.w = limit_speed(sb.w, max_angular);
        if (d.gyroscopic) {
            const Quat q = (sb.dq * b.q[i]).normalized();
            sb.w = solve_gyroscopic(q, b.inertia_local[i], sb.w, h);
            ++c.gyro;
        }
        if (d.linear_damping > 0 || d.angular_damping > 0) {
            // Implicit (Pade) damping: stable for any h.
            sb.v *= 1 / (1 + h * d.linear_damping);
            sb.w *= 1 / (1 + h * d.angular_damping);
            ++c.damping;
        }
    }
}

void integrate_positions(World& world, SolverBody* bodies, Real h, std::uint32_t lo, std::uint32_t hi) {
    const Real push_out = world.settings.solver.push_out_speed;
    for (std::uint32_t k = lo; k < hi; ++k) {
        SolverBody& sb = bodies[k];
        // The push-out velocity is capped per body, not only per contact: a chain of
        // overlaps would otherwise add up each contact's push-out speed.
        const Vec3 moving = sb.v + sb.push_v;
        const Real limit_sq = std::max(sb.v.squaredNorm(), push_out * push_out);
        const Real moving_sq = moving.squaredNorm();
        if (moving_sq > limit_sq) sb.push_v = std::sqrt(limit_sq / moving_sq) * moving - sb.v;
        sb.dp += h * (sb.v + sb.push_v);
        sb.dq = integrate_rotation(sb.dq, sb.w + sb.push_w, h);
        sb.push_v = Vec3::Zero();
        sb.push_w = Vec3::Zero();
    }
}

}  // namespace spindle
