// Space accessors: buffered (any thread; published reads, write buffer) and internal
// (the update thread; live state).
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include "api/validation.hpp"
#include "solver/speed_limit.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

// The field a vector write carries, for its error message.
const char* field_of(WriteKind kind) {
    switch (kind) {
        case WriteKind::Position: return "position";
        case WriteKind::LinearVelocity: return "linear_velocity";
        case WriteKind::AngularVelocity: return "angular_velocity";
        case WriteKind::Force: return "force";
        case WriteKind::Torque: return "torque";
        case WriteKind::Impulse: return "impulse";
        case WriteKind::AngularImpulse: return "angular_impulse";
        default: return "value";
    }
}

}  // namespace

MotionState Space::motion_state(BodyHandle body) const { return m_world->motion_states.read(body); }
Vec3 Space::position(BodyHandle body) const { return motion_state(body).position; }
Quat Space::orientation(BodyHandle body) const { return motion_state(body).orientation; }
Vec3 Space::center_of_mass(BodyHandle body) const { return motion_state(body).center_of_mass; }
Vec3 Space::linear_velocity(BodyHandle body) const { return motion_state(body).linear_velocity; }
Vec3 Space::angular_velocity(BodyHandle body) const { return motion_state(body).angular_velocity; }

namespace {

void push_vector(World& world, BodyHandle body, WriteKind kind, const Vec3& value, const char* what) {
    if (kind == WriteKind::Position) {
        check_position(value, what, field_of(kind));
    } else {
        check_finite(value, what, field_of(kind));
    }
    check_handle_for_write(world.motion_states, body, what);
    BufferedWrite write;
    write.body = body;
    write.kind = kind;
    write.vector = value;
    world.writes.push(write);
}

}  // namespace

void Space::set_position(BodyHandle body, const Vec3& p) {
    push_vector(*m_world, body, WriteKind::Position, p, "set_position");
}
void Space::set_linear_velocity(BodyHandle body, const Vec3& v) {
    push_vector(*m_world, body, WriteKind::LinearVelocity, v, "set_linear_velocity");
}
void Space::set_angular_velocity(BodyHandle body, const Vec3& w) {
    push_vector(*m_world, body, WriteKind::AngularVelocity, w, "set_angular_velocity");
}
void Space::add_force(BodyHandle body, const Vec3& f) { push_vector(*m_world, body, WriteKind::Force, f, "add_force"); }
void Space::add_torque(BodyHandle body, const Vec3& t) {
    push_vector(*m_world, body, WriteKind::Torque, t, "add_torque");
}
void Space::apply_impulse(BodyHandle body, const Vec3& j) {
    push_vector(*m_world, body, WriteKind::Impulse, j, "apply_impulse");
}
void Space::apply_angular_impulse(BodyHandle body, const Vec3& j) {
    push_vector(*m_world, body, WriteKind::AngularImpulse, j, "apply_angular_impulse");
}

void Space::set_orientation(BodyHandle body, const Quat& orientation) {
    check_orientation(orientation, "set_orientation", "orientation");
    check_handle_for_write(m_world->motion_states, body, "set_orientation");
    BufferedWrite write;
    write.body = body;
    write.kind = WriteKind::Orientation;
    write.rotation = orientation;
    m_world->writes.push(write);
}

void Space::set_motion_state(BodyHandle body, const MotionState& state) {
    validate(state, "set_motion_state");
    check_handle_for_write(m_world->motion_states, body, "set_motion_state");
    BufferedWrite write;
    write.body = body;
    write.kind = WriteKind::MotionState;
    write.state = state;
    m_world->writes.push(write);
}

void Space::wake(BodyHandle body) {
    check_handle_for_write(m_world->motion_states, body, "wake");
    BufferedWrite write;
    write.body = body;
    write.kind = WriteKind::Wake;
    m_world->writes.push(write);
}

void Space::set_collision_filter(BodyHandle body, std::uint32_t layer, std::uint32_t group) {
    check_layer(layer, "set_collision_filter", "layer");
    check_handle_for_write(m_world->motion_states, body, "set_collision_filter");
    BufferedWrite write;
    write.body = body;
    write.kind = WriteKind::Filter;
    write.layer = layer;
    write.group = group;
    m_world->writes.push(write);
}

// ---- internal ----

namespace {

std::uint32_t live_slot(const World& w, BodyHandle body, const char* what) {
    if (!w.bodies.is_live(body)) {
        throw Error(std::string(what) + ": " + to_string(body) + " is not a live body (stale or foreign handle)");
    }
    return body.index;
}

}  // namespace

MotionState Space::internal_motion_state(BodyHandle body) const {
    const AccessGate::Structure access(m_world->gate, "internal_motion_state");
    const Bodies& b = m_world->bodies;
    const std::uint32_t i = live_slot(*m_world, body, "internal_motion_state");
    return MotionState{b.origin(i), b.q[i], b.v[i], b.w[i], b.x[i]};
}
Vec3 Space::internal_position(BodyHandle body) const { return internal_motion_state(body).position; }
Quat Space::internal_orientation(BodyHandle body) const { return internal_motion_state(body).orientation; }
Vec3 Space::internal_linear_velocity(BodyHandle body) const { return internal_motion_state(body).linear_velocity; }
Vec3 Space::internal_angular_velocity(BodyHandle body) const { return internal_motion_state(body).angular_velocity; }

void Space::set_internal_motion_state(BodyHandle body, const MotionState& state) {
    const AccessGate::Structure access(m_world->gate, "set_internal_motion_state");
    const std::uint32_t i = live_slot(*m_world, body, "set_internal_motion_state");
    validate(state, "set_internal_motion_state");
    Bodies& b = m_world->bodies;
    wake_touching(*m_world, i);  // a static body too; before its proxy moves
    b.q[i] = state.orientation.normalized();
    b.x[i] = state.position + b.q[i] * b.local_com[i];
    if (b.type[i] != MotionType::Static) {
        b.v[i] = limit_speed(project_linear(state.linear_velocity, b.locks[i]),
                             m_world->settings.solver.max_linear_speed);
        b.w[i] = limit_speed(project_angular(state.angular_velocity, b.locks[i]),
                             m_world->settings.solver.max_angular_speed);
    }
    b.bounds[i] = b.traits[i].shape.bounds(b.transform(i));
    refresh_proxy(*m_world, i);
    m_world->changed_now.push_back(i);
}

bool Space::internal_is_awake(BodyHandle body) const {
    const AccessGate::Structure access(m_world->gate, "internal_is_awake");
    return m_world->bodies.awake_index[live_slot(*m_world, body, "internal_is_awake")] >= 0;
}

BodyDesc Space::internal_desc(BodyHandle body) const {
    const AccessGate::Structure access(m_world->gate, "internal_desc");
    const Bodies& b = m_world->bodies;
    const std::uint32_t i = live_slot(*m_world, body, "internal_desc");
    return b.traits[i].described(b.origin(i), b.q[i], b.v[i], b.w[i]);
}

}  // namespace spindle
