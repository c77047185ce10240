// Scene queries against compounds: a ray meets each part where that part's surface is
// and names the part; shape casts and overlaps meet the parts, not the compound's bounds.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <vector>

#include "compound_test_util.hpp"
#include "static_bodies.hpp"

namespace spindle {
namespace {

using namespace test;

// A dumbbell turned a quarter about y (its bells along z), weightless, at kPose.
const Transform kPose{Vec3(1, 2, 3), Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitY()))};

struct DumbbellScene {
    Space space;
    BodyHandle bell;
    DumbbellScene() : space(weightless()) {
        BodyDesc d;
        d.shape = dumbbell();
        d.position = kPose.p;
        d.orientation = kPose.q;
        bell = space.create_body(d);
        space.update();
    }
    static SpaceSettings weightless() {
        SpaceSettings s;
        s.gravity = Vec3::Zero();
        return s;
    }
};

TEST(CompoundQuery, RayDownOntoEachPartNamesThatPartAndItsSurface) {
    DumbbellScene scene;
    struct Case {
        Vec3 local;  // the part's top centre, in the compound's frame
        std::uint32_t part;
    };
    const Case cases[] = {{Vec3(-kBellOffset, kBell, 0), 0}, {Vec3(kBellOffset, kBell, 0), 1}, {Vec3(0, 0.08, 0), 2}};
    for (const Case& c : cases) {
        const Vec3 top = kPose.apply(c.local);
        const Vec3 from = top + Vec3(0, 4, 0), to = top - Vec3(0, 1, 0);
        const auto hit = scene.space.cast_ray(from, to);
        ASSERT_TRUE(hit.has_value()) << "part " << c.part;
        EXPECT_EQ(hit->body, scene.bell);
        EXPECT_EQ(hit->part, c.part);
        EXPECT_LT((hit->point - top).norm(), 1e-9) << "part " << c.part << ": " << hit->point.transpose();
        EXPECT_LT((hit->normal - Vec3::UnitY()).norm(), 1e-9);
        EXPECT_NEAR(hit->fraction, 4.0 / 5.0, 1e-9);
    }
}

TEST(CompoundQuery, RayThroughTheGapBetweenPartsMisses) {
    DumbbellScene scene;
    // Inside the compound's bounds, beside the bar, clear of both bells.
    const Vec3 gap = kPose.apply(Vec3(0, 0, kBell * 0.8));
    EXPECT_FALSE(scene.space.cast_ray(gap + Vec3(0, 3, 0), gap - Vec3(0, 3, 0)).has_value());
}

TEST(CompoundQuery, RayAlongTheAxisHitsTheNearestBell) {
    DumbbellScene scene;
    // Along the compound's x axis from the +x side: bell 1 first.
    const Vec3 axis = kPose.rotate(Vec3::UnitX());
    const auto hit = scene.space.cast_ray(kPose.p + 5 * axis, kPose.p - 5 * axis);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->part, 1u);
    EXPECT_LT((hit->point - kPose.apply(Vec3(kBellOffset + kBell, 0, 0))).norm(), 1e-9);
}

TEST(CompoundQuery, ShapeCastStopsOnThePartBelow) {
    DumbbellScene scene;
    const Real r = 0.1;
    const Vec3 top = kPose.apply(Vec3(kBellOffset, kBell, 0));
    const Vec3 start = top + Vec3(0, 2, 0);
    const auto hit = scene.space.cast_shape(Shape::sphere(r), {start, Quat::Identity()}, Vec3(0, -4, 0));
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->body, scene.bell);
    EXPECT_EQ(hit->part, 1u);
    EXPECT_NEAR(hit->fraction, (2 - r) / 4, 1e-5);
    EXPECT_LT((hit->point - top).norm(), 1e-4);
}

TEST(CompoundQuery, CompoundCastStopsWhereItsLowestPartTouches) {
    // The dumbbell itself swept down onto a box floor: it stops with its bells on it.
    SpaceSettings settings = DumbbellScene::weightless();
    Space space(settings);
    test::add_static_box(space, Vec3(5, 0.5, 5), Vec3(0, -0.5, 0));
    space.update();
    const auto hit = space.cast_shape(dumbbell(), {Vec3(0, 2, 0), Quat::Identity()}, Vec3(0, -4, 0));
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->fraction, (2 - kBell) / 4, 1e-5);
}

TEST(CompoundQuery, OverlapMeetsPartsNotBounds) {
    DumbbellScene scene;
    std::vector<BodyHandle> found;
    const Shape probe = Shape::box(Vec3::Constant(0.02));
    // On the bar.
    EXPECT_EQ(scene.space.overlap_shape(probe, {kPose.apply(Vec3(0.1, 0, 0)), Quat::Identity()}, found), 1u);
    // Within the bounds, off every part: a corner of bell 1's bounding box.
    const Vec3 corner = kPose.apply(Vec3(kBellOffset, kBell * 0.85, kBell * 0.85));
    EXPECT_EQ(scene.space.overlap_shape(probe, {corner, Quat::Identity()}, found), 0u);
    // A compound probe: a dumbbell beside it, one bell inside bell 0.
    const Vec3 beside = kPose.apply(Vec3(-kBellOffset, 0, 0)) + Vec3(0, 0, 0) + kPose.rotate(Vec3(0, 0, 0.1)) -
                        kPose.rotate(Vec3(kBellOffset, 0, 0));
    EXPECT_EQ(scene.space.overlap_shape(dumbbell(), {beside, kPose.q}, found), 1u);
    EXPECT_EQ(scene.space.overlap_shape(dumbbell(), {kPose.p + Vec3(0, 2 * kBell + 0.05, 0), kPose.q}, found), 0u);
}

}  // namespace
}  // namespace spindle
