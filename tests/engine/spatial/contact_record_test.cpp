// The narrowphase's contact records (stages/narrowphase.cpp): a pair with no manifolds has
// its first manifold made in the record itself, over whatever an earlier touch left there,
// and must come out as a new manifold would: no impulse, no push, its collided separations kept.
// The broadphase's new records (stages/contact_list.cpp) are default-initialized on raw room:
// every field must come out as a fresh record's, whatever the room held.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include "api/space_internals.hpp"
#include "stages/broadphase_state.hpp"
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

TEST(ContactRecord, MadeOnDirtyRoom_EveryFieldAsAFreshRecord) {
    Space space;
    test::add_static_box(space, Vec3(5, 0.5, 5), Vec3(0, -0.5, 0));
    BodyDesc box;
    box.shape = Shape::box(Vec3::Constant(0.5));
    box.position = Vec3(0, 0.5, 0);
    box.friction = 0.64;
    box.restitution = 0.25;
    box.rolling_resistance = 0.1;
    space.create_body(box);
    space.update();
    World& world = SpaceInternals::world(space);
    ASSERT_EQ(world.contacts.size(), 1u);
    const std::uint64_t key = world.contact_keys[0];
    const Contact& first = world.contacts[0];
    const std::uint32_t body_a = first.body_a, body_b = first.body_b;
    const Real friction = first.friction, restitution = first.restitution;
    const float rolling_resistance = first.rolling_resistance;
    const std::uint8_t events = first.events;
    // The record taken away, and its room (with all the rest of the array's) made garbage.
    const std::uint32_t removed[] = {0};
    remove_contacts(world, removed);
    ASSERT_EQ(world.contacts.size(), 0u);
    ASSERT_GT(world.contacts.capacity(), 0u);
    std::memset(static_cast<void*>(world.contacts.data()), 0xA5, world.contacts.capacity() * sizeof(Contact));

    const std::uint64_t keys[] = {key};
    create_contacts(world, keys);
    ASSERT_EQ(world.contacts.size(), 1u);
    const Contact& c = world.contacts[0];
    const Contact fresh{};
    EXPECT_EQ(c.body_a, body_a);
    EXPECT_EQ(c.body_b, body_b);
    EXPECT_EQ(c.friction, friction);
    EXPECT_EQ(c.restitution, restitution);
    EXPECT_EQ(c.rolling_resistance, rolling_resistance);
    EXPECT_GT(c.rolling_resistance, 0.0f);
    EXPECT_EQ(c.events, events);
    EXPECT_TRUE(c.feature == fresh.feature);
    EXPECT_EQ(c.manifold_count, 0);
    EXPECT_FALSE(c.sleeping);
    EXPECT_FALSE(c.touch_reported);
    EXPECT_FALSE(c.pushed);
    EXPECT_FALSE(c.cached);
    EXPECT_EQ(c.cached_qa.coeffs(), fresh.cached_qa.coeffs());
    EXPECT_EQ(c.cached_qb.coeffs(), fresh.cached_qb.coeffs());
    EXPECT_EQ(c.cached_xa, fresh.cached_xa);
    EXPECT_EQ(c.cached_xb, fresh.cached_xb);
    EXPECT_EQ(c.extra, nullptr);
    const ContactManifold& m = c.manifold;
    const ContactManifold& f = fresh.manifold;
    EXPECT_EQ(m.normal, f.normal);
    EXPECT_EQ(m.part_a, f.part_a);
    EXPECT_EQ(m.part_b, f.part_b);
    EXPECT_EQ(m.point_count, f.point_count);
    EXPECT_EQ(m.pushed_point, f.pushed_point);
    EXPECT_EQ(m.pushed_speed, f.pushed_speed);
    EXPECT_EQ(m.twist_impulse, f.twist_impulse);
    for (int r = 0; r < 3; ++r) EXPECT_EQ(m.rolling_impulse[r], f.rolling_impulse[r]) << r;
    EXPECT_EQ(m.radius_a, f.radius_a);
    EXPECT_EQ(m.radius_b, f.radius_b);
    EXPECT_EQ(m.friction_impulse, f.friction_impulse);
    for (int j = 0; j < kMaxManifoldPoints; ++j) {
        EXPECT_EQ(m.points[j].point, f.points[j].point) << j;
        EXPECT_EQ(m.points[j].separation, f.points[j].separation) << j;
        EXPECT_EQ(m.points[j].base_separation, f.points[j].base_separation) << j;
        EXPECT_EQ(m.points[j].normal_impulse, f.points[j].normal_impulse) << j;
        EXPECT_EQ(m.points[j].id, f.points[j].id) << j;
    }
    EXPECT_EQ(world.contact_summaries[0], kSummaryRestitution | kSummaryRolls);  // no points yet
    EXPECT_EQ(*world.contact_index.find(key), 0u);
}

}  // namespace
}  // namespace spindle
