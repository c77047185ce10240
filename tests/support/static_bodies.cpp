// Static bodies for tests.
#include "static_bodies.hpp"

namespace spindle::test {

BodyDesc ground_plane() {
    BodyDesc d;
    d.type = MotionType::Static;
    d.shape = Shape::plane(Vec3::UnitY(), 0);
    return d;
}

BodyHandle add_ground_plane(Space& space) { return space.create_body(ground_plane()); }

BodyDesc static_box(const Vec3& half_extents, const Vec3& position, const Quat& orientation) {
    BodyDesc d;
    d.type = MotionType::Static;
    d.shape = Shape::box(half_extents);
    d.position = position;
    d.orientation = orientation;
    return d;
}

BodyHandle add_static_box(Space& space, const Vec3& half_extents, const Vec3& position, const Quat& orientation,
                          Real friction) {
    BodyDesc d = static_box(half_extents, position, orientation);
    d.friction = friction;
    return space.create_body(d);
}

}  // namespace spindle::test
