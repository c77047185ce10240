// Pairs with a sphere or capsule: normals, depths and points against hand-computed
// values, speculative contacts, and two-point manifolds for capsules lying flat.
#include <gtest/gtest.h>

#include <cmath>

#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;
using test::run;

TEST(SphereSphere, OverlappingGivesDepthAndMidpoint) {
    const auto m = run(Shape::sphere(1), at(Vec3(0, 0, 0)), Shape::sphere(0.5), at(Vec3(1.2, 0, 0)));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(1, 0, 0), 1e-12);
    ASSERT_EQ(m[0].point_count, 1);
    EXPECT_NEAR(m[0].points[0].separation, -0.3, 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(0.85, 0, 0), 1e-12);  // between 0.7 and 1.0
    EXPECT_EQ(m[0].points[0].id, m[0].points[0].id);
}

TEST(SphereSphere, SeparatedGivesNothingOrSpeculativePoint) {
    EXPECT_TRUE(run(Shape::sphere(1), at(Vec3::Zero()), Shape::sphere(1), at(Vec3(0, 2.5, 0))).empty());
    const auto m = run(Shape::sphere(1), at(Vec3::Zero()), Shape::sphere(1), at(Vec3(0, 2.5, 0)), 0.6);
    ASSERT_EQ(m.size(), 1u);
    EXPECT_NEAR(m[0].points[0].separation, 0.5, 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(0, 1.25, 0), 1e-12);
}

TEST(SphereSphere, TouchingHasZeroSeparation) {
    const auto m = run(Shape::sphere(1), at(Vec3::Zero()), Shape::sphere(1), at(Vec3(0, 0, 2)));
    ASSERT_EQ(m.size(), 1u);
    EXPECT_NEAR(m[0].points[0].separation, 0, 1e-12);
}

TEST(SphereCapsule, SphereBesideTheSegmentMiddle) {
    // Capsule lying along x (rotated), sphere above its middle.
    const auto m = run(Shape::sphere(0.5), at(Vec3(0.3, 1.2, 0)), Shape::capsule(1, 0.8),
                       at(Vec3::Zero(), about(Vec3::UnitZ(), kPi / 2)));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-12);
    EXPECT_NEAR(m[0].points[0].separation, -0.1, 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(0.3, 0.75, 0), 1e-12);
}

TEST(SphereCapsule, SphereBeyondTheEndCap) {
    const auto m = run(Shape::sphere(0.5), at(Vec3(0, 2.0, 0)), Shape::capsule(0.5, 1.0), at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-12);
    EXPECT_NEAR(m[0].points[0].separation, 1.5 - 1.5, 1e-12);
}

TEST(CapsuleCapsule, CrossedCapsulesTouchAtOnePoint) {
    // A along y, B along x one unit in front along z.
    const auto m = run(Shape::capsule(1, 0.3), at(Vec3::Zero()), Shape::capsule(1, 0.5),
                       at(Vec3(0.2, 0.4, 0.7), about(Vec3::UnitZ(), kPi / 2)));
    ASSERT_EQ(m.size(), 1u);
    ASSERT_EQ(m[0].point_count, 1);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 0, 1), 1e-12);
    EXPECT_NEAR(m[0].points[0].separation, -0.1, 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(0, 0.4, 0.25), 1e-12);
}

TEST(CapsuleCapsule, ParallelCapsulesRestOnTwoPoints) {
    const Quat lying = about(Vec3::UnitZ(), kPi / 2);  // along x
    const auto m = run(Shape::capsule(1, 0.5), at(Vec3(0, 0, 0), lying), Shape::capsule(1, 0.5),
                       at(Vec3(0.5, 0.95, 0), lying));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-12);
    ASSERT_EQ(m[0].point_count, 2);
    EXPECT_TRUE(test::has_point(m[0], Vec3(-0.5, 0.475, 0), 1e-9));
    EXPECT_TRUE(test::has_point(m[0], Vec3(1.0, 0.475, 0), 1e-9));
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(m[0].points[i].separation, -0.05, 1e-12);
    EXPECT_NE(m[0].points[0].id, m[0].points[1].id);
}

TEST(SphereBox, SphereOnFaceEdgeAndCorner) {
    const Shape box = Shape::box(Vec3(1, 1, 1));
    const Shape ball = Shape::sphere(0.5);
    auto m = run(ball, at(Vec3(0.2, 1.4, -0.3)), box, at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-12);
    EXPECT_NEAR(m[0].points[0].separation, -0.1, 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(0.2, 0.95, -0.3), 1e-12);

    m = run(ball, at(Vec3(1.2, 1.2, 1.2)), box, at(Vec3::Zero()));  // corner
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(-1, -1, -1).normalized(), 1e-12);
    EXPECT_NEAR(m[0].points[0].separation, std::sqrt(3 * 0.04) - 0.5, 1e-12);
}

TEST(SphereBox, RotatedBoxAndDeepCentre) {
    const auto m = run(Shape::sphere(0.5), at(Vec3(0, 0.9, 0)), Shape::box(Vec3(1, 0.5, 1)),
                       at(Vec3::Zero(), about(Vec3::UnitY(), 0.7)));
    ASSERT_EQ(m.size(), 1u);
    EXPECT_NEAR(m[0].points[0].separation, -0.1, 1e-12);
    // Centre inside: leaves through the nearest face (+x here).
    const auto deep = run(Shape::sphere(0.5), at(Vec3(0.8, 0.1, 0)), Shape::box(Vec3(1, 1, 1)), at(Vec3::Zero()));
    ASSERT_EQ(deep.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(deep[0].normal, Vec3(-1, 0, 0), 1e-12);
    EXPECT_NEAR(deep[0].points[0].separation, -0.7, 1e-12);
}

TEST(CapsuleBox, CapsuleLyingOnBoxGetsTwoPoints) {
    const auto m = run(Shape::capsule(0.5, 0.25), at(Vec3(0.1, 1.2, 0), about(Vec3::UnitZ(), kPi / 2)),
                       Shape::box(Vec3(2, 1, 2)), at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-12);
    ASSERT_EQ(m[0].point_count, 2);
    EXPECT_TRUE(test::has_point(m[0], Vec3(-0.4, 0.975, 0), 1e-9));
    EXPECT_TRUE(test::has_point(m[0], Vec3(0.6, 0.975, 0), 1e-9));
    EXPECT_NEAR(m[0].points[0].separation, -0.05, 1e-12);
}

TEST(CapsuleBox, CoreInsideBoxUsesSat) {
    // Segment end pushed 0.1 into the top face: the core overlaps, SAT picks the top face.
    const auto m = run(Shape::capsule(0.5, 0.25), at(Vec3(0, 1.4, 0)), Shape::box(Vec3(1, 1, 1)), at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-12);
    EXPECT_NEAR(deepest(m[0]), -0.35, 1e-12);
}

TEST(CapsuleBox, CapsuleOverBoxEdgeTakesEdgeNormal) {
    // Capsule along z, above and beside the box's top +x edge: the normal runs from
    // the edge to the capsule axis.
    const Vec3 c(1.2, 1.2, 0);
    const auto m = run(Shape::capsule(0.5, 0.3), at(c, about(Vec3::UnitX(), kPi / 2)), Shape::box(Vec3(1, 1, 1)),
                       at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(-1, -1, 0).normalized(), 1e-9);
    EXPECT_NEAR(deepest(m[0]), std::sqrt(0.08) - 0.3, 1e-9);
}

TEST(SphereHull, MatchesSphereBox) {
    const Shape box = Shape::box(Vec3(1, 0.5, 2));
    const Shape hull = test::hull_box(Vec3(1, 0.5, 2));
    const Transform xb = at(Vec3(0.1, 0.2, 0.3), about(Vec3(1, 2, 3), 0.4));
    for (const Vec3& p : {Vec3(0.3, 0.9, 0.1), Vec3(1.2, 0.8, 2.1), Vec3(0.2, 0.3, 0.1), Vec3(-1.1, 0.2, 0.4)}) {
        const auto expected = run(Shape::sphere(0.4), at(p), box, xb);
        const auto actual = run(Shape::sphere(0.4), at(p), hull, xb);
        ASSERT_EQ(actual.size(), expected.size()) << p.transpose();
        if (expected.empty()) continue;
        SPINDLE_EXPECT_VEC_NEAR(actual[0].normal, expected[0].normal, 1e-9);
        EXPECT_NEAR(actual[0].points[0].separation, expected[0].points[0].separation, 1e-9);
        SPINDLE_EXPECT_VEC_NEAR(actual[0].points[0].point, expected[0].points[0].point, 1e-9);
    }
}

TEST(CapsuleHull, MatchesCapsuleBox) {
    const Shape box = Shape::box(Vec3(1, 0.5, 2));
    const Shape hull = test::hull_box(Vec3(1, 0.5, 2));
    const Shape capsule = Shape::capsule(0.6, 0.3);
    const Transform xb = at(Vec3(0.1, 0.2, 0.3), about(Vec3(1, 2, 3), 0.4));
    for (const Transform& xa : {at(Vec3(0.3, 1.2, 0.1), about(Vec3::UnitZ(), 1.4)), at(Vec3(1.2, 0.9, 1.1)),
                                at(Vec3(0.1, 0.3, 0.2), about(Vec3(1, 0, 1), 0.3))}) {
        const auto expected = run(capsule, xa, box, xb);
        const auto actual = run(capsule, xa, hull, xb);
        ASSERT_EQ(actual.size(), expected.size());
        if (expected.empty()) continue;
        SPINDLE_EXPECT_VEC_NEAR(actual[0].normal, expected[0].normal, 1e-9);
        EXPECT_EQ(actual[0].point_count, expected[0].point_count);
        EXPECT_NEAR(deepest(actual[0]), deepest(expected[0]), 1e-9);
    }
}

}  // namespace
}  // namespace spindle
