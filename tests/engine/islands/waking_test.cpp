// What wakes a sleeping island besides a touch from an awake body: destroying or moving
// what it rests on (static and kinematic bodies included), and what keeps one awake: a
// moving kinematic body under it.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <vector>

#include "static_bodies.hpp"

using namespace spindle;

namespace waking_test {

namespace {

constexpr int kMaxSettleSteps = 600;

// A kinematic platform, its top at y = 0.25.
BodyDesc platform(const Vec3& velocity) {
    BodyDesc d;
    d.type = MotionType::Kinematic;
    d.shape = Shape::box(Vec3(3, 0.25, 3));
    d.linear_velocity = velocity;
    return d;
}

BodyDesc dynamic_box(const Vec3& position) {
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
    d.position = position;
    return d;
}

}  // namespace

// A stack of unit boxes resting on a support (a floor, a pedestal or a platform), which
// the tests then take away, move or set moving.
class Waking : public ::testing::Test {
protected:
    Space space;
    BodyHandle support;
    std::vector<BodyHandle> boxes;  // bottom first

    // The support, then `count` boxes above each other, the lowest centred at height `bottom`.
    void build_stack(const BodyDesc& support_desc, Real bottom, int count) {
        support = space.create_body(support_desc);
        for (int i = 0; i < count; ++i) boxes.push_back(space.create_body(dynamic_box(Vec3(0, bottom + i, 0))));
    }

    bool any_awake() const {
        if (space.internal_is_awake(support)) return true;  // a kinematic support sleeps with its stack
        for (BodyHandle b : boxes) {
            if (space.internal_is_awake(b)) return true;
        }
        return false;
    }

    // Steps until the stack and its support sleep; the test fails if they never do.
    void settle() {
        for (int i = 0; i < kMaxSettleSteps && any_awake(); ++i) space.update();
        ASSERT_FALSE(any_awake()) << "the stack did not fall asleep";
    }

    // A second of free fall takes a body 4.9 m down; each box started at 0.5 + its level.
    void expect_fell_a_second() const {
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            EXPECT_LT(space.position(boxes[i]).y(), 0.5 + static_cast<Real>(i) - 4.5) << "box " << i;
        }
    }
};

// On main the stack stayed asleep at y = 2.5 (top box) two seconds after its floor went.
TEST_F(Waking, DestroyingTheFloorDropsTheStackWithinASecond) {
    build_stack(test::ground_plane(), 0.5, 3);
    settle();
    space.destroy_body(support);
    for (int i = 0; i < 60; ++i) space.update();
    expect_fell_a_second();
}

// On main the stack stayed asleep at y = 2.5 (top box) while its floor was 49 m lower.
TEST_F(Waking, MovingTheFloorBySetPositionDropsTheStack) {
    build_stack(test::static_box(Vec3(5, 0.5, 5), Vec3(0, -0.5, 0)), 0.5, 3);
    settle();
    space.set_position(support, Vec3(0, -49.5, 0));
    for (int i = 0; i < 60; ++i) space.update();
    expect_fell_a_second();
}

// On main the box stayed asleep on nothing at y = 2.5, a metre above the ground.
TEST_F(Waking, DestroyingAStaticBoxUnderASleepingBodyDropsIt) {
    space.create_body(test::ground_plane());
    build_stack(test::static_box(Vec3(1, 1, 1), Vec3(0, 1, 0)), 2.5, 1);
    settle();
    space.destroy_body(support);
    for (int i = 0; i < 120; ++i) space.update();
    EXPECT_NEAR(space.position(boxes[0]).y(), 0.5, 0.05);  // landed on the ground
}

// A static body teleported into a sleeping one makes a new contact that wakes it. On main
// the box slept on, overlapped by the wall, at x = 0.
TEST_F(Waking, MovingAStaticBodyIntoASleepingBodyWakesIt) {
    const BodyHandle wall = space.create_body(test::static_box(Vec3(0.5, 1, 2), Vec3(10, 1, 0)));
    build_stack(test::ground_plane(), 0.5, 1);
    settle();
    space.set_position(wall, Vec3(0.9, 1, 0));  // 0.1 m into the box
    space.update();
    space.update();
    EXPECT_TRUE(space.internal_is_awake(boxes[0]));
}

// On main the top box stayed asleep at y = 2.5 with the pedestal moved 0.5 m lower.
TEST_F(Waking, SetInternalMotionStateOfATouchingStaticBodyWakesTheIsland) {
    build_stack(test::static_box(Vec3(1, 1, 1), Vec3(0, 1, 0)), 2.5, 2);
    settle();
    MotionState lowered = space.internal_motion_state(support);
    lowered.position.y() -= 0.5;
    space.set_internal_motion_state(support, lowered);
    for (BodyHandle b : boxes) EXPECT_TRUE(space.internal_is_awake(b));
    for (int i = 0; i < 120; ++i) space.update();
    EXPECT_NEAR(space.position(boxes[0]).y(), 2.0, 0.05);  // landed on the lowered pedestal
    EXPECT_NEAR(space.position(boxes[1]).y(), 3.0, 0.05);
}

// A slow kinematic platform (below the sleep threshold) carrying a box. On main the
// platform fell asleep with its velocity zeroed after 0.5 s: it stopped at x = 0.015
// instead of 0.15 after 5 s, and the box slept with it.
TEST_F(Waking, ASlowKinematicPlatformKeepsMovingAndKeepsItsRiderAwake) {
    build_stack(platform(Vec3(0.03, 0, 0)), 0.75, 1);
    const BodyHandle rider = boxes[0];
    bool platform_slept = false, rider_slept = false;
    for (int i = 0; i < 300; ++i) {
        space.update();
        platform_slept |= !space.internal_is_awake(support);
        // The first steps the box lands: it may not ride yet.
        if (i > 30) rider_slept |= !space.internal_is_awake(rider);
    }
    EXPECT_FALSE(platform_slept);
    EXPECT_FALSE(rider_slept);
    EXPECT_DOUBLE_EQ(space.internal_linear_velocity(support).x(), 0.03);
    EXPECT_NEAR(space.position(support).x(), 0.15, 1e-9);
    EXPECT_NEAR(space.position(rider).x(), 0.15, 0.01);  // carried by friction
}

// A kinematic platform at rest may sleep with what rests on it; a velocity written to
// it wakes it and its rider.
TEST_F(Waking, AVelocityWrittenToASleepingPlatformWakesItsRider) {
    build_stack(platform(Vec3::Zero()), 0.75, 1);
    settle();
    space.set_linear_velocity(support, Vec3(0.03, 0, 0));
    space.update();
    EXPECT_TRUE(space.internal_is_awake(support));
    EXPECT_TRUE(space.internal_is_awake(boxes[0]));
}

}  // namespace waking_test
