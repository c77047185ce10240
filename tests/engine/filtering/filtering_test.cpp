// Collision filtering: the layer table and groups keep bodies apart, filtered pairs cost
// no narrowphase work, and a filter changed after creation (a body's, or the table)
// takes effect at the next step both ways.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <string>

#include "space_calls.hpp"
#include "static_bodies.hpp"

using namespace spindle;

namespace filtering_test {

namespace {

constexpr std::uint32_t kGroundLayer = 1;
constexpr std::uint32_t kGhostLayer = 2;  // ignores the ground in these tests

BodyHandle add_ground(Space& space) {
    BodyDesc g = test::static_box(Vec3(10, 0.5, 10), Vec3(0, -0.5, 0));
    g.layer = kGroundLayer;
    return space.create_body(g);
}

BodyDesc ball(const Vec3& p, std::uint32_t layer = 0, std::uint32_t group = 0) {
    BodyDesc d;
    d.shape = Shape::sphere(0.5);
    d.position = p;
    d.layer = layer;
    d.group = group;
    return d;
}

BodyDesc box(const Vec3& p, std::uint32_t group) {
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
    d.position = p;
    d.group = group;
    return d;
}

using test::error_of;
using test::run;
using test::weightless;

}  // namespace

TEST(Filtering, BallOnALayerThatIgnoresTheGround_FallsThrough) {
    Space space;
    add_ground(space);
    space.set_layers_collide(kGroundLayer, kGhostLayer, false);
    const BodyHandle ghost = space.create_body(ball(Vec3(0, 2, 0), kGhostLayer));
    run(space, 120);
    EXPECT_LT(space.internal_position(ghost).y(), -5.0);
}

TEST(Filtering, BallOnACollidingLayer_RestsOnTheGround) {
    Space space;
    add_ground(space);
    space.set_layers_collide(kGroundLayer, kGhostLayer, false);
    const BodyHandle solid = space.create_body(ball(Vec3(0, 2, 0), 3));
    run(space, 120);
    EXPECT_NEAR(space.internal_position(solid).y(), 0.5, 0.02);
}

TEST(Filtering, LayerTable_IsSymmetricAndAllCollideByDefault) {
    Space space;
    for (std::uint32_t a = 0; a < kLayerCount; ++a) {
        for (std::uint32_t b = 0; b < kLayerCount; ++b) ASSERT_TRUE(space.layers_collide(a, b));
    }
    space.set_layers_collide(4, 9, false);
    EXPECT_FALSE(space.layers_collide(4, 9));
    EXPECT_FALSE(space.layers_collide(9, 4));
    EXPECT_TRUE(space.layers_collide(4, 4));
    EXPECT_TRUE(space.layers_collide(9, 9));
    space.set_layers_collide(9, 4, true);
    EXPECT_TRUE(space.layers_collide(4, 9));
}

// A box slides through another at rest: the same group keeps them apart, different groups do not.
Real overtaking(std::uint32_t group_a, std::uint32_t group_b) {
    Space space(weightless());
    BodyDesc moving = box(Vec3(0, 0, 0), group_a);
    moving.linear_velocity = Vec3(3, 0, 0);
    const BodyHandle a = space.create_body(moving);
    const BodyHandle b = space.create_body(box(Vec3(3, 0, 0), group_b));
    run(space, 120);  // 2 s: alone, a would end at x = 6
    return space.internal_position(a).x() - space.internal_position(b).x();
}

TEST(Filtering, BoxesInOneGroup_PassThroughEachOther) { EXPECT_GT(overtaking(7, 7), 2.5); }

TEST(Filtering, BoxesInDifferentGroupsOrNone_Collide) {
    EXPECT_LT(overtaking(7, 8), -0.9);
    EXPECT_LT(overtaking(0, 0), -0.9);  // group 0 is no group
}

// Overlapping bodies at rest: every pair is reported once, at the first step. The filtered
// ones are counted and never reach the narrowphase; the one allowed pair does every step.
TEST(Filtering, FilteredPairs_AreCountedAndCostNoNarrowphaseWork) {
    SpaceSettings settings = weightless();
    settings.sleep.enabled = false;
    Space space(settings);
    space.set_layers_collide(4, 5, false);
    // A ragdoll-like row in group 3: three overlapping pairs (0-1, 1-2, 2-3).
    for (int k = 0; k < 4; ++k) space.create_body(ball(Vec3(0.8 * k, 0, 0), 0, 3));
    // Layers 4 and 5 ignore each other: one pair.
    space.create_body(ball(Vec3(20, 0, 0), 4));
    space.create_body(ball(Vec3(20.8, 0, 0), 5));
    // Allowed: two balls just touching, far from the rest.
    space.create_body(ball(Vec3(40, 0, 0)));
    space.create_body(ball(Vec3(41, 0, 0)));
    const int steps = 10;
    run(space, steps);
    EXPECT_EQ(space.counters().pairs_filtered, 4u);
    EXPECT_EQ(space.counters().contacts_updated, static_cast<std::uint64_t>(steps));  // the allowed pair only
}

TEST(Filtering, NothingFiltered_CountsNothing) {
    Space space;
    add_ground(space);
    space.create_body(ball(Vec3(0, 2, 0)));
    run(space, 60);
    EXPECT_EQ(space.counters().pairs_filtered, 0u);
    EXPECT_GT(space.counters().contacts_updated, 0u);
}

// The ball rests (and sleeps) on the ground, then moves to a layer that ignores it.
TEST(Filtering, LayerChangedAfterCreation_StartsPassingThroughAtTheNextStep) {
    Space space;
    add_ground(space);
    space.set_layers_collide(kGroundLayer, kGhostLayer, false);
    const BodyHandle b = space.create_body(ball(Vec3(0, 0.5, 0)));
    run(space, 90);
    ASSERT_FALSE(space.internal_is_awake(b));  // asleep: the change must wake it
    ASSERT_NEAR(space.internal_position(b).y(), 0.5, 0.02);

    space.set_collision_filter(b, kGhostLayer, 0);
    EXPECT_EQ(space.internal_desc(b).layer, 0u);  // buffered: nothing changes before the update
    space.update();
    EXPECT_EQ(space.internal_desc(b).layer, kGhostLayer);
    EXPECT_EQ(space.last_update().contacts, 0u);
    EXPECT_TRUE(space.internal_is_awake(b));
    run(space, 60);
    EXPECT_LT(space.internal_position(b).y(), -2.0);
}

// Two of three resting balls change layer in one update: both fall, the third stays.
TEST(Filtering, TwoFiltersChangedInOneUpdate_BothApplyAtTheNextStep) {
    Space space;
    add_ground(space);
    space.set_layers_collide(kGroundLayer, kGhostLayer, false);
    const BodyHandle kept = space.create_body(ball(Vec3(0, 0.5, 0)));
    const BodyHandle first = space.create_body(ball(Vec3(3, 0.5, 0)));
    const BodyHandle second = space.create_body(ball(Vec3(6, 0.5, 0)));
    run(space, 90);
    ASSERT_FALSE(space.internal_is_awake(second));

    space.set_collision_filter(second, kGhostLayer, 0);
    space.set_collision_filter(first, kGhostLayer, 0);
    run(space, 60);
    EXPECT_LT(space.internal_position(first).y(), -2.0);
    EXPECT_LT(space.internal_position(second).y(), -2.0);
    EXPECT_NEAR(space.internal_position(kept).y(), 0.5, 0.02);
}

// The ground, not the ball, changes layer: the sleeping ball it held is woken and falls.
TEST(Filtering, GroundLayerChangedAfterCreation_WakesWhatRestedOnIt) {
    Space space;
    const BodyHandle ground = add_ground(space);
    space.set_layers_collide(kGhostLayer, 0, false);
    const BodyHandle b = space.create_body(ball(Vec3(0, 0.5, 0)));
    run(space, 90);
    ASSERT_FALSE(space.internal_is_awake(b));

    space.set_collision_filter(ground, kGhostLayer, 0);
    space.update();
    EXPECT_TRUE(space.internal_is_awake(b));
    run(space, 60);
    EXPECT_LT(space.internal_position(b).y(), -2.0);
}

// Two boxes of one group overlap at rest and sleep; moving one out of the group makes the
// pair appear at the next step (though neither proxy moved) and pushes them apart.
TEST(Filtering, GroupChangedAfterCreation_StopsPassingThroughAtTheNextStep) {
    Space space(weightless());
    const BodyHandle a = space.create_body(box(Vec3(0, 0, 0), 5));
    const BodyHandle b = space.create_body(box(Vec3(0.6, 0, 0), 5));
    run(space, 60);
    ASSERT_FALSE(space.internal_is_awake(a));
    ASSERT_EQ(space.last_update().contacts, 0u);

    space.set_collision_filter(a, 0, 0);
    space.update();
    EXPECT_GT(space.last_update().contacts, 0u);
    EXPECT_TRUE(space.internal_is_awake(a));
    EXPECT_TRUE(space.internal_is_awake(b));
    run(space, 60);
    EXPECT_GT(space.internal_position(b).x() - space.internal_position(a).x(), 0.95);
}

TEST(Filtering, LayerTableChanged_ReappliesToExistingBodiesBothWays) {
    Space space;
    add_ground(space);
    const BodyHandle b = space.create_body(ball(Vec3(0, 0.5, 0), kGhostLayer));
    run(space, 90);
    ASSERT_FALSE(space.internal_is_awake(b));

    space.set_layers_collide(kGroundLayer, kGhostLayer, false);  // the resting ball falls
    space.update();
    EXPECT_EQ(space.last_update().contacts, 0u);
    run(space, 17);
    const Real sunk = space.internal_position(b).y();
    EXPECT_LT(sunk, 0.2);

    space.set_layers_collide(kGroundLayer, kGhostLayer, true);  // inside the ground: pushed out
    space.update();
    EXPECT_GT(space.last_update().contacts, 0u);
    run(space, 120);
    EXPECT_NEAR(space.internal_position(b).y(), 0.5, 0.05);
}

// Two sleeping boxes overlap on layers that ignore each other; allowing the pair wakes
// them and pushes them apart.
TEST(Filtering, LayerTableChanged_WakesSleepersWhosePairItAllows) {
    Space space(weightless());
    space.set_layers_collide(1, 2, false);
    BodyDesc d = box(Vec3(0, 0, 0), 0);
    d.layer = 1;
    const BodyHandle a = space.create_body(d);
    d.position = Vec3(0.6, 0, 0);
    d.layer = 2;
    const BodyHandle b = space.create_body(d);
    run(space, 60);
    ASSERT_FALSE(space.internal_is_awake(a));
    ASSERT_FALSE(space.internal_is_awake(b));

    space.set_layers_collide(2, 1, true);
    space.update();
    EXPECT_TRUE(space.internal_is_awake(a));
    EXPECT_TRUE(space.internal_is_awake(b));
    EXPECT_GT(space.last_update().contacts, 0u);
    run(space, 60);
    EXPECT_GT(space.internal_position(b).x() - space.internal_position(a).x(), 0.95);
}

TEST(Filtering, LastFilterWriteWins) {
    Space space;
    const BodyHandle b = space.create_body(ball(Vec3::Zero()));
    space.set_collision_filter(b, 3, 9);
    space.set_collision_filter(b, 6, 2);
    space.update();
    EXPECT_EQ(space.internal_desc(b).layer, 6u);
    EXPECT_EQ(space.internal_desc(b).group, 2u);
}

TEST(Filtering, BadLayer_IsRejectedNamingItAndNothingChanges) {
    Space space;
    const BodyHandle b = space.create_body(ball(Vec3::Zero(), 31));
    const std::string create = error_of([&] { space.create_body(ball(Vec3(5, 0, 0), 32)); });
    EXPECT_NE(create.find("create_body: layer must be < 32, got 32"), std::string::npos) << create;
    EXPECT_EQ(space.body_count(), 1u);

    const std::string set = error_of([&] { space.set_collision_filter(b, 32, 0); });
    EXPECT_NE(set.find("set_collision_filter: layer must be < 32, got 32"), std::string::npos) << set;
    const std::string table = error_of([&] { space.set_layers_collide(0, 32, false); });
    EXPECT_NE(table.find("set_layers_collide: b must be < 32, got 32"), std::string::npos) << table;
    const std::string read = error_of([&] { (void)space.layers_collide(32, 0); });
    EXPECT_NE(read.find("got 32"), std::string::npos) << read;

    space.update();
    EXPECT_EQ(space.internal_desc(b).layer, 31u);
    EXPECT_EQ(space.last_update().writes_applied, 0);
    for (std::uint32_t l = 0; l < kLayerCount; ++l) EXPECT_TRUE(space.layers_collide(0, l));
}

}  // namespace filtering_test
