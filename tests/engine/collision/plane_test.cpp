// Convex shapes against a plane: vertices below (or within the speculative distance of)
// the plane become points; the normal points into the plane's solid side.
#include <gtest/gtest.h>

#include <cmath>

#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;
using test::run;

const Shape kGround = Shape::plane(Vec3::UnitY(), 0);

TEST(ConvexPlane, SphereRestingOnGround) {
    const auto m = run(Shape::sphere(0.5), at(Vec3(1, 0.45, 2)), kGround, at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-15);
    ASSERT_EQ(m[0].point_count, 1);
    EXPECT_NEAR(m[0].points[0].separation, -0.05, 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(1, -0.025, 2), 1e-12);
}

TEST(ConvexPlane, PlaneOffsetAndTransformAreApplied) {
    // Plane y = 1 in its frame; the frame is raised by 2 and turned so local +y is world +x.
    const Shape plane = Shape::plane(Vec3::UnitY(), 1);
    const Transform xp = at(Vec3(0, 2, 0), about(Vec3::UnitZ(), -kPi / 2));  // local +y -> world +x
    // World plane: normal +x through (1, 2, 0): x = 1.
    const auto m = run(Shape::sphere(1), at(Vec3(1.9, 5, 0)), plane, xp);
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(-1, 0, 0), 1e-12);
    EXPECT_NEAR(m[0].points[0].separation, -0.1, 1e-12);
}

TEST(ConvexPlane, SeparatedGivesNothingOrSpeculativePoint) {
    EXPECT_TRUE(run(Shape::sphere(0.5), at(Vec3(0, 0.7, 0)), kGround, at(Vec3::Zero())).empty());
    const auto m = run(Shape::sphere(0.5), at(Vec3(0, 0.7, 0)), kGround, at(Vec3::Zero()), 0.3);
    ASSERT_EQ(m.size(), 1u);
    EXPECT_NEAR(m[0].points[0].separation, 0.2, 1e-12);
}

TEST(ConvexPlane, LyingCapsuleHasTwoPointsStandingOne) {
    const Shape capsule = Shape::capsule(1, 0.25);
    auto m = run(capsule, at(Vec3(0, 0.2, 0), about(Vec3::UnitZ(), kPi / 2)), kGround, at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    ASSERT_EQ(m[0].point_count, 2);
    EXPECT_TRUE(test::has_point(m[0], Vec3(1, -0.025, 0), 1e-12));
    EXPECT_TRUE(test::has_point(m[0], Vec3(-1, -0.025, 0), 1e-12));
    m = run(capsule, at(Vec3(0, 1.2, 0)), kGround, at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    EXPECT_EQ(m[0].point_count, 1);
}

TEST(ConvexPlane, BoxOnTiltedPlaneHasFourPoints) {
    const Shape plane = Shape::plane(Vec3(0, 1, 0), 0);
    const Quat tilt = about(Vec3::UnitX(), 0.3);
    // The box sits tilted with the plane, 0.01 deep.
    const Transform xb = at(tilt * Vec3(0, 0.49, 0), tilt);
    const auto m = run(Shape::box(Vec3(1, 0.5, 1)), xb, plane, at(Vec3::Zero(), tilt));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(tilt * Vec3(0, -1, 0)), 1e-12);
    ASSERT_EQ(m[0].point_count, 4);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(m[0].points[i].separation, -0.01, 1e-12);
}

TEST(ConvexPlane, HullCornerDownAndSwappedOrder) {
    const Shape hull = test::hull_box(Vec3(1, 1, 1));
    const Quat corner_down = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3(0, -1, 0));
    const Transform xh = at(Vec3(0, std::sqrt(3.0) - 0.1, 0), corner_down);
    const auto m = run(hull, xh, kGround, at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    ASSERT_EQ(m[0].point_count, 1);
    EXPECT_NEAR(m[0].points[0].separation, -0.1, 1e-12);
    const auto flipped = run(kGround, at(Vec3::Zero()), hull, xh);
    ASSERT_EQ(flipped.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(flipped[0].normal, Vec3(0, 1, 0), 1e-12);
}

TEST(ConvexPlane, StaticPairsNeverCollide) {
    EXPECT_TRUE(run(kGround, at(Vec3::Zero()), kGround, at(Vec3::Zero())).empty());
}

}  // namespace
}  // namespace spindle
