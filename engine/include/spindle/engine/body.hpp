// Bodies as the user sees them: a small generational handle, a description to create
// one from, and the motion state that the buffered accessors read and write.
#pragma once

#include <cstdint>
#include <string>

#include <spindle/engine/math.hpp>
#include <spindle/engine/shape.hpp>

namespace spindle {

// Collision layers per space: BodyDesc::layer is below this.
inline constexpr std::uint32_t kLayerCount = 32;

// A body's name in its space. index is its slot; generation changes every time the
// slot is reused, so a handle to a destroyed body is detected, never aliased.
struct BodyHandle {
    std::uint32_t index = 0;
    std::uint32_t generation = 0;  // 0 never names a live body
    bool valid_bits() const noexcept { return generation != 0; }
    friend bool operator==(BodyHandle, BodyHandle) = default;
};

std::string to_string(BodyHandle handle);

enum class MotionType : std::uint8_t {
    Static,     // never moves; infinite mass
    Kinematic,  // moves by its velocity; infinite mass; pushes dynamic bodies
    Dynamic,    // moved by forces and contacts
};

// Everything that describes a body's motion at one instant.
struct MotionState {
    Vec3 position = Vec3::Zero();  // the shape's origin, world
    Quat orientation = Quat::Identity();
    Vec3 linear_velocity = Vec3::Zero();   // of the centre of mass
    Vec3 angular_velocity = Vec3::Zero();  // world
    Vec3 center_of_mass = Vec3::Zero();    // world; equals position for centred shapes
};

// Motion locks (Box2D v3's fixed rotation, Jolt's allowed degrees of freedom), in world
// axes. A locked translation axis: the body's centre of mass never moves along it. A
// locked rotation axis: the body never turns about it. Locking translation z and
// rotation x and y keeps a body in the x-y plane (a 2D body in a 3D scene); locking all
// three rotations keeps its orientation. The locks are exact, not springs: the body
// has no mass to move along a locked axis (contacts and joints see it infinitely heavy
// there) and every velocity it is given, at creation, by a write, a force or an
// impulse, loses its locked components. A teleport (a written position or orientation)
// puts it anywhere; it stays locked from there. Rotation locked about one axis alone
// stops the spin about it, but turns about the other two still combine into a little
// of it (as in Jolt); lock two or three for a rotation that stays exact. Bodies without
// locks pay nothing for them.
struct MotionLocks {
    bool translation_x = false, translation_y = false, translation_z = false;
    bool rotation_x = false, rotation_y = false, rotation_z = false;

    // A 2D body in the x-y plane: translation z and rotation x and y locked.
    static constexpr MotionLocks plane_xy() {
        MotionLocks locks;
        locks.translation_z = locks.rotation_x = locks.rotation_y = true;
        return locks;
    }
    // No rotation at all (Box2D's fixed rotation).
    static constexpr MotionLocks all_rotation() {
        MotionLocks locks;
        locks.rotation_x = locks.rotation_y = locks.rotation_z = true;
        return locks;
    }
    bool any() const noexcept {
        return translation_x || translation_y || translation_z || rotation_x || rotation_y || rotation_z;
    }
    friend bool operator==(const MotionLocks&, const MotionLocks&) = default;
};

// A space keeps it as BodyTraits (engine/src/world.hpp) without the pose and velocities: a
// field added here is added there too.
struct BodyDesc {
    MotionType type = MotionType::Dynamic;
    Shape shape = Shape::sphere(0.5);
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();  // normalised at creation; must not be zero
    Vec3 linear_velocity = Vec3::Zero();
    Vec3 angular_velocity = Vec3::Zero();
    // A dynamic body's mass and principal inertias must come out within [1e-24, 1e24] (kg,
    // kg m^2): the solver works in single precision (create_body refuses a body beyond).
    Real density = 1000;  // kg/m^3; used when mass == 0
    Real mass = 0;        // kg; > 0 overrides density (inertia scaled to match)
    Real friction = 0.6;
    Real restitution = 0;
    // Rolling resistance (Box3D's): a ball, a barrel or a log rolling or rocking on
    // something slows and stops instead of rolling for ever. Dimensionless, >= 0 (0: none,
    // and no cost). A touching part pair brakes the bodies' relative spin with a torque of
    // at most this x the pair's rolling radius x its normal force: the radius of a
    // sphere or capsule, a quarter of a box's or hull's inner radius (the larger of the two
    // parts'). Two bodies mix as the larger of their coefficients. Box3D's benchmark trees
    // carry 0.05.
    Real rolling_resistance = 0;
    Real gravity_scale = 1;
    Real linear_damping = 0;   // 1/s; 0 costs nothing
    Real angular_damping = 0;  // 1/s; 0 costs nothing
    // Gyroscopic motion: a spinning asymmetric body precesses and flips, keeping its
    // angular momentum (not for a body with a rotation lock: it turns as any other).
    // An elongated dynamic body (its largest principal inertia over 10 times its
    // smallest: a pole, a tree, a thin limb) always moves so, whatever this says: without
    // it, such a body tipping over on its end turns into a fast, growing spin about its
    // long axis and falls late. For others it costs some time a body each substep.
    bool gyroscopic = false;
    MotionLocks locks;  // nothing locked by default; for dynamic and kinematic bodies
    bool allow_interpolation = true;
    bool allow_sleep = true;
    bool fast = false;  // also swept against static geometry (continuous collision)
    // Collision filter. layer: 0..kLayerCount-1; whether two layers collide is the
    // space's layer table (Space::set_layers_collide; all pairs collide by default).
    // group: 0 is none; bodies sharing a non-zero group never collide (a ragdoll's limbs).
    std::uint32_t layer = 0;
    std::uint32_t group = 0;
    // Contact events (Space::read_contact_events) for every pair this body is in: begin
    // and end of touch, hits. Pairs where neither body asks cost nothing for events.
    bool contact_events = false;
    // A sensor detects overlaps (begin and end events with the other body, whatever either
    // asked) and exerts no force: its contacts never reach the solver nor join islands. It
    // detects bodies it could touch (one of the two dynamic), never another sensor.
    bool sensor = false;
    std::uint64_t user_data = 0;
};

}  // namespace spindle
