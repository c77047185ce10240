// A body moving fast along a mesh, not into it, is swept (it moves far for its size) but
// cannot pass through the triangles under it: none of its points comes nearer their plane
// than half its thinnest half-size within a step. The sweep must not stop it at the first
// touch of such a triangle, short of where the solver put it: on a flat mesh it keeps the
// pace it keeps on a plane of the same height.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>

#include "grid_mesh.hpp"

using namespace spindle;

namespace fast_over_mesh_test {

namespace {

constexpr int kSteps = 60;

// How far along x `shape`, resting on `floor` at height `rest` and launched along x at
// `speed` and coming down at 1 m/s (rolling about z when `roll`), goes in kSteps steps.
Real distance_over(const Shape& floor, const Shape& shape, Real rest, Real speed, bool roll) {
    Space space;
    BodyDesc ground;
    ground.type = MotionType::Static;
    ground.shape = floor;
    space.create_body(ground);
    BodyDesc body;
    body.shape = shape;
    body.position = Vec3(-30, rest, 0);
    body.linear_velocity = Vec3(speed, -1, 0);
    if (roll) body.angular_velocity = Vec3(0, 0, -speed / rest);
    body.friction = roll ? 0.6 : 0;
    const BodyHandle handle = space.create_body(body);
    for (int i = 0; i < kSteps; ++i) space.update();
    return space.internal_motion_state(handle).position.x() + 30;
}

}  // namespace

// A ball and a box sliding at 16 and 20 m/s without friction settle onto the floor from
// 5 cm up: their sweeps start above it and touch it within the step. Not stopped there,
// they keep their speed along x and go as far as they would with no floor.
TEST(FastOverMesh, BodiesSettlingWhileSlidingFastAreNotStoppedShort) {
    const Shape mesh = test::flat_grid_mesh(100, 1.0);
    const Shape plane = Shape::plane(Vec3::UnitY(), 0);
    const Shape ball = Shape::sphere(0.5);
    const Shape box = Shape::box(Vec3(0.5, 0.5, 0.5));
    for (const Shape* floor : {&plane, &mesh}) {
        const char* name = floor == &plane ? "plane" : "mesh";
        EXPECT_NEAR(distance_over(*floor, ball, 0.55, 16, false), 16.0, 0.005) << "ball on the " << name;
        EXPECT_NEAR(distance_over(*floor, box, 0.55, 20, false), 20.0, 0.005) << "box on the " << name;
    }
}

// A 4 m bar spinning at 30 rad/s about z, its centre still 1.5 m over the floor: its
// centre neither comes nearer nor moves, but its end swings 1 m a step, down through the
// floor's height. Its turn about its centre counts, so it is swept and its end stops at
// the floor (the centre alone, as Box3D measures it, would let the end through).
TEST(FastOverMesh, ABarSpinningAboveTheFloorStopsItsEndAtTheFloor) {
    const Shape mesh = test::flat_grid_mesh(100, 1.0);
    const Shape plane = Shape::plane(Vec3::UnitY(), 0);
    for (const Shape* floor : {&plane, &mesh}) {
        Space space;
        space.set_gravity(Vec3::Zero());
        BodyDesc ground;
        ground.type = MotionType::Static;
        ground.shape = *floor;
        space.create_body(ground);
        BodyDesc bar;
        bar.shape = Shape::box(Vec3(2, 0.05, 0.05));
        bar.position = Vec3(0, 1.5, 0);
        bar.angular_velocity = Vec3(0, 0, 30);
        const BodyHandle handle = space.create_body(bar);
        Real lowest = 1e9;
        for (int i = 0; i < 20; ++i) {
            space.update();
            const MotionState s = space.internal_motion_state(handle);
            for (Real end : {-2.0, 2.0}) lowest = std::min(lowest, (s.position + s.orientation * Vec3(end, 0, 0)).y());
        }
        EXPECT_GT(lowest, -0.1) << "on the " << (floor == &plane ? "plane" : "mesh");
    }
}

}  // namespace fast_over_mesh_test
