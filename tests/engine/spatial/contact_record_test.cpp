// The narrowphase's contact records (stages/narrowphase.cpp): a pair with no manifolds has
// its first manifold made in the record itself, over whatever an earlier touch left there,
// and must come out as a new manifold would: no impulse, no push, its collided separations kept.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include "api/space_internals.hpp"
#include "stages/stages.hpp"
#include "static_bodies.hpp"
#include "world.hpp"

namespace spindle {
namespace {

TEST(ContactRecord, ManifoldMadeWhereNoneWas_KeepsNothingOfAnEarlierTouch) {
    SpaceSettings settings;
    settings.sleep.enabled = false;
    Space space(settings);
    test::add_static_box(space, Vec3(5, 0.5, 5), Vec3(0, -0.5, 0));
    BodyDesc box;
    box.shape = Shape::box(Vec3::Constant(0.5));
    box.position = Vec3(0, 0.5, 0);
    box.linear_velocity = Vec3(1, 0, 0);  // sliding: friction pushes too
    box.rolling_resistance = 0.1;
    space.create_body(box);
    for (int i = 0; i < 5; ++i) space.update();

    World& world = SpaceInternals::world(space);
    ASSERT_EQ(world.contacts.size(), 1u);
    Contact& contact = world.contacts[0];
    ASSERT_EQ(contact.manifold_count, 1);
    ASSERT_EQ(contact.manifold.point_count, 4);
    ASSERT_GT(contact.manifold.points[0].normal_impulse, 0.0f);
    // As a touch that ended leaves the record: no manifold counted, the last one's fields
    // still there (here made larger than any the step would give).
    ContactManifold& m = contact.manifold;
    contact.manifold_count = 0;
    contact.cached = false;
    m.part_a = m.part_b = 3;
    m.pushed_point = 2;
    m.pushed_speed = 9;
    m.twist_impulse = 7;
    m.rolling_impulse[0] = m.rolling_impulse[1] = m.rolling_impulse[2] = 5;
    m.radius_a = m.radius_b = 0.25;
    m.friction_impulse = Vec3(1, 2, 3);
    for (ContactPoint& p : m.points) {
        p.normal_impulse = 11;
        p.base_separation = 42;
        p.separation = 42;
    }
    update_narrowphase(world);

    ASSERT_EQ(contact.manifold_count, 1);
    EXPECT_EQ(m.point_count, 4);
    EXPECT_EQ(m.part_a, 0u);
    EXPECT_EQ(m.part_b, 0u);
    EXPECT_EQ(m.pushed_point, -1);
    EXPECT_EQ(m.pushed_speed, 0.0f);
    EXPECT_EQ(m.twist_impulse, 0.0f);
    for (const float r : m.rolling_impulse) EXPECT_EQ(r, 0.0f);
    EXPECT_EQ(m.radius_a, 0.0);
    EXPECT_EQ(m.radius_b, 0.0);
    EXPECT_EQ(m.friction_impulse, Vec3::Zero());
    EXPECT_NEAR(m.normal.y(), 1, 1e-6);
    for (int j = 0; j < m.point_count; ++j) {
        EXPECT_EQ(m.points[j].normal_impulse, 0.0f) << j;
        EXPECT_LT(std::abs(m.points[j].separation), 0.01) << j;
        EXPECT_EQ(m.points[j].base_separation, m.points[j].separation) << j;
    }
    EXPECT_TRUE(contact.cached);
}

}  // namespace
}  // namespace spindle
