// SolverBody: what the solver reads and writes per awake body in a step, packed
// together because every constraint touches two of them at random (AoS beats SoA
// here). Deltas (dp, dq) are kept instead of poses so that separations are computed
// from small numbers even far from the origin.
#pragma once

#include <spindle/engine/math.hpp>

namespace spindle {

struct SolverBody {
    Vec3 v = Vec3::Zero();
    Vec3 w = Vec3::Zero();
    Vec3 dp = Vec3::Zero();        // position change since the step began
    Quat dq = Quat::Identity();    // rotation change since the step began
    Mat3 inv_inertia = Mat3::Zero();  // world, fixed for the step
    Real inv_mass = 0;
    bool dynamic = false;  // only dynamic bodies are written by constraints
};

}  // namespace spindle
