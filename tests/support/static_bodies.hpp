// Static bodies for tests: the ground planes, floors, walls and ramps the suites stand
// their bodies on.
#pragma once

#include <spindle/engine/space.hpp>

namespace spindle::test {

// The ground: a static plane through the origin facing +y, the rest BodyDesc's defaults.
BodyDesc ground_plane();
BodyHandle add_ground_plane(Space& space);

// A static box's description, the rest BodyDesc's defaults: for a floor that also sets
// its layer, its events or its friction before it is made.
BodyDesc static_box(const Vec3& half_extents, const Vec3& position, const Quat& orientation = Quat::Identity());

// A static box made in the space.
BodyHandle add_static_box(Space& space, const Vec3& half_extents, const Vec3& position,
                          const Quat& orientation = Quat::Identity(), Real friction = BodyDesc{}.friction);

}  // namespace spindle::test
