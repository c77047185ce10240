// What wakes a sleeping island besides a touch from an awake body: destroying or moving
// what it rests on (static and kinematic bodies included), and what keeps one awake: a
// moving kinematic body under it.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <vector>

using namespace spindle;

namespace {

constexpr int kMaxSettleSteps = 600;

BodyDesc static_box(const Vec3& position, const Vec3& half_extents) {
    BodyDesc d;
    d.type = MotionType::Static;
    d.shape = Shape::box(half_extents);
    d.position = position;
    return d;
}

BodyDesc dynamic_box(const Vec3& position) {
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
    d.position = position;
    return d;
}

bool any_awake(const Space& space, const std::vector<BodyHandle>& bodies) {
    for (BodyHandle b : bodies) {
        if (space.internal_is_awake(b)) return true;
    }
    return false;
}

// Steps until every body sleeps; the test fails if they never do.
void settle(Space& space, const std::vector<BodyHandle>& bodies) {
    for (int i = 0; i < kMaxSettleSteps && any_awake(space, bodies); ++i) space.update();
    ASSERT_FALSE(any_awake(space, bodies)) << "the scene did not fall asleep";
}

// A stack of three boxes resting on a floor.
struct Stack {
    Space space;
    BodyHandle floor;
    std::vector<BodyHandle> boxes;
};

void build_stack(Stack& s, const BodyDesc& floor) {
    s.floor = s.space.create_body(floor);
    for (int i = 0; i < 3; ++i) s.boxes.push_back(s.space.create_body(dynamic_box(Vec3(0, 0.5 + i, 0))));
}

// A second of free fall takes a body 4.9 m down; each box started at 0.5 + its level.
void expect_fell_a_second(const Stack& s) {
    for (std::size_t i = 0; i < s.boxes.size(); ++i) {
        EXPECT_LT(s.space.position(s.boxes[i]).y(), 0.5 + static_cast<Real>(i) - 4.5) << "box " << i;
    }
}

}  // namespace

// On main the stack stayed asleep at y = 2.5 (top box) two seconds after its floor went.
TEST(Waking, DestroyingTheFloorDropsTheStackWithinASecond) {
    Stack s;
    BodyDesc plane;
    plane.type = MotionType::Static;
    plane.shape = Shape::plane(Vec3::UnitY(), 0);
    build_stack(s, plane);
    settle(s.space, s.boxes);
    s.space.destroy_body(s.floor);
    for (int i = 0; i < 60; ++i) s.space.update();
    expect_fell_a_second(s);
}

// On main the stack stayed asleep at y = 2.5 (top box) while its floor was 49 m lower.
TEST(Waking, MovingTheFloorBySetPositionDropsTheStack) {
    Stack s;
    build_stack(s, static_box(Vec3(0, -0.5, 0), Vec3(5, 0.5, 5)));
    settle(s.space, s.boxes);
    s.space.set_position(s.floor, Vec3(0, -49.5, 0));
    for (int i = 0; i < 60; ++i) s.space.update();
    expect_fell_a_second(s);
}

// On main the box stayed asleep on nothing at y = 2.5, a metre above the ground.
TEST(Waking, DestroyingAStaticBoxUnderASleepingBodyDropsIt) {
    Space space;
    BodyDesc ground;
    ground.type = MotionType::Static;
    ground.shape = Shape::plane(Vec3::UnitY(), 0);
    space.create_body(ground);
    const BodyHandle pedestal = space.create_body(static_box(Vec3(0, 1, 0), Vec3(1, 1, 1)));
    const BodyHandle box = space.create_body(dynamic_box(Vec3(0, 2.5, 0)));
    settle(space, {box});
    space.destroy_body(pedestal);
    for (int i = 0; i < 120; ++i) space.update();
    EXPECT_NEAR(space.position(box).y(), 0.5, 0.05);  // landed on the ground
}

// A static body teleported into a sleeping one makes a new contact that wakes it. On main
// the box slept on, overlapped by the wall, at x = 0.
TEST(Waking, MovingAStaticBodyIntoASleepingBodyWakesIt) {
    Space space;
    BodyDesc ground;
    ground.type = MotionType::Static;
    ground.shape = Shape::plane(Vec3::UnitY(), 0);
    space.create_body(ground);
    const BodyHandle wall = space.create_body(static_box(Vec3(10, 1, 0), Vec3(0.5, 1, 2)));
    const BodyHandle box = space.create_body(dynamic_box(Vec3(0, 0.5, 0)));
    settle(space, {box});
    space.set_position(wall, Vec3(0.9, 1, 0));  // 0.1 m into the box
    space.update();
    space.update();
    EXPECT_TRUE(space.internal_is_awake(box));
}

// On main the top box stayed asleep at y = 2.5 with the pedestal moved 0.5 m lower.
TEST(Waking, SetInternalMotionStateOfATouchingStaticBodyWakesTheIsland) {
    Space space;
    const BodyHandle pedestal = space.create_body(static_box(Vec3(0, 1, 0), Vec3(1, 1, 1)));
    std::vector<BodyHandle> boxes;
    for (int i = 0; i < 2; ++i) boxes.push_back(space.create_body(dynamic_box(Vec3(0, 2.5 + i, 0))));
    settle(space, boxes);
    MotionState lowered = space.internal_motion_state(pedestal);
    lowered.position.y() -= 0.5;
    space.set_internal_motion_state(pedestal, lowered);
    for (BodyHandle b : boxes) EXPECT_TRUE(space.internal_is_awake(b));
    for (int i = 0; i < 120; ++i) space.update();
    EXPECT_NEAR(space.position(boxes[0]).y(), 2.0, 0.05);  // landed on the lowered pedestal
    EXPECT_NEAR(space.position(boxes[1]).y(), 3.0, 0.05);
}

// A slow kinematic platform (below the sleep threshold) carrying a box. On main the
// platform fell asleep with its velocity zeroed after 0.5 s: it stopped at x = 0.015
// instead of 0.15 after 5 s, and the box slept with it.
TEST(Waking, ASlowKinematicPlatformKeepsMovingAndKeepsItsRiderAwake) {
    Space space;
    BodyDesc platform;
    platform.type = MotionType::Kinematic;
    platform.shape = Shape::box(Vec3(3, 0.25, 3));
    platform.linear_velocity = Vec3(0.03, 0, 0);
    const BodyHandle p = space.create_body(platform);
    const BodyHandle rider = space.create_body(dynamic_box(Vec3(0, 0.75, 0)));
    bool platform_slept = false, rider_slept = false;
    for (int i = 0; i < 300; ++i) {
        space.update();
        platform_slept |= !space.internal_is_awake(p);
        // The first steps the box lands: it may not ride yet.
        if (i > 30) rider_slept |= !space.internal_is_awake(rider);
    }
    EXPECT_FALSE(platform_slept);
    EXPECT_FALSE(rider_slept);
    EXPECT_DOUBLE_EQ(space.internal_linear_velocity(p).x(), 0.03);
    EXPECT_NEAR(space.position(p).x(), 0.15, 1e-9);
    EXPECT_NEAR(space.position(rider).x(), 0.15, 0.01);  // carried by friction
}

// A kinematic platform at rest may sleep with what rests on it; a velocity written to
// it wakes it and its rider.
TEST(Waking, AVelocityWrittenToASleepingPlatformWakesItsRider) {
    Space space;
    BodyDesc platform;
    platform.type = MotionType::Kinematic;
    platform.shape = Shape::box(Vec3(3, 0.25, 3));
    const BodyHandle p = space.create_body(platform);
    const BodyHandle rider = space.create_body(dynamic_box(Vec3(0, 0.75, 0)));
    settle(space, {p, rider});
    space.set_linear_velocity(p, Vec3(0.03, 0, 0));
    space.update();
    EXPECT_TRUE(space.internal_is_awake(p));
    EXPECT_TRUE(space.internal_is_awake(rider));
}
