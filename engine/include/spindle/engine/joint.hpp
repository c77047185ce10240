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

struct JointDesc {
    JointType type = JointType::BallSocket;
    BodyHandle body_a;
    BodyHandle body_b;
    JointAnchors anchors;
    HingeParams hinge;               // used by Hinge
    DistanceParams distance;         // used by Distance
    SwingTwistParams swing_twist;    // used by SwingTwist
    bool collide_connected = false;  // false: the two bodies never make contacts with each other
    std::uint64_t user_data = 0;

    static JointDesc ball_socket_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor);
    static JointDesc hinge_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor, const Vec3& world_axis);
    static JointDesc fixed_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor);
    static JointDesc swing_twist_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor, const Vec3& world_twist_axis);
    static JointDesc distance_between(BodyHandle a, BodyHandle b, const Vec3& world_anchor_a,
                                      const Vec3& world_anchor_b);
};

// How far a joint is from satisfied, from the bodies' current poses.
struct JointError {
    Real linear = 0;  // m: anchor separation; distance joint: length outside what it allows
    // rad: hinge axis misalignment, fixed joint rotation error; swing-twist: how far the
    // swing is outside its cone or the twist outside its range, whichever is more
    Real angular = 0;
};

}  // namespace spindle
