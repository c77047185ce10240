// Changes to a body after its creation, made live at ApplyWrites (buffering.cpp) from
// the buffered setters (api/body_setters.cpp): material, motion type, shape, and the
// kinematic moves that the next step carries out.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "world.hpp"

namespace spindle {

// A dynamic body whose largest principal inertia is more than this many times its
// smallest is elongated: it always turns keeping its angular momentum (integrator.cpp),
// as if it set BodyDesc::gyroscopic. Without that, a pole or tree pivoting on its end
// turns any spin out of its tipping plane into a spin about its long axis that grows
// without bound, and it falls late (docs/benchmarks.md, h45, session 19). Box3D applies
// its gyroscopic step to every body; a body this far from a sphere is where it matters.
inline constexpr Real kElongatedInertiaRatio = 10;
// The solver works in single precision (solver/wide.hpp): a dynamic body's mass and principal
// inertias must lie within [kMinMass, kMaxMass] (kg, kg m^2), where float holds them, their
// inverses and their products with lever arms and impulses with room to spare (a 1 mm grain's
// inertia is ~1e-13 kg m^2, a 1 km rock's ~1e18). Beyond it an impulse turns into inf or NaN.
inline constexpr Real kMinMass = 1e-24;
inline constexpr Real kMaxMass = 1e24;

// A body's mass, inertia and centre of mass as create_body computes them: from the
// shape and the description's density or mass for a dynamic body, none otherwise.
struct BodyMass {
    Real inv_mass = 0;
    Mat3 inv_inertia = Mat3::Zero();
    Mat3 inertia = Mat3::Zero();
    Vec3 local_com = Vec3::Zero();  // in the shape's frame
    bool elongated = false;         // kElongatedInertiaRatio
};
// Throws spindle::Error ("<who>: the shape has no volume ...", "<who>: mass ... must be within
// ...") for a shape or mass that gives no finite inverse, or one out of the solver's range.
BodyMass body_mass(const BodyTraits& traits, MotionType type, const Shape& shape, const char* who);

// These bodies' friction, restitution or rolling resistance changed (descriptions already set; slots
// ascending): every contact of theirs takes the combined values again. One pass over the
// contacts for all of them.
void recombine_materials(World& world, std::span<const std::uint32_t> slots);

// Each returns false, changing nothing, when the new mass would not be finite.
// The body and what touches it are woken, its contacts removed (found again at the next
// step) and its proxy made again; its origin stays where it is.
bool change_motion_type(World& world, std::uint32_t slot, MotionType type);
// Mass, inertia and centre of mass rebuilt from the new shape unless keep_mass.
bool change_shape(World& world, std::uint32_t slot, const Shape& shape, bool keep_mass);

// The changes after creation in one body's pending writes (motion type, then shape,
// material, gravity scale, damping, user data), before its pose and velocities are
// applied. Bodies whose material (friction, restitution, rolling resistance) changed are added to `rematerialed`, for
// recombine_materials once all are applied. Returns the writes rejected (a motion type or
// shape whose mass would not be finite; a kinematic move of a body not kinematic).
int apply_body_changes(World& world, const PendingWrites& write, std::vector<std::uint32_t>& rematerialed);

// A kinematic body's move to a target pose (Space::move_kinematic), replacing any move
// of the same body that no step has taken yet.
void add_kinematic_move(World& world, std::uint32_t slot, const Vec3& origin, const Quat& orientation);
// At the start of a step: each moving body gets the velocities that reach its target in dt.
void start_kinematic_moves(World& world, Real dt);
// After the solver: each is put exactly on its target and stops (unless moved again).
void finish_kinematic_moves(World& world);

}  // namespace spindle
