// The write side of buffering: writes from any number of threads wait here until
// ApplyWrites, coalesced per body as the seed says: one pending value per body and
// property, the last write winning, and forces, torques and impulses summed. So
// ApplyWrites costs in proportion to the bodies written, not to the writes made, and a
// flood of writes cannot grow the buffer beyond one entry per body.
//
// The entries are striped by body slot, each stripe under its own mutex: writes to
// different bodies rarely contend, and all writes to one body pass one lock, whose
// order is the order the writes were made (the last one wins across threads too).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/platform/spin.hpp>

namespace spindle {

enum class WriteKind : std::uint8_t {
    Position,
    Orientation,
    LinearVelocity,
    AngularVelocity,
    MotionState,  // all of it
    Force,        // additive from here on
    Torque,
    Impulse,
    AngularImpulse,
    Wake,
    Filter,  // layer and group
    // Changes after creation (api/body_setters.cpp): each replaces the last of its kind.
    Friction,
    Restitution,
    RollingResistance,
    GravityScale,
    Damping,  // linear and angular
    MotionType,
    Shape,
    UserData,
    KinematicMove,  // target pose
    ForceAt,        // force at a world point: the force, and its moment about the origin
    ImpulseAt,      // the same for an impulse
};

// One write as a caller makes it.
struct BufferedWrite {
    BodyHandle body;
    WriteKind kind = WriteKind::Wake;
    Vec3 vector = Vec3::Zero();          // position, velocity, force, impulse, kinematic target
    Vec3 moment = Vec3::Zero();          // force or impulse at a point: p x vector
    Quat rotation = Quat::Identity();    // orientation
    MotionState state;                   // motion state
    std::uint32_t layer = 0, group = 0;  // collision filter
    Real scalar = 0,
         scalar2 = 0;  // friction, restitution, rolling resistance, gravity scale, damping (linear, angular)
    std::uint64_t user_data = 0;
    spindle::MotionType motion_type = spindle::MotionType::Dynamic;
    bool keep_mass = false;
    spindle::Shape shape;  // set_shape only (empty otherwise: no geometry is copied)
};

// Which properties a body's pending entry holds.
enum PendingBits : std::uint32_t {
    kPendingPosition = 1U << 0U,
    kPendingOrientation = 1U << 1U,
    kPendingLinearVelocity = 1U << 2U,
    kPendingAngularVelocity = 1U << 3U,
    kPendingForce = 1U << 4U,
    kPendingTorque = 1U << 5U,
    kPendingImpulse = 1U << 6U,
    kPendingAngularImpulse = 1U << 7U,
    kPendingWake = 1U << 8U,
    kPendingFilter = 1U << 9U,
    kPendingFriction = 1U << 10U,
    kPendingRestitution = 1U << 11U,
    kPendingGravityScale = 1U << 12U,
    kPendingDamping = 1U << 13U,
    kPendingMotionType = 1U << 14U,
    kPendingShape = 1U << 15U,
    kPendingUserData = 1U << 16U,
    kPendingKinematicMove = 1U << 17U,
    kPendingForceAt = 1U << 18U,
    kPendingImpulseAt = 1U << 19U,
    kPendingRollingResistance = 1U << 20U,
    kPendingPose = kPendingPosition | kPendingOrientation,
    kPendingVelocity = kPendingLinearVelocity | kPendingAngularVelocity,
};

// One body's writes since the last ApplyWrites. A velocity written after an impulse
// replaces it (the impulse was made to the velocity it overwrites); an impulse written
// after a velocity adds to it. ApplyWrites applies pose, then velocities, then impulses,
// then adds forces and torques for the next step.
struct PendingWrites {
    BodyHandle body;
    std::uint32_t writes = 0;  // calls coalesced into this entry
    std::uint32_t bits = 0;    // PendingBits
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();
    Vec3 linear_velocity = Vec3::Zero();
    Vec3 angular_velocity = Vec3::Zero();
    Vec3 force = Vec3::Zero();  // sums, saturated so they stay finite; valid where their bit is set
    Vec3 torque = Vec3::Zero();
    Vec3 impulse = Vec3::Zero();
    Vec3 angular_impulse = Vec3::Zero();
    std::uint32_t layer = 0, group = 0;  // valid where kPendingFilter is set
    // Changes after creation, each valid where its bit is set.
    Real friction = 0, restitution = 0, rolling_resistance = 0, gravity_scale = 1;
    Real linear_damping = 0, angular_damping = 0;
    spindle::MotionType motion_type = spindle::MotionType::Dynamic;
    bool keep_mass = false;
    spindle::Shape shape;
    std::uint64_t user_data = 0;
    Vec3 target_position = Vec3::Zero();  // kinematic move: the shape's origin
    Quat target_orientation = Quat::Identity();
    // Forces and impulses at points: their sums, and the sums of their moments about the
    // world origin (p x f). ApplyWrites turns them into a torque about the centre of mass
    // as it is then: sum(p x f) - c x sum(f).
    Vec3 force_at = Vec3::Zero(), force_moment = Vec3::Zero();
    Vec3 impulse_at = Vec3::Zero(), impulse_moment = Vec3::Zero();
};

class WriteBuffer {
public:
    // Any thread. Holds one stripe's lock for the merge of one write.
    void push(const BufferedWrite& write);
    // The update thread: every body's pending entry, in slot order (so what ApplyWrites
    // does never depends on which thread wrote first). `out` is reused between updates.
    // `superseded` gets the writes dropped because their body's slot was reused by a
    // newer body before they were applied.
    void drain(std::vector<PendingWrites>& out, std::uint32_t& superseded);
    // Stripes whose lock drain took so far: only those written to since the last drain. The
    // update thread.
    std::uint64_t stripes_drained() const noexcept { return m_stripes_drained; }

private:
    static constexpr std::uint32_t kStripes = 64;
    struct alignas(cache_line_size) Stripe {
        std::mutex lock;
        // Set by push under the lock, cleared by drain under it and read by drain before
        // taking it: an update with nothing written takes no lock at all. A write that
        // happened before the update is seen; one racing with it may wait for the next.
        std::atomic<bool> written{false};
        std::vector<std::int32_t> entry_of;  // by slot / kStripes: index into entries, -1 none
        std::vector<PendingWrites> entries;
        std::uint32_t superseded = 0;
    };
    Stripe m_stripes[kStripes];
    std::uint64_t m_stripes_drained = 0;
};

}  // namespace spindle
