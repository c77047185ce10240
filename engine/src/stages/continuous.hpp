// What the solver's FinalizeBodies jobs ask of the Continuous stage (continuous.cpp):
// whether a body's step moved it far enough for its size that it must be swept.
#pragma once

#include <algorithm>
#include <cstdint>

#include "solver/solver_body.hpp"
#include "world.hpp"

namespace spindle {

// SolverBody::sweep: whether the Continuous stage sweeps the body.
inline constexpr std::uint8_t kSweepNever = 0;     // static, kinematic, a sensor
inline constexpr std::uint8_t kSweepWhenFast = 1;  // a dynamic body, in the steps moves_fast() says
inline constexpr std::uint8_t kSweepAlways = 2;    // flagged BodyDesc::fast

// Whether the step just solved (velocities v, w and the motion dp, dq of `body`, whose
// orientation was q before it) may have carried some point of the body's surface farther
// than half its thinnest half-size: Box3D's check in b3FinalizeBodiesTask, a spin about a
// long body's own axis counting only its girth, and a turn counting only the core's reach
// (Box3D counts a ball's spin too, which moves none of its surface). A squared bound first
// lets a body at rest out cheaply (|modified_cross(a, b)| <= sqrt(2) |a| |b|,
// (x + y)^2 <= 2 (x^2 + y^2)).
inline bool moves_fast(const SolverBody& body, const SweepExtent& extent, const Quat& q, Real dt) {
    const Real limit = Real(0.5) * extent.thinnest;
    const Real limit2 = limit * limit;
    const Real reach2 = extent.core_reach.squaredNorm();
    const Real speed2 = 2 * (body.v.squaredNorm() + 2 * body.w.squaredNorm() * reach2) * dt * dt;
    const Real moved2 = 2 * (body.dp.squaredNorm() + 8 * body.dq.vec().squaredNorm() * reach2);
    if (speed2 <= limit2 && moved2 <= limit2) return false;
    const Quat back = q.conjugate();
    const Vec3 local_w = (back * body.w).cwiseAbs();
    const Vec3 local_turn = (back * body.dq.vec()).cwiseAbs();
    const Real speed = body.v.norm() + modified_cross(local_w, extent.core_reach).norm();
    // sin(angle / 2) times the axis: twice it is the angle, for small angles.
    const Real moved = body.dp.norm() + 2 * modified_cross(local_turn, extent.core_reach).norm();
    return std::max(moved, speed * dt) > limit;
}

}  // namespace spindle
