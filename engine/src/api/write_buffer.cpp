// WriteBuffer: pending writes coalesced per body, striped by slot.
#include "api/write_buffer.hpp"

#include <algorithm>

#include "solver/speed_limit.hpp"

namespace spindle {
namespace {

// Adds v to one of the entry's sums, which starts afresh when its bit is clear (never
// written, or dropped by a velocity write since).
void accumulate(PendingWrites& entry, Vec3& sum, std::uint16_t bit, const Vec3& v) {
    sum = (entry.bits & bit) != 0 ? saturate(sum + v) : v;
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
            entry.bits = (entry.bits | kPendingAngularVelocity) & ~kPendingAngularImpulse;
            break;
        case WriteKind::MotionState:
            entry.position = write.state.position;
            entry.orientation = write.state.orientation;
            entry.linear_velocity = write.state.linear_velocity;
            entry.angular_velocity = write.state.angular_velocity;
            entry.bits = (entry.bits | kPendingPose | kPendingVelocity) & ~(kPendingImpulse | kPendingAngularImpulse);
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
    }
}

}  // namespace

void WriteBuffer::push(const BufferedWrite& write) {
    const std::uint32_t slot = write.body.index;
    Stripe& stripe = m_stripes[slot % kStripes];
    const std::uint32_t local = slot / kStripes;
    std::scoped_lock guard(stripe.lock);
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
        std::scoped_lock guard(stripe.lock);
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
