// Compound mass properties against closed forms: parts add up by the parallel axis
// theorem, a part's inertia turns with its orientation, and bounds are the parts' union.
#include <spindle/engine/shape.hpp>

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "collision/compound.hpp"
#include "compound_test_util.hpp"

namespace spindle {
namespace {

constexpr Real kDensity = 700;

void expect_near(const Mat3& actual, const Mat3& expected, Real tolerance) {
    EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), tolerance) << "actual\n"
                                                                    << actual << "\nexpected\n"
                                                                    << expected;
}

TEST(CompoundMass, TwoBoxesSideBySideAreOneLongBox) {
    const CompoundPart parts[] = {{Shape::box(Vec3(0.5, 0.2, 0.3)), Vec3(1.5, 2, -1), Quat::Identity()},
                                  {Shape::box(Vec3(0.5, 0.2, 0.3)), Vec3(2.5, 2, -1), Quat::Identity()}};
    const MassProperties compound = Shape::compound(parts).mass_properties(kDensity);
    const MassProperties single = Shape::box(Vec3(1, 0.2, 0.3)).mass_properties(kDensity);
    EXPECT_NEAR(compound.mass, single.mass, 1e-9);
    EXPECT_LT((compound.center_of_mass - Vec3(2, 2, -1)).norm(), 1e-12);
    expect_near(compound.inertia, single.inertia, 1e-9);
}

TEST(CompoundMass, OffsetSphereFollowsTheParallelAxisTheorem) {
    const Real r = 0.4;
    const Vec3 offset(0.3, -1.2, 0.5);
    const CompoundPart center[] = {{Shape::sphere(r), Vec3::Zero(), Quat::Identity()}};
    const CompoundPart off[] = {{Shape::sphere(r), offset, Quat::Identity()},
                                {Shape::sphere(r), -offset, Quat::Identity()}};
    const MassProperties one = Shape::compound(center).mass_properties(kDensity);
    const MassProperties two = Shape::compound(off).mass_properties(kDensity);
    const Real m = kDensity * 4.0 / 3.0 * kPi * r * r * r;
    EXPECT_NEAR(one.mass, m, 1e-9);
    EXPECT_NEAR(two.mass, 2 * m, 1e-9);
    EXPECT_LT(two.center_of_mass.norm(), 1e-12);
    // Each ball: 2/5 m r^2 about its centre, plus m (|d|^2 I - d d^T) to the shared centre.
    const Mat3 ball = Mat3::Identity() * (0.4 * m * r * r);
    const Mat3 shift = m * (offset.squaredNorm() * Mat3::Identity() - offset * offset.transpose());
    expect_near(two.inertia, 2 * (ball + shift), 1e-9);
    expect_near(one.inertia, ball, 1e-9);
}

TEST(CompoundMass, OnePartOffCentreHasItsCentreOfMassThere) {
    const Vec3 offset(1, 2, 3);
    const CompoundPart parts[] = {{Shape::capsule(0.5, 0.2), offset, Quat::Identity()}};
    const MassProperties compound = Shape::compound(parts).mass_properties(kDensity);
    const MassProperties capsule = Shape::capsule(0.5, 0.2).mass_properties(kDensity);
    EXPECT_LT((compound.center_of_mass - offset).norm(), 1e-12);
    expect_near(compound.inertia, capsule.inertia, 1e-9);
}

TEST(CompoundMass, PartInertiaTurnsWithItsOrientation) {
    // A box turned 90 degrees about z swaps its x and y moments.
    const Vec3 half(0.8, 0.2, 0.4);
    const CompoundPart parts[] = {{Shape::box(half), Vec3::Zero(), Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()))}};
    const MassProperties turned = Shape::compound(parts).mass_properties(kDensity);
    const MassProperties box = Shape::box(Vec3(half.y(), half.x(), half.z())).mass_properties(kDensity);
    expect_near(turned.inertia, box.inertia, 1e-9);
}

TEST(CompoundMass, TableMatchesItsPartsSummedByHand) {
    using namespace test;
    const MassProperties mp = table().mass_properties(kDensity);
    const Real top_mass = kDensity * 8 * kTopHalf.prod();
    const Real leg_mass = kDensity * 8 * kLegHalf.prod();
    EXPECT_NEAR(mp.mass, top_mass + 4 * leg_mass, 1e-9);
    const Real top_y = kTableHeight - kTopHalf.y();
    const Real com_y = (top_mass * top_y + 4 * leg_mass * kLegHalf.y()) / (top_mass + 4 * leg_mass);
    EXPECT_LT((mp.center_of_mass - Vec3(0, com_y, 0)).norm(), 1e-12);
    // About the vertical axis: the top's own, plus each leg's own and its distance to the axis.
    const Real top_yy = top_mass / 3 * (kTopHalf.x() * kTopHalf.x() + kTopHalf.z() * kTopHalf.z());
    const Real leg_yy = leg_mass / 3 * (kLegHalf.x() * kLegHalf.x() + kLegHalf.z() * kLegHalf.z());
    EXPECT_NEAR(mp.inertia(1, 1), top_yy + 4 * (leg_yy + leg_mass * (kLegX * kLegX + kLegZ * kLegZ)), 1e-9);
    EXPECT_NEAR(mp.inertia(0, 1), 0, 1e-9);
}

TEST(CompoundMass, NonUnitOrientationIsNormalised) {
    const Quat q = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
    const CompoundPart unit[] = {{Shape::box(Vec3(0.3, 0.2, 0.1)), Vec3(0, 1, 0), q}};
    const CompoundPart scaled[] = {{Shape::box(Vec3(0.3, 0.2, 0.1)), Vec3(0, 1, 0), Quat(q.coeffs() * 5)}};
    expect_near(Shape::compound(scaled).mass_properties(kDensity).inertia,
                Shape::compound(unit).mass_properties(kDensity).inertia, 1e-9);
}

TEST(CompoundBounds, AreTheUnionOfThePartsBounds) {
    using namespace test;
    const Transform pose{Vec3(5, 1, -2), Quat::Identity()};
    const Aabb box = dumbbell().bounds(pose);
    EXPECT_LT((box.min - Vec3(5 - kBellOffset - kBell, 1 - kBell, -2 - kBell)).norm(), 1e-12);
    EXPECT_LT((box.max - Vec3(5 + kBellOffset + kBell, 1 + kBell, -2 + kBell)).norm(), 1e-12);
    // Turned a quarter about z, the bells lie along y.
    const Aabb turned = dumbbell().bounds({Vec3::Zero(), Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()))});
    EXPECT_NEAR(turned.max.y(), kBellOffset + kBell, 1e-12);
    EXPECT_NEAR(turned.max.x(), kBell, 1e-12);
}

// Parts at the compound's origin, unturned, skip the pose product; moved or turned ones
// must not: each part's world box is its shape's under the compound's pose times its own.
// A part at the origin gives the same bits as the product's; a moved or turned part's product
// may round otherwise here than in the engine (either compiler may fuse multiply-adds), so
// those are compared to far below what leaving their pose out would move them.
TEST(CompoundBounds, EachPartsBoxIsItsShapeUnderItsWorldPose) {
    constexpr Real kRounding = 1e-12;  // metres-sized boxes: a few ulps
    const std::vector<Vec3> wedge = {Vec3(0.2, 0, 0.1), Vec3(1, 0.1, 0), Vec3(0.3, 0.9, 0.2), Vec3(0.4, 0.2, 1.1)};
    const CompoundPart parts[] = {
        {Shape::convex_hull(wedge), Vec3::Zero(), Quat::Identity()},
        {Shape::convex_hull(wedge), Vec3(0.5, -0.3, 0.2), Quat::Identity()},
        {Shape::convex_hull(wedge), Vec3::Zero(), Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 0).normalized()))},
        {Shape::box(Vec3(0.4, 0.1, 0.2)), Vec3::Zero(), Quat::Identity()},
        {Shape::box(Vec3(0.4, 0.1, 0.2)), Vec3(-1, 0, 0.5), Quat(Eigen::AngleAxisd(-0.4, Vec3::UnitY()))},
        {Shape::capsule(0.3, 0.2), Vec3::Zero(), Quat::Identity()},
        {Shape::capsule(0.3, 0.2), Vec3(0, 0.8, 0), Quat(Eigen::AngleAxisd(1.1, Vec3::UnitX()))},
    };
    const Shape shape = Shape::compound(parts);
    const Compound& compound = *shape.parts;
    std::mt19937 rng(44);
    std::normal_distribution<Real> g;
    std::vector<Aabb> boxes(compound.size());
    for (int sample = 0; sample < 50; ++sample) {
        const Quat q = Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
        const Transform x{Vec3(3 * g(rng), 3 * g(rng), 3 * g(rng)), q};
        const Aabb all = compound.bounds(x, boxes);
        Aabb expected_all;
        for (std::uint32_t i = 0; i < compound.size(); ++i) {
            const Aabb expected = compound.shape(i).bounds(x * compound.pose(i));
            const bool at_origin = compound.pose(i).p == Vec3::Zero() && compound.pose(i).q.vec() == Vec3::Zero();
            const Real tolerance = at_origin ? 0 : kRounding;
            EXPECT_LE((boxes[i].min - expected.min).cwiseAbs().maxCoeff(), tolerance)
                << "sample " << sample << " part " << i;
            EXPECT_LE((boxes[i].max - expected.max).cwiseAbs().maxCoeff(), tolerance)
                << "sample " << sample << " part " << i;
            expected_all = expected_all.merged(boxes[i]);
        }
        EXPECT_EQ(all.min, expected_all.min) << "sample " << sample;
        EXPECT_EQ(all.max, expected_all.max) << "sample " << sample;
        EXPECT_EQ(compound.bounds(x).min, expected_all.min) << "sample " << sample;
        EXPECT_EQ(compound.bounds(x).max, expected_all.max) << "sample " << sample;
    }
}

}  // namespace
}  // namespace spindle
