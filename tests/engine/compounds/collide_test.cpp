// collide() with compounds: one manifold per touching part pair, labelled with the parts,
// in part order, the deepest kept when more touch than fit; and in a Space a contact
// keeps one manifold per touching part pair.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "api/space_internals.hpp"
#include "collision/collide.hpp"
#include "compound_test_util.hpp"
#include "stages/stages.hpp"
#include "static_bodies.hpp"

namespace spindle {
namespace {

using namespace test;

// A top (part 0) on six legs (parts 1..6) along x; leg i reaches `extra * i` below y = 0.
Shape six_legged_bench(Real extra = 0) {
    std::vector<CompoundPart> parts;
    parts.push_back({Shape::box(Vec3(1.2, 0.05, 0.5)), Vec3(0, 0.65, 0), Quat::Identity()});
    std::uint32_t i = 1;
    for (const Real x : {-1.0, 0.0, 1.0}) {
        for (const Real z : {-0.4, 0.4}) {
            const Real drop = extra * i++;
            parts.push_back(
                {Shape::box(Vec3(0.05, 0.3 + drop / 2, 0.05)), Vec3(x, 0.3 - drop / 2, z), Quat::Identity()});
        }
    }
    return Shape::compound(parts);
}

std::vector<Manifold> collide_all(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                                  int capacity = kMaxContactManifolds) {
    std::vector<Manifold> out(static_cast<std::size_t>(capacity));
    out.resize(static_cast<std::size_t>(collide(a, xa, b, xb, 0.01, out.data(), capacity)));
    return out;
}

TEST(CompoundCollide, EachTouchingPartPairHasItsOwnManifoldInPartOrder) {
    const Shape plane = Shape::plane(Vec3::UnitY(), 0);
    const std::vector<Manifold> m = collide_all(plane, Transform{}, six_legged_bench(), Transform{});
    ASSERT_EQ(m.size(), 6u);  // the top is far above the plane
    for (std::uint32_t i = 0; i < 6; ++i) {
        EXPECT_EQ(m[i].part_a, 0u);
        EXPECT_EQ(m[i].part_b, i + 1);
        EXPECT_LT((m[i].normal - Vec3::UnitY()).norm(), 1e-12);  // from the plane to the bench
        EXPECT_EQ(m[i].point_count, 4);
        for (int k = 0; k < m[i].point_count; ++k) EXPECT_NEAR(m[i].points[k].separation, 0, 1e-12);
    }
    // The other way round the parts and the normal swap sides.
    const std::vector<Manifold> flipped = collide_all(six_legged_bench(), Transform{}, plane, Transform{});
    ASSERT_EQ(flipped.size(), 6u);
    EXPECT_EQ(flipped[2].part_a, 3u);
    EXPECT_EQ(flipped[2].part_b, 0u);
    EXPECT_LT((flipped[2].normal + Vec3::UnitY()).norm(), 1e-12);
}

TEST(CompoundCollide, MorePartPairsThanFitKeepTheDeepestAndTheFarthestApartInPartOrder) {
    // Leg i reaches i mm below the plane. Of four, half are the deepest (legs 5 and 6, at
    // x = 1), then the farthest from those kept: leg 2 (x = -1, the deeper of the two
    // there), then leg 4 (x = 0, as far from leg 2 as from leg 6 and deeper than leg 3). The
    // deepest four (legs 3 to 6) held the bench on its half at x >= 0 only.
    const Shape plane = Shape::plane(Vec3::UnitY(), 0);
    const std::vector<Manifold> m = collide_all(plane, Transform{}, six_legged_bench(0.001), Transform{}, 4);
    ASSERT_EQ(m.size(), 4u);
    const std::uint32_t kept[] = {2, 4, 5, 6};
    for (std::uint32_t i = 0; i < 4; ++i) EXPECT_EQ(m[i].part_b, kept[i]);
}

TEST(CompoundCollide, ManyTouchingPartsKeepTheDeepestInPartOrder) {
    // 70 balls in a row on a plane, every ninth (from part 4) a millimetre deeper: more
    // part pairs than the walk holds, and the deepest eight come out in part order.
    std::vector<CompoundPart> parts;
    for (int i = 0; i < 70; ++i) {
        const Real depth = i % 9 == 4 ? 0.002 : 0.001;
        parts.push_back({Shape::sphere(0.1), Vec3(0.25 * i, 0.1 - depth, 0), Quat::Identity()});
    }
    const std::vector<Manifold> m = collide_all(Shape::plane(Vec3::UnitY(), 0), Transform{}, Shape::compound(parts),
                                                Transform{});
    ASSERT_EQ(m.size(), 8u);
    for (std::uint32_t k = 0; k < 8; ++k) {
        EXPECT_EQ(m[k].part_b, 4 + 9 * k);
        EXPECT_NEAR(m[k].points[0].separation, -0.002, 1e-12);
    }
}

TEST(CompoundCollide, CompoundOnCompoundLabelsBothParts) {
    // The dumbbell lies across the table's top (part 0) on its two bells (parts 0 and 1).
    const Transform on_top{Vec3(0, kTableHeight + kBell - 0.001, 0), Quat::Identity()};
    const std::vector<Manifold> m = collide_all(table(), Transform{}, dumbbell(), on_top);
    ASSERT_EQ(m.size(), 2u);
    EXPECT_EQ(m[0].part_a, 0u);
    EXPECT_EQ(m[0].part_b, 0u);
    EXPECT_EQ(m[1].part_a, 0u);
    EXPECT_EQ(m[1].part_b, 1u);
    for (const Manifold& each : m) {
        EXPECT_LT((each.normal - Vec3::UnitY()).norm(), 1e-9);
        ASSERT_EQ(each.point_count, 1);
        EXPECT_NEAR(each.points[0].separation, -0.001, 1e-9);
    }
    // Lifted clear of the top (beyond the speculative distance), nothing.
    const Transform above{on_top.p + Vec3(0, 0.05, 0), on_top.q};
    EXPECT_TRUE(collide_all(table(), Transform{}, dumbbell(), above).empty());
}

TEST(CompoundCollide, CompoundOnCompoundMeetsWithinTheSpeculativeDistance) {
    // The bells hang 5 mm over the table's top, within collide_all's 10 mm: each part of one
    // compound lies clear of the other's whole box, but not of that box fattened by the
    // speculative distance, and still meets a part of the other. Both ways round.
    const Transform over{Vec3(0, kTableHeight + kBell + 0.005, 0), Quat::Identity()};
    const std::vector<Manifold> m = collide_all(table(), Transform{}, dumbbell(), over);
    ASSERT_EQ(m.size(), 2u);
    const std::vector<Manifold> flipped = collide_all(dumbbell(), over, table(), Transform{});
    ASSERT_EQ(flipped.size(), 2u);
    for (std::uint32_t i = 0; i < 2; ++i) {
        EXPECT_EQ(m[i].part_a, 0u);
        EXPECT_EQ(m[i].part_b, i);
        EXPECT_EQ(flipped[i].part_a, i);
        EXPECT_EQ(flipped[i].part_b, 0u);
        for (const Manifold* each : {&m[i], &flipped[i]}) {
            ASSERT_EQ(each->point_count, 1);
            EXPECT_NEAR(each->points[0].separation, 0.005, 1e-9);
        }
    }
}

// A space that never sleeps, with a static plane at y = 0 (its first body).
std::unique_ptr<Space> space_on_plane() {
    SpaceSettings settings;
    settings.sleep.enabled = false;
    auto space = std::make_unique<Space>(settings);
    test::add_ground_plane(*space);
    return space;
}

TEST(CompoundCollide, ContactKeepsAManifoldPerTouchingLegAndStandsStill) {
    const std::unique_ptr<Space> scene = space_on_plane();
    Space& space = *scene;
    BodyDesc d;
    d.shape = six_legged_bench();
    d.position = Vec3::Zero();
    const BodyHandle bench = space.create_body(d);
    for (int i = 0; i < 120; ++i) space.update();
    const World& world = SpaceInternals::world(space);
    ASSERT_EQ(world.contacts.size(), 1u);
    const Contact& contact = world.contacts[0];
    ASSERT_EQ(contact.manifold_count, 6);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(contact.manifold_at(i).part_b, static_cast<std::uint32_t>(i + 1));
    EXPECT_LT(space.position(bench).norm(), 1e-3);
    EXPECT_LT(space.angular_velocity(bench).norm(), 1e-3);
}

TEST(CompoundCollide, RecollidedLegsKeepTheirOwnWarmStart) {
    // A block near one end loads the near legs more than the far ones. All legs stand on
    // the plane with the same feature ids; collided afresh, each leg's points must take the
    // impulses of the same leg, not of the first leg whose ids match.
    std::vector<CompoundPart> parts;
    parts.push_back({Shape::box(Vec3(1.1, 0.05, 0.5)), Vec3(0, 0.65, 0), Quat::Identity()});
    parts.push_back({Shape::box(Vec3(0.3, 0.3, 0.3)), Vec3(0.75, 1.0, 0), Quat::Identity()});
    for (const Real x : {-1.0, 1.0}) {
        for (const Real z : {-0.4, 0.4}) {
            parts.push_back({Shape::box(Vec3(0.05, 0.3, 0.05)), Vec3(x, 0.3, z), Quat::Identity()});
        }
    }
    const std::unique_ptr<Space> scene = space_on_plane();
    Space& space = *scene;
    BodyDesc d;
    d.shape = Shape::compound(parts);
    d.position = Vec3::Zero();
    space.create_body(d);
    for (int i = 0; i < 120; ++i) space.update();

    World& world = SpaceInternals::world(space);
    ASSERT_EQ(world.contacts.size(), 1u);
    Contact& contact = world.contacts[0];
    ASSERT_EQ(contact.manifold_count, 4);
    auto leg_load = [&](int m) {
        Real sum = 0;
        const ContactManifold& leg = contact.manifold_at(m);
        for (int j = 0; j < leg.point_count; ++j) sum += leg.points[j].normal_impulse;
        return sum;
    };
    Real before[4];
    for (int m = 0; m < 4; ++m) before[m] = leg_load(m);
    EXPECT_GT(before[3], 2 * before[0]);  // the near legs (x = +1) carry more than the far ones
    contact.cached = false;               // collide afresh instead of recycling
    update_narrowphase(world);
    ASSERT_EQ(contact.manifold_count, 4);
    for (int m = 0; m < 4; ++m) EXPECT_NEAR(leg_load(m), before[m], 1e-9 + 1e-6 * before[m]) << "leg " << m;
}

}  // namespace
}  // namespace spindle

namespace spindle {
namespace {

TEST(CompoundCollide, AConvexPairCollidedAfterACompoundPairIsLabelledNoPart) {
    // The narrowphase collides a chunk of pairs with one scratch list of manifolds. A box's
    // pair collided after a compound's must not keep the compound's part labels: a manifold
    // labelled with another part misses its own warm start (and takes that part's radius),
    // so a pair's result would hang on which pair its chunk collided before it.
    // Part 0 rides above the others, off the ground: the compound's manifolds are parts 1-3.
    std::vector<CompoundPart> parts;
    parts.push_back({Shape::box(Vec3(0.2, 0.2, 0.2)), Vec3(0.5, 0.6, 0)});
    for (int i = 0; i < 3; ++i) parts.push_back({Shape::box(Vec3(0.2, 0.2, 0.2)), Vec3(0.5 * i, 0.2, 0)});
    const std::unique_ptr<Space> scene = space_on_plane();
    Space& space = *scene;
    BodyDesc d;
    for (int i = 0; i < 4; ++i) {  // compounds and boxes in turn, apart on the plane
        d.shape = Shape::compound(parts);
        d.position = Vec3(-20 + 10 * i, 0, 0);
        space.create_body(d);
        d.shape = Shape::box(Vec3(0.2, 0.2, 0.2));
        d.position = Vec3(-20 + 10 * i, 0.2, 5);
        space.create_body(d);
    }
    for (int i = 0; i < 30; ++i) space.update();
    World& world = SpaceInternals::world(space);
    for (Contact& contact : world.contacts) contact.cached = false;  // every pair collided afresh
    update_narrowphase(world);
    int boxes = 0;
    for (const Contact& contact : world.contacts) {
        if (world.bodies.traits[contact.body_b].shape.type != ShapeType::Box) continue;
        ASSERT_GT(contact.manifold_count, 0);
        ++boxes;
        for (int m = 0; m < contact.manifold_count; ++m) {
            EXPECT_EQ(contact.manifold_at(m).part_a, 0u) << "box " << contact.body_b;
            EXPECT_EQ(contact.manifold_at(m).part_b, 0u) << "box " << contact.body_b;
        }
    }
    EXPECT_EQ(boxes, 4);
}

}  // namespace
}  // namespace spindle
