// Sensors: a body flagged sensor reports overlaps (Begin and End with the other body,
// whatever either asked) and exerts no force, static, kinematic or dynamic; two sensors
// do not detect each other.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include "events_common.hpp"

using namespace spindle;
using namespace spindle::test;

namespace sensor_test {

namespace {

BodyDesc sensor_box(MotionType type, const Vec3& position, const Vec3& half = Vec3(2, 0.5, 2)) {
    BodyDesc d;
    d.type = type;
    d.shape = Shape::box(half);
    d.position = position;
    d.sensor = true;
    return d;
}

}  // namespace

TEST(Sensor, StaticSensor_CountsAFallingBall_AndDoesNotSlowIt) {
    // The same ball falls through a space with a sensor box in its way and one without.
    Space with, without;
    const BodyHandle sensor = with.create_body(sensor_box(MotionType::Static, Vec3(0, 5, 0)));
    const BodyHandle ball = with.create_body(spindle::test::ball(7, false));  // asks for nothing
    const BodyHandle control = without.create_body(spindle::test::ball(7, false));
    for (int i = 0; i < 90; ++i) {
        with.update();
        without.update();
        ASSERT_EQ(with.internal_motion_state(ball).linear_velocity,
                  without.internal_motion_state(control).linear_velocity)
            << "step " << i;
        ASSERT_EQ(with.internal_position(ball), without.internal_position(control)) << "step " << i;
    }
    EXPECT_LT(with.internal_position(ball).y(), 0);  // fell through the whole box
    const std::vector<ContactEvent> events = read_all(with);
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].kind, ContactEventKind::Begin);
    EXPECT_EQ(events[1].kind, ContactEventKind::End);
    for (const ContactEvent& e : events) {
        EXPECT_TRUE(e.sensor);
        EXPECT_EQ(e.body_a, sensor);
        EXPECT_EQ(e.body_b, ball);
    }
    EXPECT_LT(events[0].step, events[1].step);
    EXPECT_EQ(with.counters().contact_points_solved, 0u);  // its contact never reached the solver
}

TEST(Sensor, StaticSensor_CountsEveryBallThatEnters) {
    Space space;
    space.create_body(sensor_box(MotionType::Static, Vec3(0, 1, 0), Vec3(4, 1, 4)));
    add_ground(space);
    for (int i = 0; i < 5; ++i) space.create_body(spindle::test::ball(4 + i, false, 1.5 * i - 3));
    run(space, 180);  // they all fall into the sensor and come to rest on the ground inside it
    const std::vector<ContactEvent> events = read_all(space);
    EXPECT_EQ(count(events, ContactEventKind::Begin), 5u);
    EXPECT_EQ(count(events, ContactEventKind::End), 0u);
    for (const ContactEvent& e : events) EXPECT_TRUE(e.sensor);  // the ground pairs asked nothing
}

TEST(Sensor, DynamicSensor_FallsThroughTheFloor) {
    Space space;
    const BodyHandle ground = add_ground(space);
    BodyDesc d = spindle::test::ball(0.5, false);
    d.sensor = true;
    const BodyHandle sensor = space.create_body(d);
    run(space, 120);
    EXPECT_LT(space.internal_position(sensor).y(), -5);
    const std::vector<ContactEvent> events = read_all(space);
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].kind, ContactEventKind::Begin);
    EXPECT_EQ(events[1].kind, ContactEventKind::End);
    EXPECT_EQ(events[0].body_a, ground);
    EXPECT_EQ(events[0].body_b, sensor);
}

TEST(Sensor, KinematicSensor_DetectsWithoutPushing) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    Space space(settings);
    BodyDesc target = spindle::test::ball(0, false);
    target.position = Vec3(0, 0, 0);
    target.allow_sleep = false;
    const BodyHandle resting = space.create_body(target);
    BodyDesc sweep = sensor_box(MotionType::Kinematic, Vec3(-4, 0, 0), Vec3(0.5, 0.5, 0.5));
    sweep.linear_velocity = Vec3(4, 0, 0);  // passes through the ball in 2 s
    space.create_body(sweep);
    run(space, 150);
    EXPECT_EQ(space.internal_position(resting), Vec3::Zero());
    EXPECT_EQ(space.internal_linear_velocity(resting), Vec3::Zero());
    const std::vector<ContactEvent> events = read_all(space);
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].kind, ContactEventKind::Begin);
    EXPECT_EQ(events[1].kind, ContactEventKind::End);
    EXPECT_TRUE(events[0].sensor);
}

TEST(Sensor, SensorOnABallAtRest_DoesNotKeepItsIslandAwake) {
    Space space;
    add_ground(space);
    space.create_body(sensor_box(MotionType::Static, Vec3(0, 0.5, 0), Vec3(2, 1, 2)));
    const BodyHandle ball = space.create_body(spindle::test::ball(0.2, false));
    run(space, 240);
    EXPECT_FALSE(space.internal_is_awake(ball));  // sleeps inside the sensor, still overlapping
    const std::vector<ContactEvent> events = read_all(space);
    EXPECT_EQ(count(events, ContactEventKind::Begin), 1u);
    EXPECT_EQ(count(events, ContactEventKind::End), 0u);
}

TEST(Sensor, TwoSensors_DoNotDetectEachOther) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    Space space(settings);
    BodyDesc d = spindle::test::ball(0, true);
    d.sensor = true;
    space.create_body(d);
    d.position.x() += 0.5;  // overlapping
    space.create_body(d);
    d.type = MotionType::Static;
    d.position.x() += 0.5;
    space.create_body(d);
    run(space, 30);
    EXPECT_EQ(read_all(space).size(), 0u);
    EXPECT_EQ(space.counters().contacts_updated, 0u);  // no contact at all
    EXPECT_EQ(space.counters().contact_event_checks, 0u);
}

TEST(Sensor, FastBall_IsNotStoppedByAStaticSensor) {
    // A fast ball is swept against static geometry; a static sensor is none: the ball
    // moves exactly as in a space without the sensor.
    Space with, without;
    with.create_body(sensor_box(MotionType::Static, Vec3(0, 5, 0), Vec3(2, 0.05, 2)));
    BodyDesc d = spindle::test::ball(7, false);
    d.fast = true;
    d.linear_velocity = Vec3(0, -60, 0);  // a metre a step
    const BodyHandle ball = with.create_body(d);
    const BodyHandle control = without.create_body(d);
    for (int i = 0; i < 20; ++i) {
        with.update();
        without.update();
        ASSERT_EQ(with.internal_position(ball), without.internal_position(control)) << "step " << i;
    }
    EXPECT_LT(with.internal_position(ball).y(), -5);
    EXPECT_EQ(with.counters().swept_tests, 0u);  // the sensor is no wall to sweep against
    EXPECT_EQ(count(read_all(with), ContactEventKind::Begin), 1u);
}

TEST(Sensor, MovingSensor_JoinsNoIsland_TheBallItOverlapsSleeps) {
    // A dynamic sensor that keeps moving (never rests) overlaps a resting ball the whole
    // time: linked in one island, the ball could not sleep.
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    Space space(settings);
    const BodyHandle resting = space.create_body(spindle::test::ball(0, false));
    BodyDesc d = sensor_box(MotionType::Dynamic, Vec3(0, 0.5, 0), Vec3(3, 3, 3));
    d.linear_velocity = Vec3(0.2, 0, 0);
    const BodyHandle sensor = space.create_body(d);
    run(space, 90);
    EXPECT_TRUE(space.internal_is_awake(sensor));
    EXPECT_FALSE(space.internal_is_awake(resting));
    const std::vector<ContactEvent> events = read_all(space);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::Begin);
}

}  // namespace sensor_test
