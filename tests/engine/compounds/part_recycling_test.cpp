// A compound against a triangle mesh recycles part by part (collide_compound.cpp), as Box3D
// recycles each shape's contact: a part whose own points have moved less than the recycle
// distance keeps its manifolds, moved with it, while the body's other parts are collided.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "grid_mesh.hpp"

namespace spindle {
namespace part_recycling {
namespace {

// A box part lying on a flat mesh and, 3.5 m along x, a box part lying there too: one body
// resting on both on a frictionless mesh, turning about the vertical through the first
// part's centre at 0.9 rad/s (its centre of mass moving to match). The second part slides
// round 3.5 m out, 5.25 cm a step; the first turns about its centre, which drifts a few
// centimetres in 20 steps as the body turns about its centre of mass.
BodyHandle start_turning(Space& space) {
    BodyDesc ground;
    ground.type = MotionType::Static;
    ground.shape = test::flat_grid_mesh(20, 1);
    ground.friction = 0;
    space.create_body(ground);
    const Shape box = Shape::box(Vec3(0.25, 0.25, 0.25));
    std::vector<CompoundPart> parts{{box}, {box}};
    parts[1].position = Vec3(3.5, 0, 0);
    BodyDesc desc;
    desc.shape = Shape::compound(parts);
    desc.friction = 0;
    desc.position = Vec3(0.4, 0.25, 0.3);  // both parts on the mesh
    const BodyHandle body = space.create_body(desc);
    MotionState state = space.internal_motion_state(body);
    const Vec3 w(0, 0.9, 0);
    state.angular_velocity = w;
    state.linear_velocity = w.cross(state.center_of_mass - desc.position);
    space.set_internal_motion_state(body, state);
    return body;
}

// The contact is collided again every step (its far part moves past the recycle distance
// each step), but the near part's own points move a few millimetres a step: it keeps its
// manifold, moved with it, in most steps (16 of 20; none without per-part recycling, when
// both parts collide every step). The body rests on the mesh, both parts' pushes holding it
// there, and keeps its turn.
TEST(PartRecycling, APartTurningInPlaceKeepsItsManifoldWhileTheFarPartIsCollided) {
    SpaceSettings settings;
    settings.sleep.enabled = false;  // it turns on without stopping
    Space space(settings);
    const BodyHandle body = start_turning(space);
    constexpr int kSteps = 20;
    for (int i = 0; i < kSteps; ++i) space.update();
    const WorkCounters& c = space.counters();
    EXPECT_EQ(c.contacts_updated, std::uint64_t{kSteps});
    EXPECT_LE(c.manifolds_reused, 1u);  // the contact as a whole is not recycled
    const std::uint64_t met = c.mesh_parts_collided + c.mesh_parts_recycled;
    EXPECT_EQ(met, 2u * (c.contacts_updated - c.manifolds_reused));
    EXPECT_GE(c.mesh_parts_recycled, 12u);  // the near part, in most steps
    EXPECT_GE(c.mesh_parts_collided, 20u);  // the far part, every step
    EXPECT_NEAR(space.internal_position(body).y(), 0.25, 5e-3);
    EXPECT_NEAR(space.internal_linear_velocity(body).y(), 0, 1e-2);
    EXPECT_NEAR(space.internal_angular_velocity(body).y(), 0.9, 1e-3);
}

}  // namespace
}  // namespace part_recycling
}  // namespace spindle
