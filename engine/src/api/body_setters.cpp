// The buffered changes after creation (issue 17): material, gravity scale, damping,
// motion type, shape, user data, forces and impulses at points, kinematic moves. Each
// checks its values, then the handle (lock-free), then goes to the write buffer; ApplyWrites
// makes it live (stages/body_changes.cpp).
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include "api/validation.hpp"
#include "solver/speed_limit.hpp"
#include "world.hpp"

namespace spindle {
namespace {

const char* name_of(MotionType type) {
    switch (type) {
        case MotionType::Static: return "Static";
        case MotionType::Kinematic: return "Kinematic";
        case MotionType::Dynamic: return "Dynamic";
    }
    return "?";
}

BufferedWrite write_of(BodyHandle body, WriteKind kind) {
    BufferedWrite write;
    write.body = body;
    write.kind = kind;
    return write;
}

// A force or impulse at a world point: the vector and its moment about the origin.
void push_at(World& world, BodyHandle body, WriteKind kind, const Vec3& vector, const Vec3& point, const char* who,
             const char* field) {
    check_finite(vector, who, field);
    check_position(point, who, "point");
    check_handle_for_write(world.motion_states, body, who);
    BufferedWrite write = write_of(body, kind);
    write.vector = vector;
    write.moment = saturated_cross(point, vector);
    world.writes.push(write);
}

void push_scalar(World& world, BodyHandle body, WriteKind kind, Real value, const char* who) {
    check_handle_for_write(world.motion_states, body, who);
    BufferedWrite write = write_of(body, kind);
    write.scalar = value;
    world.writes.push(write);
}

}  // namespace

void Space::set_friction(BodyHandle body, Real friction) {
    check_non_negative(friction, "set_friction", "friction");
    push_scalar(*m_world, body, WriteKind::Friction, friction, "set_friction");
}

void Space::set_restitution(BodyHandle body, Real restitution) {
    check_non_negative(restitution, "set_restitution", "restitution");
    push_scalar(*m_world, body, WriteKind::Restitution, restitution, "set_restitution");
}

void Space::set_rolling_resistance(BodyHandle body, Real rolling_resistance) {
    check_non_negative(rolling_resistance, "set_rolling_resistance", "rolling_resistance");
    push_scalar(*m_world, body, WriteKind::RollingResistance, rolling_resistance, "set_rolling_resistance");
}

void Space::set_gravity_scale(BodyHandle body, Real scale) {
    check_finite(scale, "set_gravity_scale", "gravity_scale");
    push_scalar(*m_world, body, WriteKind::GravityScale, scale, "set_gravity_scale");
}

void Space::set_damping(BodyHandle body, Real linear, Real angular) {
    check_non_negative(linear, "set_damping", "linear_damping");
    check_non_negative(angular, "set_damping", "angular_damping");
    check_handle_for_write(m_world->motion_states, body, "set_damping");
    BufferedWrite write = write_of(body, WriteKind::Damping);
    write.scalar = linear;
    write.scalar2 = angular;
    m_world->writes.push(write);
}

void Space::set_motion_type(BodyHandle body, MotionType type) {
    const char* who = "set_motion_type";
    if (type != MotionType::Static && type != MotionType::Kinematic && type != MotionType::Dynamic) {
        reject_field(who, "type", "must be Static, Kinematic or Dynamic", std::to_string(static_cast<int>(type)));
    }
    check_handle_for_write(m_world->motion_states, body, who);
    if (type != MotionType::Static && m_world->motion_states.published_static_only_shape(body.index)) {
        throw Error(std::string(who) + ": " + to_string(body) + " has a plane or triangle mesh shape, which only a " +
                    "static body can have (type " + name_of(type) + ")");
    }
    BufferedWrite write = write_of(body, WriteKind::MotionType);
    write.motion_type = type;
    m_world->writes.push(write);
}

void Space::set_shape(BodyHandle body, const Shape& shape, bool keep_mass) {
    const char* who = "set_shape";
    validate(shape, who);
    check_handle_for_write(m_world->motion_states, body, who);
    const MotionType type = m_world->motion_states.published_motion_type(body.index);
    if (shape.static_only() && type != MotionType::Static) {
        throw Error(std::string(who) + ": a " + to_string(shape.type) + " shape can only belong to a static body (" +
                    to_string(body) + " is " + name_of(type) + ")");
    }
    if (type == MotionType::Dynamic && !keep_mass) {
        const MassProperties unit = shape.mass_properties(1);
        if (!(unit.mass > 0) || !unit.inertia.allFinite()) {
            reject_field(who, "shape", "must have a volume for a dynamic body, mass per density",
                         std::to_string(unit.mass));
        }
    }
    BufferedWrite write = write_of(body, WriteKind::Shape);
    write.shape = shape;
    write.keep_mass = keep_mass;
    m_world->writes.push(write);
}

void Space::set_user_data(BodyHandle body, std::uint64_t user_data) {
    check_handle_for_write(m_world->motion_states, body, "set_user_data");
    BufferedWrite write = write_of(body, WriteKind::UserData);
    write.user_data = user_data;
    m_world->writes.push(write);
}

std::uint64_t Space::user_data(BodyHandle body) const { return m_world->motion_states.read_user_data(body); }

void Space::add_force_at(BodyHandle body, const Vec3& force, const Vec3& point) {
    push_at(*m_world, body, WriteKind::ForceAt, force, point, "add_force_at", "force");
}

void Space::apply_impulse_at(BodyHandle body, const Vec3& impulse, const Vec3& point) {
    push_at(*m_world, body, WriteKind::ImpulseAt, impulse, point, "apply_impulse_at", "impulse");
}

void Space::move_kinematic(BodyHandle body, const Vec3& position, const Quat& orientation) {
    const char* who = "move_kinematic";
    check_position(position, who, "position");
    check_orientation(orientation, who, "orientation");
    check_handle_for_write(m_world->motion_states, body, who);
    const MotionType type = m_world->motion_states.published_motion_type(body.index);
    if (type != MotionType::Kinematic) {
        throw Error(std::string(who) + ": " + to_string(body) + " is " + name_of(type) + ", not Kinematic");
    }
    BufferedWrite write = write_of(body, WriteKind::KinematicMove);
    write.vector = position;
    write.rotation = orientation;
    m_world->writes.push(write);
}

}  // namespace spindle
