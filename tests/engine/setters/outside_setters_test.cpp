// Changes to bodies that others rest on or are jointed to, as an outside tester tried
// them: a static floor teleported or turned from under sleeping boxes, a joint's body
// destroyed with a target write pending.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include "space_calls.hpp"
#include "static_bodies.hpp"

using namespace spindle;
using namespace spindle::test;

namespace outside_setters_test {

namespace {

BodyDesc box_at(const Vec3& position) {
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.25, 0.25, 0.25));
    d.position = position;
    return d;
}

}  // namespace

// A box asleep on a static floor: the floor teleported away (or turned on edge) wakes the
// box, which falls; it does not hang asleep in the air.
TEST(OutsideSetters, StaticFloorMovedFromUnderASleepingBoxWakesIt) {
    for (int way = 0; way < 2; ++way) {
        SCOPED_TRACE(way == 0 ? "teleported" : "turned");
        Space space;
        const BodyHandle floor = add_static_box(space, Vec3(2, 0.5, 2), Vec3(0, -0.5, 0));
        const BodyHandle box = space.create_body(box_at(Vec3(0, 0.25, 0)));
        run(space, 120);
        ASSERT_FALSE(space.internal_is_awake(box));
        if (way == 0) {
            space.set_position(floor, Vec3(10, -0.5, 0));
        } else {
            space.set_orientation(floor, Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ())));
            space.set_position(floor, Vec3(5, -0.5, 0));
        }
        run(space, 30);  // half a second: 1.2 m of free fall
        EXPECT_LT(space.internal_position(box).y(), -0.5);
    }
}

// A mouse joint's body destroyed after a target write: the joint goes with it, its write
// is dropped and counted, nothing else changes.
TEST(OutsideSetters, MouseTargetPendingWhenItsBodyIsDestroyedIsDropped) {
    Space space;
    const BodyHandle ground = add_static_box(space, Vec3(2, 0.5, 2), Vec3(0, -0.5, 0));
    const BodyHandle box = space.create_body(box_at(Vec3(0, 0.25, 0)));
    const JointHandle mouse = space.create_joint(JointDesc::mouse_at(ground, box, Vec3(0, 0.25, 0), 5, 1, 1000));
    run(space, 2);
    space.set_mouse_target(mouse, Vec3(1, 1, 0));
    space.destroy_body(box);
    EXPECT_FALSE(space.contains(mouse));
    space.update();
    EXPECT_EQ(space.last_update().writes_rejected, 1);
    EXPECT_EQ(space.joint_count(), 0u);
    EXPECT_NE(error_of([&] { space.set_mouse_target(mouse, Vec3(1, 1, 0)); }).find(to_string(mouse)),
              std::string::npos);
}

}  // namespace outside_setters_test
