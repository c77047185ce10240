// Space accessors: buffered (any thread; published reads, write buffer) and internal
// (the update thread; live state).
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

// Lock-free, so a thread holding the motion-state lock can still write. Newer
// generations than the published one may be bodies created since; ApplyWrites checks
// those. Older ones are certainly stale.
void check_handle_for_write(const MotionStateManager& manager, BodyHandle body, const char* what) {
    const bool stale = body.generation == 0 || manager.published_generation(body.index) > body.generation;
    if (stale)
        throw Error(std::string(what) + ": " + to_string(body) + " is not a live body (stale or foreign handle)");
}

void check_finite_write(const Vec3& v, const char* what) {
    if (!is_finite(v)) throw Error(std::string(what) + ": value must be finite");
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
    check_finite_write(value, what);
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
    if (!is_finite(orientation) || orientation.norm() < 1e-9) {
        throw Error("set_orientation: orientation must be a finite, non-zero quaternion");
    }
    check_handle_for_write(m_world->motion_states, body, "set_orientation");
    BufferedWrite write;
    write.body = body;
    write.kind = WriteKind::Orientation;
    write.rotation = orientation;
    m_world->writes.push(write);
}

void Space::set_motion_state(BodyHandle body, const MotionState& state) {
    if (!is_finite(state.position) || !is_finite(state.linear_velocity) || !is_finite(state.angular_velocity) ||
        !is_finite(state.orientation) || state.orientation.norm() < 1e-9) {
        throw Error("set_motion_state: every field must be finite and the orientation non-zero");
    }
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
    const Bodies& b = m_world->bodies;
    const std::uint32_t i = live_slot(*m_world, body, "internal_motion_state");
    return MotionState{b.origin(i), b.q[i], b.v[i], b.w[i], b.x[i]};
}
Vec3 Space::internal_position(BodyHandle body) const { return internal_motion_state(body).position; }
Quat Space::internal_orientation(BodyHandle body) const { return internal_motion_state(body).orientation; }
Vec3 Space::internal_linear_velocity(BodyHandle body) const { return internal_motion_state(body).linear_velocity; }
Vec3 Space::internal_angular_velocity(BodyHandle body) const { return internal_motion_state(body).angular_velocity; }

void Space::set_internal_motion_state(BodyHandle body, const MotionState& state) {
    const std::uint32_t i = live_slot(*m_world, body, "set_internal_motion_state");
    if (!is_finite(state.position) || !is_finite(state.linear_velocity) || !is_finite(state.angular_velocity) ||
        !is_finite(state.orientation) || state.orientation.norm() < 1e-9) {
        throw Error("set_internal_motion_state: every field must be finite and the orientation non-zero");
    }
    Bodies& b = m_world->bodies;
    b.q[i] = state.orientation.normalized();
    b.x[i] = state.position + b.q[i] * b.local_com[i];
    if (b.type[i] != MotionType::Static) {
        b.v[i] = state.linear_velocity;
        b.w[i] = state.angular_velocity;
        wake_body(*m_world, i);
    }
    b.bounds[i] = b.desc[i].shape.bounds(b.transform(i));
    refresh_proxy(*m_world, i);
    m_world->changed_now.push_back(i);
}

bool Space::internal_is_awake(BodyHandle body) const {
    return m_world->bodies.awake_index[live_slot(*m_world, body, "internal_is_awake")] >= 0;
}

const BodyDesc& Space::internal_desc(BodyHandle body) const {
    return m_world->bodies.desc[live_slot(*m_world, body, "internal_desc")];
}

}  // namespace spindle
