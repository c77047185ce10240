// Contact points on demand (EventSettings::publish_contact_points, Space::read_contact_points):
// a resting box shows its four corners on the ground with the ground's normal and the
// weight they carry, a ball its one point; nothing and no work while off; sensors left
// out; the cap counts what it leaves out; bad settings are refused.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <vector>

#include "events_common.hpp"

using namespace spindle;
using namespace spindle::test;

namespace contact_points_test {

namespace {

SpaceSettings with_points(bool on) {
    SpaceSettings s;
    s.sleep.enabled = false;
    s.events.publish_contact_points = on;
    return s;
}

// A 1 x 0.4 x 0.6 m box of 10 kg resting on the ground (top at y = 0).
BodyHandle add_box(Space& space) {
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.5, 0.2, 0.3));
    d.position = Vec3(1, 0.2, 2);
    d.mass = 10;
    return space.create_body(d);
}

}  // namespace

TEST(ContactPoints, RestingBoxShowsItsFourCornersWithTheNormalAndTheWeight) {
    Space space(with_points(true));
    const BodyHandle ground = add_ground(space);
    const BodyHandle box = add_box(space);
    run(space, 60);
    std::vector<ContactPointInfo> points;
    EXPECT_EQ(space.read_contact_points(points), space.counters().steps);
    ASSERT_EQ(points.size(), 4u);
    Real impulse = 0;
    for (const ContactPointInfo& p : points) {
        EXPECT_EQ(p.body_a, ground);  // the lower slot
        EXPECT_EQ(p.body_b, box);
        EXPECT_NEAR(p.normal.y(), 1.0, 1e-9);
        EXPECT_NEAR(p.point.y(), 0.0, 0.01);  // on the ground's top, within the overlap
        EXPECT_NEAR(std::abs(p.point.x() - 1), 0.5, 0.01);
        EXPECT_NEAR(std::abs(p.point.z() - 2), 0.3, 0.01);
        EXPECT_LE(p.separation, 0.01);
        impulse += p.normal_impulse;
    }
    // The four carry the box's weight: one substep's share of a step's m g dt.
    const TimeStepSettings& ts = space.settings().time_step;
    const Real substep = ts.duration / space.settings().solver.substeps;
    EXPECT_NEAR(impulse, 10 * 9.81 * substep, 0.05 * 10 * 9.81 * substep);
}

TEST(ContactPoints, OffPublishesNothingAndDoesNoWork_TurnedOffClearsThem) {
    Space space(with_points(false));
    add_ground(space);
    add_box(space);
    space.create_body(ball(0, false, -3));
    run(space, 30);
    std::vector<ContactPointInfo> points(3);
    EXPECT_EQ(space.read_contact_points(points), 0u);
    EXPECT_TRUE(points.empty());
    EXPECT_EQ(space.counters().contact_points_published, 0u);

    EventSettings on = space.settings().events;
    on.publish_contact_points = true;
    space.set_events(on);
    space.update();
    EXPECT_EQ(space.read_contact_points(points), space.counters().steps);
    EXPECT_EQ(points.size(), 5u);  // the box's four corners and the ball's one point
    EXPECT_EQ(space.counters().contact_points_published, 5u);

    on.publish_contact_points = false;
    space.set_events(on);
    space.update();
    EXPECT_EQ(space.read_contact_points(points), 0u);
    EXPECT_TRUE(points.empty());
    run(space, 5);
    EXPECT_EQ(space.counters().contact_points_published, 5u);
}

TEST(ContactPoints, SensorsAreLeftOutAndTheCapCountsTheRest) {
    SpaceSettings settings = with_points(true);
    settings.events.max_contact_points = 3;
    Space space(settings);
    add_ground(space);
    add_box(space);
    BodyDesc sensor = ball(-0.5, false, -3);  // half sunk into the ground: overlapping
    sensor.sensor = true;
    space.create_body(sensor);
    run(space, 10);
    std::vector<ContactPointInfo> points;
    std::size_t left_out = 0;
    space.read_contact_points(points, &left_out);
    EXPECT_EQ(points.size(), 3u);
    EXPECT_EQ(left_out, 1u);  // the box's fourth corner; the sensor's overlap is no point
}

TEST(ContactPoints, BadSettingsAreRefusedNamingTheField) {
    Space space(with_points(false));
    EventSettings bad;
    bad.max_contact_points = 0;
    EXPECT_NE(error_of([&] { space.set_events(bad); }).find("max_contact_points"), std::string::npos);
    EXPECT_EQ(space.settings().events.max_contact_points, EventSettings{}.max_contact_points);
}

}  // namespace contact_points_test
