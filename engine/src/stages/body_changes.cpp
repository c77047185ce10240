// Changes to a body after its creation (ApplyWrites): material recombined into its
// contacts, motion type and shape with everything that depends on them (mass, awake
// list, proxy tree, contacts, fast-body count), and kinematic moves.
#include "stages/body_changes.hpp"

#include <spindle/platform/error.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

#include "api/describe.hpp"
#include "solver/speed_limit.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {

BodyMass body_mass(const BodyTraits& traits, MotionType type, const Shape& shape, const char* who) {
    BodyMass out;
    if (type != MotionType::Dynamic) return out;
    MassProperties mp = shape.mass_properties(traits.density);
    if (traits.mass > 0) {
        mp.inertia *= traits.mass / mp.mass;
        mp.mass = traits.mass;
    }
    if (!(mp.mass > 0)) {
        throw Error(std::string(who) + ": the shape has no volume (mass " + number(mp.mass) + ")");
    }
    const std::string range = "within [" + number(kMinMass) + ", " + number(kMaxMass) + "]";
    if (!(mp.mass >= kMinMass && mp.mass <= kMaxMass)) {
        throw Error(std::string(who) + ": mass must be " + range + " kg (the solver's single precision), got " +
                    number(mp.mass));
    }
    // Principal inertias, ascending: a compound's inertia need not be diagonal.
    const Vec3 principal =
        mp.inertia.allFinite()
            ? Vec3(Eigen::SelfAdjointEigenSolver<Mat3>(mp.inertia, Eigen::EigenvaluesOnly).eigenvalues())
            : Vec3(mp.inertia.diagonal());
    if (!(principal.x() >= kMinMass && principal.z() <= kMaxMass)) {
        throw Error(std::string(who) + ": its mass properties are out of range: principal inertias must be " + range +
                    " kg m^2 (the solver's single precision), got " + vec(principal));
    }
    out.inv_mass = 1 / mp.mass;
    out.inv_inertia = mp.inertia.inverse();
    out.inertia = mp.inertia;
    out.local_com = mp.center_of_mass;
    out.elongated = principal.z() > kElongatedInertiaRatio * principal.x();
    return out;
}

void recombine_materials(World& world, std::span<const std::uint32_t> slots) {
    const auto changed = [slots](std::uint32_t i) { return std::binary_search(slots.begin(), slots.end(), i); };
    const Bodies& b = world.bodies;
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        Contact& contact = world.contacts[c];
        if (!changed(contact.body_a) && !changed(contact.body_b)) continue;
        mix_materials(b.traits[contact.body_a], b.traits[contact.body_b], contact);
        world.contact_summaries[c] = contact_summary(contact);  // its restitution bit
    }
}

namespace {

// Joint frames are kept from the centre of mass (joint_store.hpp): when it moves in the
// body, they move back by as much, so the anchors stay on the same material point.
void shift_joint_frames(World& world, std::uint32_t slot, const Vec3& old_com, const Vec3& new_com) {
    Joints& joints = world.joints;
    if (joints.live == 0 || old_com == new_com) return;
    const Vec3 delta = old_com - new_com;
    for (std::uint32_t j = 0; j < joints.capacity(); ++j) {
        if (!joints.alive[j]) continue;
        Joint& joint = joints.joint[j];
        if (joint.body_a == slot) joint.local_a += delta;
        if (joint.body_b == slot) joint.local_b += delta;
    }
}

// The body's new mass, centre of mass kept under its origin.
void set_mass(World& world, std::uint32_t slot, const BodyMass& mass) {
    Bodies& b = world.bodies;
    const Vec3 origin = b.origin(slot);
    shift_joint_frames(world, slot, b.local_com[slot], mass.local_com);
    b.inv_mass[slot] = mass.inv_mass;
    b.inv_inertia_local[slot] = mass.inv_inertia;
    b.inertia_local[slot] = mass.inertia;
    b.elongated[slot] = mass.elongated ? 1 : 0;
    b.local_com[slot] = mass.local_com;
    b.x[slot] = origin + b.q[slot] * mass.local_com;
}

// Before a change that takes away what rests on the body or changes what it collides
// as: everything it touches wakes, and its contacts and proxy go (made again after).
void detach(World& world, std::uint32_t slot) {
    wake_touching(world, slot);
    remove_contacts_of(world, slot);
    remove_proxy(world, slot);
}

// After: a new proxy (in the tree of its motion type), whose pairs the next broadphase
// reports as for a created body, and the extents the solver's sweep check reads.
void attach(World& world, std::uint32_t slot) {
    Bodies& b = world.bodies;
    b.bounds[slot] = b.traits[slot].shape.bounds(b.transform(slot));
    b.remake_extent(slot);  // a new shape, centre of mass or motion type
    add_proxy(world, slot);
    world.changed_now.push_back(slot);
    publish_kind(world, slot);
}

}  // namespace

bool change_motion_type(World& world, std::uint32_t slot, MotionType type) {
    Bodies& b = world.bodies;
    if (b.type[slot] == type) return true;
    BodyMass mass;
    try {
        mass = body_mass(b.traits[slot], type, b.traits[slot].shape, "set_motion_type");
    } catch (const Error&) {
        return false;
    }
    detach(world, slot);  // wakes the body first, so it is in no sleeping island
    if (b.is_fast(slot)) world.fast_bodies -= 1;
    const MotionType before = b.type[slot];
    b.type[slot] = type;
    b.traits[slot].type = type;
    set_mass(world, slot, mass);
    b.locks[slot] = type == MotionType::Static ? 0 : lock_bits(b.traits[slot].locks);
    if (type == MotionType::Static || before == MotionType::Static) {
        // A static body has no velocity; a static body set moving starts at rest.
        b.v[slot] = b.w[slot] = Vec3::Zero();
    } else {
        b.v[slot] = project_linear(b.v[slot], b.locks[slot]);
        b.w[slot] = project_angular(b.w[slot], b.locks[slot]);
    }
    b.force[slot] = b.torque[slot] = Vec3::Zero();
    if (b.is_fast(slot)) world.fast_bodies += 1;
    set_awake(world, slot, type != MotionType::Static);
    b.island[slot] = -1;
    if (type == MotionType::Static) {
        // A static body is never recorded again: both history steps hold its pose, so an
        // interpolated read does not stay a step behind.
        b.reset_history(slot);
    } else if (before == MotionType::Static) {
        // Its first history (a static body has none), or the one its slot's last moving
        // body left.
        b.hold_history(slot, b.origin(slot), b.q[slot]);
    }
    world.body_set_version += 1;  // the solver's colours depend on which bodies are dynamic
    attach(world, slot);
    return true;
}

bool change_shape(World& world, std::uint32_t slot, const Shape& shape, bool keep_mass) {
    Bodies& b = world.bodies;
    BodyMass mass;
    if (!keep_mass) {
        try {
            mass = body_mass(b.traits[slot], b.type[slot], shape, "set_shape");
        } catch (const Error&) {
            return false;
        }
    }
    detach(world, slot);
    if (!keep_mass) set_mass(world, slot, mass);
    b.traits[slot].shape = shape;
    attach(world, slot);
    return true;
}

int apply_body_changes(World& world, const PendingWrites& write, std::vector<std::uint32_t>& rematerialed) {
    constexpr std::uint32_t kMaterial = kPendingFriction | kPendingRestitution | kPendingRollingResistance;
    constexpr std::uint32_t kChanges = kPendingMotionType | kPendingShape | kMaterial | kPendingGravityScale |
                                       kPendingDamping | kPendingUserData;
    if ((write.bits & kChanges) == 0) return 0;
    Bodies& b = world.bodies;
    const std::uint32_t i = write.body.index;
    BodyTraits& traits = b.traits[i];
    int rejected = 0;
    if ((write.bits & kPendingMotionType) != 0 && !change_motion_type(world, i, write.motion_type)) rejected += 1;
    if ((write.bits & kPendingShape) != 0) {
        // A shape only a static body can have stays off a body that is not (any more).
        const bool fits = !write.shape.static_only() || b.type[i] == MotionType::Static;
        if (!fits || !change_shape(world, i, write.shape, write.keep_mass)) rejected += 1;
    }
    if ((write.bits & kMaterial) != 0) {
        if ((write.bits & kPendingFriction) != 0) traits.friction = write.friction;
        if ((write.bits & kPendingRestitution) != 0) traits.restitution = write.restitution;
        if ((write.bits & kPendingRollingResistance) != 0) traits.rolling_resistance = write.rolling_resistance;
        rematerialed.push_back(i);
        // What rests on a static body slides or bounces differently now (a moving body is
        // woken with its island by ApplyWrites).
        if (b.type[i] == MotionType::Static) wake_touching(world, i);
    }
    if ((write.bits & kPendingGravityScale) != 0) traits.gravity_scale = write.gravity_scale;
    if ((write.bits & kPendingDamping) != 0) {
        traits.linear_damping = write.linear_damping;
        traits.angular_damping = write.angular_damping;
    }
    if ((write.bits & kPendingUserData) != 0) {
        traits.user_data = write.user_data;
        world.changed_now.push_back(i);  // published at this update's flip, awake or not
    }
    return rejected;
}

void add_kinematic_move(World& world, std::uint32_t slot, const Vec3& origin, const Quat& orientation) {
    const Bodies& b = world.bodies;
    const Quat q = orientation.normalized();
    KinematicMove move{BodyHandle{slot, b.generation[slot]}, origin + q * b.local_com[slot], q};
    for (KinematicMove& pending : world.kinematic_moves) {
        if (pending.body.index == slot) {
            pending = move;  // the last write wins
            return;
        }
    }
    world.kinematic_moves.push_back(move);
}

void start_kinematic_moves(World& world, Real dt) {
    Bodies& b = world.bodies;
    // A body destroyed or no longer kinematic since its move was written does not move.
    std::erase_if(world.kinematic_moves, [&](const KinematicMove& m) {
        return !b.is_live(m.body) || b.type[m.body.index] != MotionType::Kinematic;
    });
    for (const KinematicMove& move : world.kinematic_moves) {
        const std::uint32_t i = move.body.index;
        b.v[i] = (move.center_of_mass - b.x[i]) / dt;
        // The turn from the current orientation to the target, on the shortest arc.
        Quat turn = move.orientation * b.q[i].conjugate();
        if (turn.w() < 0) turn.coeffs() = -turn.coeffs();
        const Eigen::AngleAxis<Real> axis_angle(turn.normalized());
        b.w[i] = axis_angle.axis() * (axis_angle.angle() / dt);
    }
}

void finish_kinematic_moves(World& world) {
    Bodies& b = world.bodies;
    for (const KinematicMove& move : world.kinematic_moves) {
        const std::uint32_t i = move.body.index;
        // Exactly on the target: the integration reached it only to rounding.
        b.x[i] = move.center_of_mass;
        b.q[i] = move.orientation;
        b.v[i] = b.w[i] = Vec3::Zero();
    }
    world.kinematic_moves.clear();
}

}  // namespace spindle
