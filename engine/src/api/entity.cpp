// Entity: direct values outside a space, the space's buffered accessors inside one.
#include <spindle/engine/entity.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include "api/validation.hpp"

namespace spindle {

Entity::Entity(BodyDesc desc) : m_desc(std::move(desc)) {}

void Entity::add_to(Space& space) {
    if (m_space) throw Error("Entity::add_to: the body is already in a space (" + to_string(m_handle) + ")");
    m_handle = space.create_body(m_desc);
    m_space = &space;
}

void Entity::remove_from_space() {
    if (!m_space) return;
    if (!m_space->contains(m_handle)) {
        // Destroyed through the space already: nothing live to copy back, and throwing
        // here would leave the entity in a space that no longer has its body for good.
        m_space = nullptr;
        m_handle = BodyHandle{};
        return;
    }
    const MotionState s = m_space->internal_motion_state(m_handle);
    m_desc.position = s.position;
    m_desc.orientation = s.orientation;
    m_desc.linear_velocity = s.linear_velocity;
    m_desc.angular_velocity = s.angular_velocity;
    m_space->destroy_body(m_handle);
    m_space = nullptr;
    m_handle = BodyHandle{};
}

MotionState Entity::motion_state() const {
    if (m_space) return m_space->motion_state(m_handle);
    return MotionState{m_desc.position, m_desc.orientation, m_desc.linear_velocity, m_desc.angular_velocity,
                       m_desc.position};
}

Vec3 Entity::position() const { return motion_state().position; }
Quat Entity::orientation() const { return motion_state().orientation; }
Vec3 Entity::linear_velocity() const { return motion_state().linear_velocity; }
Vec3 Entity::angular_velocity() const { return motion_state().angular_velocity; }

void Entity::set_position(const Vec3& position) {
    if (m_space) return m_space->set_position(m_handle, position);
    check_finite(position, "Entity::set_position", "position");
    m_desc.position = position;
}

void Entity::set_orientation(const Quat& orientation) {
    if (m_space) return m_space->set_orientation(m_handle, orientation);
    check_orientation(orientation, "Entity::set_orientation", "orientation");
    m_desc.orientation = orientation.normalized();
}

void Entity::set_linear_velocity(const Vec3& velocity) {
    if (m_space) return m_space->set_linear_velocity(m_handle, velocity);
    check_finite(velocity, "Entity::set_linear_velocity", "linear_velocity");
    m_desc.linear_velocity = velocity;
}

void Entity::set_angular_velocity(const Vec3& velocity) {
    if (m_space) return m_space->set_angular_velocity(m_handle, velocity);
    check_finite(velocity, "Entity::set_angular_velocity", "angular_velocity");
    m_desc.angular_velocity = velocity;
}

void Entity::set_motion_state(const MotionState& state) {
    if (m_space) return m_space->set_motion_state(m_handle, state);
    validate(state, "Entity::set_motion_state");  // all or nothing
    set_position(state.position);
    set_orientation(state.orientation);
    set_linear_velocity(state.linear_velocity);
    set_angular_velocity(state.angular_velocity);
}

}  // namespace spindle
