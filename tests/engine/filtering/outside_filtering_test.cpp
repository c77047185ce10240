// Collision filtering as an outside tester tried it: a layer turned off against itself,
// the largest group, a filter change that must not undo a joint's own exclusion, and
// sensors behind the layer table.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <vector>

#include "space_calls.hpp"
#include "static_bodies.hpp"

using namespace spindle;
using namespace spindle::test;

namespace outside_filtering_test {

namespace {

// Two boxes pressed into each other (0.2 m of overlap), weightless: whether they push
// apart says whether their pair collides.
struct Overlapping {
    Space space{weightless()};
    BodyHandle a, b;
    Overlapping(std::uint32_t layer_a, std::uint32_t group_a, std::uint32_t layer_b, std::uint32_t group_b) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        d.allow_sleep = false;
        d.contact_events = true;
        d.position = Vec3(-0.4, 0, 0);
        d.layer = layer_a;
        d.group = group_a;
        a = space.create_body(d);
        d.position = Vec3(0.4, 0, 0);
        d.layer = layer_b;
        d.group = group_b;
        b = space.create_body(d);
    }
    Real gap() const { return space.internal_position(b).x() - space.internal_position(a).x(); }
    std::size_t events() {
        std::vector<ContactEvent> out;
        return space.read_contact_events(out);
    }
};

// Pushed apart to (nearly) a box's width: 0.8 m apart at first, 1 m when separated.
constexpr Real kParted = 0.97;

}  // namespace

TEST(OutsideFiltering, ALayerTurnedOffAgainstItselfLetsItsBodiesPassAndBackOnPartsThem) {
    Overlapping s(5, 0, 5, 0);
    s.space.set_layers_collide(5, 5, false);
    EXPECT_FALSE(s.space.layers_collide(5, 5));
    EXPECT_TRUE(s.space.layers_collide(5, 4));
    run(s.space, 30);
    EXPECT_NEAR(s.gap(), 0.8, 1e-9);
    EXPECT_EQ(s.events(), 0u);
    s.space.set_layers_collide(5, 5, true);
    run(s.space, 60);
    EXPECT_GT(s.gap(), kParted);
    EXPECT_GE(s.events(), 1u);
}

TEST(OutsideFiltering, TheLargestGroupSharedNeverCollidesAndAgainstNoGroupDoes) {
    Overlapping shared(0, ~0u, 0, ~0u);
    run(shared.space, 30);
    EXPECT_NEAR(shared.gap(), 0.8, 1e-9);
    Overlapping one(0, ~0u, 0, 0);
    run(one.space, 60);
    EXPECT_GT(one.gap(), kParted);
    Overlapping differ(0, ~0u, 0, ~0u - 1);
    run(differ.space, 60);
    EXPECT_GT(differ.gap(), kParted);
}

// A joint without collide_connected excludes its pair; the layer table allowing the pair
// again (which finds the filtered overlaps anew) must not bring it back, and the
// joint's destruction must.
TEST(OutsideFiltering, AllowingAJointedPairsLayersKeepsTheJointsExclusion) {
    Overlapping s(1, 0, 2, 0);
    s.space.set_layers_collide(1, 2, false);
    const JointHandle j = s.space.create_joint(JointDesc::ball_socket_at(s.a, s.b, Vec3(0, 0, 0)));
    run(s.space, 5);
    s.space.set_layers_collide(1, 2, true);
    s.space.set_collision_filter(s.a, 1, 0);  // and the body's own filter written again
    run(s.space, 30);
    EXPECT_NEAR(s.gap(), 0.8, 1e-3) << "the jointed pair collided";
    EXPECT_EQ(s.events(), 0u);
    s.space.destroy_joint(j);
    run(s.space, 60);
    EXPECT_GT(s.gap(), kParted);
}

// A sensor on a layer the table keeps from the body's: no overlap events; allowed
// again: the overlap begins; filtered off again: it ends.
TEST(OutsideFiltering, SensorsFollowTheLayerTable) {
    Space space(weightless());
    BodyDesc zone = static_box(Vec3(1, 1, 1), Vec3::Zero());
    zone.sensor = true;
    zone.layer = 3;
    space.create_body(zone);
    BodyDesc d;
    d.shape = Shape::sphere(0.3);
    d.layer = 4;
    d.allow_sleep = false;
    space.create_body(d);
    space.set_layers_collide(3, 4, false);
    run(space, 5);
    std::vector<ContactEvent> events;
    EXPECT_EQ(space.read_contact_events(events), 0u);
    space.set_layers_collide(3, 4, true);
    run(space, 5);
    events.clear();
    ASSERT_EQ(space.read_contact_events(events), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::Begin);
    EXPECT_TRUE(events[0].sensor);
    space.set_layers_collide(4, 3, false);
    run(space, 5);
    events.clear();
    ASSERT_EQ(space.read_contact_events(events), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::End);
}

}  // namespace outside_filtering_test
