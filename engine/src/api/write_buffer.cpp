// WriteBuffer: pending writes coalesced per body, striped by slot.
#include "api/write_buffer.hpp"

#include <algorithm>

#include "solver/speed_limit.hpp"

namespace spindle {
namespace {

// Adds v to one of the entry's sums, which starts afresh when its bit is clear (never
// written, or dropped by a velocity write since).
void accumulate(PendingWrites& entry, Vec3& sum, std::uint32_t bit, const Vec3& v) {
    sum = (entry.bits & bit) != 0 ? saturate(sum + v) : v;
    entry.bits |= bit;
}

// A force or impulse at a point: its sum and its moment about the origin, which start
// afresh when the bit is clear (ApplyWrites takes the moment about the centre of mass).
void accumulate_at(PendingWrites& entry, Vec3& sum, Vec3& moment, std::uint32_t bit, const BufferedWrite& write) {
    if ((entry.bits & bit) == 0) sum = moment = Vec3::Zero();
    sum = saturate(sum + write.vector);
    moment = saturate(moment + write.moment);
    entry.bits |= bit;
}

void merge(PendingWrites& entry, const BufferedWrite& write) {
    entry.writes += 1;
    switch (write.kind) {
        case WriteKind::Position:
            entry.position = write.vector;
            entry.bits |= kPendingPosition;
            break;
        case WriteKind::Orientation:
            entry.orientation = write.rotation;
            entry.bits |= kPendingOrientation;
            break;
        case WriteKind::LinearVelocity:
            entry.linear_velocity = write.vector;
            entry.bits = (entry.bits | kPendingLinearVelocity) & ~kPendingImpulse;
            break;
        case WriteKind::AngularVelocity:
            entry.angular_velocity = write.vector;
            // The angular part of an impulse at a point goes too; its linear part is in `impulse`.
            entry.bits = (entry.bits | kPendingAngularVelocity) & ~(kPendingAngularImpulse | kPendingImpulseAt);
            break;
        case WriteKind::MotionState:
            entry.position = write.state.position;
            entry.orientation = write.state.orientation;
            entry.linear_velocity = write.state.linear_velocity;
            entry.angular_velocity = write.state.angular_velocity;
            entry.bits = (entry.bits | kPendingPose | kPendingVelocity) &
                         ~(kPendingImpulse | kPendingAngularImpulse | kPendingImpulseAt);
            break;
        case WriteKind::Force: accumulate(entry, entry.force, kPendingForce, write.vector); break;
        case WriteKind::Torque: accumulate(entry, entry.torque, kPendingTorque, write.vector); break;
        case WriteKind::Impulse: accumulate(entry, entry.impulse, kPendingImpulse, write.vector); break;
        case WriteKind::AngularImpulse:
            accumulate(entry, entry.angular_impulse, kPendingAngularImpulse, write.vector);
            break;
        case WriteKind::Wake: entry.bits |= kPendingWake; break;
        case WriteKind::Filter:
            entry.layer = write.layer;
            entry.group = write.group;
            entry.bits |= kPendingFilter;
            break;
        case WriteKind::Friction:
            entry.friction = write.scalar;
            entry.bits |= kPendingFriction;
            break;
        case WriteKind::Restitution:
            entry.restitution = write.scalar;
            entry.bits |= kPendingRestitution;
            break;
        case WriteKind::RollingResistance:
            entry.rolling_resistance = write.scalar;
            entry.bits |= kPendingRollingResistance;
            break;
        case WriteKind::GravityScale:
            entry.gravity_scale = write.scalar;
            entry.bits |= kPendingGravityScale;
            break;
        case WriteKind::Damping:
            entry.linear_damping = write.scalar;
            entry.angular_damping = write.scalar2;
            entry.bits |= kPendingDamping;
            break;
        case WriteKind::MotionType:
            entry.motion_type = write.motion_type;
            entry.bits |= kPendingMotionType;
            break;
        case WriteKind::Shape:
            entry.shape = write.shape;
            entry.keep_mass = write.keep_mass;
            entry.bits |= kPendingShape;
            break;
        case WriteKind::UserData:
            entry.user_data = write.user_data;
            entry.bits |= kPendingUserData;
            break;
        case WriteKind::KinematicMove:
            entry.target_position = write.vector;
            entry.target_orientation = write.rotation;
            entry.bits |= kPendingKinematicMove;
            break;
        case WriteKind::ForceAt:
            // The linear part is a force like any other; the moment waits for the centre of mass.
            accumulate(entry, entry.force, kPendingForce, write.vector);
            accumulate_at(entry, entry.force_at, entry.force_moment, kPendingForceAt, write);
            break;
        case WriteKind::ImpulseAt:
            accumulate(entry, entry.impulse, kPendingImpulse, write.vector);
            accumulate_at(entry, entry.impulse_at, entry.impulse_moment, kPendingImpulseAt, write);
            break;
    }
}

}  // namespace

void WriteBuffer::push(const BufferedWrite& write) {
    const std::uint32_t slot = write.body.index;
    Stripe& stripe = m_stripes[slot % kStripes];
    const std::uint32_t local = slot / kStripes;
    std::scoped_lock guard(stripe.lock);
    stripe.written.store(true, std::memory_order_release);
    if (stripe.entry_of.size() <= local) stripe.entry_of.resize(local + 1, -1);
    std::int32_t& at = stripe.entry_of[local];
    if (at < 0) {
        at = static_cast<std::int32_t>(stripe.entries.size());
        stripe.entries.emplace_back().body = write.body;
    }
    PendingWrites& entry = stripe.entries[static_cast<std::size_t>(at)];
    if (entry.body.generation != write.body.generation) {
        // The slot holds another body than the entry's: the older one was destroyed, and
        // its writes can never apply.
        if (write.body.generation < entry.body.generation) {
            stripe.superseded += 1;
            return;
        }
        stripe.superseded += entry.writes;
        entry = PendingWrites{};
        entry.body = write.body;
    }
    merge(entry, write);
}

void WriteBuffer::drain(std::vector<PendingWrites>& out, std::uint32_t& superseded) {
    out.clear();
    superseded = 0;
    for (Stripe& stripe : m_stripes) {
        if (!stripe.written.load(std::memory_order_acquire)) continue;
        std::scoped_lock guard(stripe.lock);
        stripe.written.store(false, std::memory_order_relaxed);
        m_stripes_drained += 1;
        for (const PendingWrites& entry : stripe.entries) stripe.entry_of[entry.body.index / kStripes] = -1;
        out.insert(out.end(), stripe.entries.begin(), stripe.entries.end());
        stripe.entries.clear();
        superseded += stripe.superseded;
        stripe.superseded = 0;
    }
    std::sort(out.begin(), out.end(),
              [](const PendingWrites& a, const PendingWrites& b) { return a.body.index < b.body.index; });
}

}  // namespace spindle
