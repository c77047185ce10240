// The joint store behind Space's joint API (joint_api.cpp): slots with generations,
// each joint's frames in its bodies' centre-of-mass frames, and the impulses kept
// between steps for warm starting. The solver reads it in joint_solver.cpp.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <spindle/engine/joint.hpp>

namespace spindle {

struct World;

// What the solver needs of one joint, fixed at creation (frames) or carried between
// steps (impulses). Frames are relative to each body's centre of mass, in its own
// frame, so they hold however the bodies move.
struct Joint {
    JointType type = JointType::BallSocket;
    std::uint32_t body_a = 0, body_b = 0;  // slots
    Vec3 local_a = Vec3::Zero();           // anchor on A
    Vec3 local_b = Vec3::Zero();           // anchor on B
    Vec3 axis_a = Vec3::UnitZ();           // hinge (swing-twist: twist; prismatic: slide) axis on A
    Vec3 axis_b = Vec3::UnitZ();           // hinge (swing-twist: twist) axis on B
    Vec3 ref_a = Vec3::UnitX();            // perpendicular to the axis, equal in world at creation
    Vec3 ref_b = Vec3::UnitX();
    Quat reference = Quat::Identity();  // fixed, prismatic, motor: B's orientation in A's frame at creation
    Real rest_length = 0;               // distance; prismatic: the anchors' offset along the axis at creation
    HingeParams hinge;
    DistanceParams distance;
    SwingTwistParams swing_twist;
    PrismaticParams prismatic;
    MotorParams motor;  // the offsets as last set (Space::set_motor_target)
    bool collide_connected = false;
    bool sleeping = false;  // both bodies asleep (or one asleep, one static)

    // Accumulated impulses of the last step (warm starting).
    Vec3 linear_impulse = Vec3::Zero();   // point constraint (prismatic: off the axis; motor: the pull), world
    Vec3 angular_impulse = Vec3::Zero();  // hinge alignment / fixed, prismatic, motor rotation / swing-twist friction
    Real axial_impulse = 0;               // distance: the rigid or spring row; prismatic: the spring
    Real motor_impulse = 0;
    Real lower_impulse = 0;
    Real upper_impulse = 0;
    Real swing_impulse = 0;  // swing-twist cone, along the swing axis
};

// Joints by slot (holes where joints were destroyed), like Bodies. Hot data (Joint)
// apart from the description as given (read only on request).
struct Joints {
    std::vector<std::uint32_t> generation;
    std::vector<std::uint8_t> alive;
    std::vector<std::uint32_t> free_slots;  // LIFO; reused slots get a new generation
    std::uint32_t live = 0;
    std::vector<Joint> joint;
    std::vector<JointDesc> desc;
    // Pair key (min slot << 32 | max slot) -> number of joints between the two bodies
    // that switch their collision off (collide_connected = false).
    std::unordered_map<std::uint64_t, std::uint32_t> blocked_pairs;
    // Slots of the live joints that are not asleep, ascending; rebuilt only after a joint
    // is made, destroyed, or changes sleep, so sleeping joints cost nothing per step.
    std::vector<std::uint32_t> awake_list;
    bool awake_dirty = false;

    std::uint32_t capacity() const noexcept { return static_cast<std::uint32_t>(generation.size()); }
    bool is_live(JointHandle h) const noexcept {
        return h.index < generation.size() && alive[h.index] && generation[h.index] == h.generation &&
               h.generation != 0;
    }
    JointHandle handle(std::uint32_t slot) const noexcept { return {slot, generation[slot]}; }
};

inline std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t{a < b ? a : b} << 32) | (a < b ? b : a);
}

// True when a joint between bodies a and b (slots) switches their collision off; the
// broadphase asks before it makes a contact for each new pair. Inline, so that without
// such a joint (most spaces) the question is one test of an empty table, not a call.
inline bool joint_blocks_pair(const Joints& joints, std::uint32_t a, std::uint32_t b) {
    return !joints.blocked_pairs.empty() && joints.blocked_pairs.count(pair_key(a, b)) != 0;
}

// The awake joints' slots (Joints::awake_list, rebuilt first if stale).
const std::vector<std::uint32_t>& awake_joints(World& world);

// Destroys every joint attached to a body (destroy_body), waking its partners.
void destroy_joints_of(World& world, std::uint32_t body_slot);

}  // namespace spindle
