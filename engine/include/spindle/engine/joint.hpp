// Joints as the user sees them: a generational handle, a description to create one
// from (ball-socket, hinge, fixed, distance, prismatic, swing-twist, motor), and the
// error a joint currently has.
#pragma once

#include <cstdint>
#include <string>

#include <spindle/engine/body.hpp>
#include <spindle/engine/math.hpp>

namespace spindle {

// A joint's name in its space; like BodyHandle, a reused slot gets a new generation,
// so a handle to a destroyed joint is detected, never aliased.
struct JointHandle {
    std::uint32_t index = 0;
    std::uint32_t generation = 0;  // 0 never names a live joint
    bool valid_bits() const noexcept { return generation != 0; }
    friend bool operator==(JointHandle, JointHandle) = default;
};

std::string to_string(JointHandle handle);

enum class JointType : std::uint8_t {
    BallSocket,  // the anchors coincide; rotation is free
    Hinge,       // the anchors coincide and the axes stay aligned; optional limit and motor
    Fixed,       // the anchors coincide and the relative rotation stays as at creation (weld)
    Distance,    // the anchors keep a distance: rigid, or a spring with optional min/max
    Prismatic,   // a slider: B translates along one axis of A, no relative rotation
    SwingTwist,  // the anchors coincide; a cone limit on the swing, a range on the twist
    Motor,       // drives B toward a target pose relative to A (and the mouse joint)
};
const char* to_string(JointType type) noexcept;

// How anchors (and hinge axes) are given.
enum class JointFrame : std::uint8_t {
    World,  // world points/axes, turned into each body's frame from its pose at creation
    Local,  // points/axes in each body's own frame (the shape's origin, like BodyDesc::position)
};

// Where a joint attaches to each body. A ball-socket, hinge or fixed joint given one
// world point uses it for both bodies.
// Anchors are points: within 1e9 m of the origin (World) or of the body's origin (Local),
// as positions are; create_joint refuses others, naming the anchor.
struct JointAnchors {
    JointFrame frame = JointFrame::World;
    Vec3 a = Vec3::Zero();  // on body_a
    Vec3 b = Vec3::Zero();  // on body_b

    static JointAnchors world(const Vec3& point) { return {JointFrame::World, point, point}; }
    static JointAnchors world(const Vec3& on_a, const Vec3& on_b) { return {JointFrame::World, on_a, on_b}; }
    static JointAnchors local(const Vec3& on_a, const Vec3& on_b) { return {JointFrame::Local, on_a, on_b}; }
};

// Hinge: rotation about one axis. The angle is B's rotation relative to A about the
// axis, measured from the pose at creation (0 there), in radians.
struct HingeParams {
    Vec3 axis_a = Vec3::UnitZ();  // in anchors.frame; normalised at creation
    Vec3 axis_b = Vec3::UnitZ();  // World frame: must be the same axis as axis_a
    bool enable_limit = false;
    Real lower_angle = 0;  // rad, in [-pi, pi], <= upper_angle
    Real upper_angle = 0;  // rad, in [-pi, pi]
    bool enable_motor = false;
    Real motor_speed = 0;       // rad/s of B relative to A about the axis
    Real max_motor_torque = 0;  // N m; the motor gives up beyond it
    // A soft limit: past it a spring of this frequency (for the mass the limit turns, as
    // the distance spring) and damping ratio pushes back, so the body overshoots and
    // settles on the limit, sagging under a load. 0: as stiff as the solver's joints.
    Real limit_spring_hertz = 0;
    Real limit_damping_ratio = 0;  // 1 = critical
};

// Distance: rigid at rest_length, or (enable_spring) a spring toward rest_length that
// is free within [min_length, max_length] when enable_limit is set.
struct DistanceParams {
    Real rest_length = -1;  // m; negative: the anchors' distance at creation
    bool enable_spring = false;
    Real spring_hertz = 0;          // 0 with enable_spring: no spring force (a rope within the limits)
    Real spring_damping_ratio = 0;  // 1 = critical
    bool enable_limit = false;
    Real min_length = 0;      // m
    Real max_length = kHuge;  // m; >= min_length
};

// Swing-twist (ragdoll shoulders, hips, neck): the anchors coincide; B's twist axis may swing
// away from A's twist axis within a cone, and B may twist about its twist axis within
// [twist_min, twist_max], measured from the relative pose at creation (0 there); friction
// torque resists both.
struct SwingTwistParams {
    Vec3 twist_axis_a = Vec3::UnitY();  // in anchors.frame; normalised at creation
    Vec3 twist_axis_b = Vec3::UnitY();  // World frame: must be the same axis as twist_axis_a
    Real cone_half_angle = kPi / 4;     // rad, in [0, pi]: the swing limit
    Real twist_min = -kPi / 4;          // rad, in [-pi, pi], <= twist_max
    Real twist_max = kPi / 4;
    Real max_friction_torque = 0;  // N m
};

// Prismatic (a slider): B keeps its orientation relative to A and its anchor moves only
// along an axis fixed in A. The translation is B's anchor from A's along the axis,
// measured from the pose at creation (0 there), in metres.
struct PrismaticParams {
    Vec3 axis_a = Vec3::UnitX();  // in anchors.frame (on A); normalised at creation
    bool enable_limit = false;
    Real lower_translation = 0;     // m, <= upper_translation
    Real upper_translation = 0;     // m
    bool enable_spring = false;     // toward target_translation
    Real spring_hertz = 0;          // 0 with enable_spring: no spring force
    Real spring_damping_ratio = 0;  // 1 = critical
    Real target_translation = 0;    // m
    bool enable_motor = false;
    Real motor_speed = 0;      // m/s of B relative to A along the axis
    Real max_motor_force = 0;  // N; the motor gives up beyond it
};

// Motor: drives B toward a target pose relative to A. B's anchor is pulled toward A's
// anchor plus linear_offset (in A's frame), and B's orientation toward A's turned by
// angular_offset on top of the relative orientation at creation; the pull is capped at
// max_force and max_torque. Stiffness: a spring of linear_hertz / angular_hertz (for the
// mass it moves) with a damping ratio, or, at 0 hertz, as stiff as the solver's joints.
// The target can be moved while the space runs (Space::set_motor_target, buffered).
//
// A mouse (drag) joint is a motor joint whose body_a stands for the world: a static body
// (the ground, or one made for the purpose), JointDesc::mouse_at. Its target is a world
// point (Space::set_mouse_target) and its rotation is free (max_torque 0).
struct MotorParams {
    Vec3 linear_offset = Vec3::Zero();       // m, in A's frame, from A's anchor to B's anchor's target
    Quat angular_offset = Quat::Identity();  // in A's frame, on top of the relative orientation at creation
    Real max_force = 0;                      // N; 0: no pull on the anchor
    Real max_torque = 0;                     // N m; 0: rotation free
    Real linear_hertz = 0;                   // 0: as stiff as the solver's joints
    Real linear_damping_ratio = 1;
    Real angular_hertz = 0;
    Real angular_damping_ratio = 1;
};

struct JointDesc {
    JointType type = JointType::BallSocket;
    BodyHandle body_a;
    BodyHandle body_b;
    JointAnchors anchors;
    HingeParams hinge;               // used by Hinge
    DistanceParams distance;         // used by Distance
    SwingTwistParams swing_twist;    // used by SwingTwist
    PrismaticParams prismatic;       // used by Prismatic
    MotorParams motor;               // used by Motor
    bool collide_connected = false;  // false: the two bodies never make contacts with each other
    std::uint64_t user_data = 0;

    static JointDesc ball_socket_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor);
    static JointDesc hinge_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor, const Vec3& world_axis);
    static JointDesc fixed_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor);
    static JointDesc prismatic_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor, const Vec3& world_axis);
    static JointDesc swing_twist_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor, const Vec3& world_twist_axis);
    // A motor joint with both anchors at world_anchor and zero offsets (it holds B where
    // it is); set the offsets, caps and stiffness in `motor`.
    static JointDesc motor_between(BodyHandle a, BodyHandle b, const Vec3& world_anchor);
    // A mouse joint: the point world_point of `body` pulled toward a world target (at
    // first the point itself) by a spring of `hertz` and damping_ratio, at most max_force;
    // `world` is a static body. Contacts between the two stay on (collide_connected).
    static JointDesc mouse_at(BodyHandle world, BodyHandle body, const Vec3& world_point, Real hertz,
                              Real damping_ratio, Real max_force);
    static JointDesc distance_between(BodyHandle a, BodyHandle b, const Vec3& world_anchor_a,
                                      const Vec3& world_anchor_b);
};

// How far a joint is from satisfied, from the bodies' current poses.
struct JointError {
    // m: anchor separation; distance joint: length outside what it allows; prismatic: B's
    // anchor off the axis, plus how far the translation is outside its limits; motor: B's
    // anchor from its target
    Real linear = 0;
    // rad: hinge axis misalignment, fixed and prismatic joint rotation error; motor: B's
    // turn from its target (0 with max_torque 0); swing-twist: how far the
    // swing is outside its cone or the twist outside its range, whichever is more
    Real angular = 0;
};

}  // namespace spindle
