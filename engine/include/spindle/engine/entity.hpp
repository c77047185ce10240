// Entity: a body that can live outside a space (the seed, section 2: "If an Entity
// does not belong to a Space, the buffered properties simply access the internal
// values"). Outside a space its accessors read and write its own description
// directly; inside one they are the space's buffered accessors for its handle.
#pragma once

#include <spindle/engine/body.hpp>

namespace spindle {

class Space;

class Entity {
public:
    explicit Entity(BodyDesc desc = {});

    bool in_space() const noexcept { return m_space != nullptr; }
    BodyHandle handle() const noexcept { return m_handle; }
    Space* space() const noexcept { return m_space; }

    // Structure: the space's update thread, or any thread while it does not update.
    // add_to creates the body in the space from its current values (throws, and stays
    // outside, on bad values); remove_from_space copies the live state back first (a body
    // already destroyed through the space is just let go: the entity keeps its values).
    void add_to(Space& space);
    void remove_from_space();

    // Buffered in a space (any thread); direct outside one.
    MotionState motion_state() const;
    Vec3 position() const;
    Quat orientation() const;
    Vec3 linear_velocity() const;
    Vec3 angular_velocity() const;
    void set_position(const Vec3& position);
    void set_orientation(const Quat& orientation);
    void set_linear_velocity(const Vec3& velocity);
    void set_angular_velocity(const Vec3& velocity);
    void set_motion_state(const MotionState& state);

    // The description it was made from, with its values as of the last removal or direct write.
    const BodyDesc& desc() const noexcept { return m_desc; }

private:
    BodyDesc m_desc;
    Space* m_space = nullptr;
    BodyHandle m_handle;
};

}  // namespace spindle
