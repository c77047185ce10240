// Shape factories reject bad input with readable errors; bounds and mass properties
// match closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include <spindle/engine/shape.hpp>
#include <spindle/platform/error.hpp>

#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;

std::string error_of(void (*make)()) {
    try {
        make();
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

void expect_relative(Real actual, Real expected, Real tol = 1e-5) {
    EXPECT_NEAR(actual, expected, tol * std::abs(expected)) << "actual " << actual << " expected " << expected;
}

TEST(ShapeFactory, RejectsBadSizesNamingFieldAndValue) {
    EXPECT_EQ(error_of([] { Shape::box(Vec3(1, -1, 1)); }), "box: half_extents.y must be positive and finite, got -1");
    EXPECT_EQ(error_of([] { Shape::sphere(0); }), "sphere: radius must be positive and finite, got 0");
    EXPECT_EQ(error_of([] { Shape::sphere(std::numeric_limits<Real>::quiet_NaN()); }),
              "sphere: radius must be positive and finite, got nan");
    EXPECT_EQ(error_of([] { Shape::capsule(-0.5, 1); }), "capsule: half_height must be positive and finite, got -0.5");
    EXPECT_EQ(error_of([] { Shape::capsule(1, std::numeric_limits<Real>::infinity()); }),
              "capsule: radius must be positive and finite, got inf");
    EXPECT_EQ(error_of([] { Shape::plane(Vec3::Zero(), 1); }),
              "plane: normal must be finite and non-zero, got (0, 0, 0)");
    EXPECT_EQ(error_of([] { Shape::plane(Vec3::UnitY(), std::numeric_limits<Real>::infinity()); }),
              "plane: offset must be finite, got inf");
}

TEST(ShapeFactory, PlaneNormalIsNormalisedWithItsOffset) {
    const Shape p = Shape::plane(Vec3(0, 2, 0), 4);
    SPINDLE_EXPECT_VEC_NEAR(p.normal, Vec3(0, 1, 0), 1e-15);
    EXPECT_DOUBLE_EQ(p.offset, 2);
    EXPECT_TRUE(p.static_only());
}

TEST(ShapeBounds, RotatedBoxIsExact) {
    const Shape b = Shape::box(Vec3(1, 2, 3));
    const Aabb box = b.bounds(at(Vec3(10, 0, 0), about(Vec3::UnitZ(), kPi / 2)));
    SPINDLE_EXPECT_VEC_NEAR(box.min, Vec3(8, -1, -3), 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(box.max, Vec3(12, 1, 3), 1e-12);
}

TEST(ShapeBounds, CapsuleCoversBothEndsAndRadius) {
    const Shape c = Shape::capsule(1, 0.5);
    const Aabb box = c.bounds(at(Vec3(0, 1, 0), about(Vec3::UnitZ(), kPi / 2)));
    SPINDLE_EXPECT_VEC_NEAR(box.min, Vec3(-1.5, 0.5, -0.5), 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(box.max, Vec3(1.5, 1.5, 0.5), 1e-12);
}

TEST(ShapeBounds, HullAndSphere) {
    const Shape h = test::hull_box(Vec3(1, 1, 1));
    const Aabb box = h.bounds(at(Vec3(0, 0, 0), about(Vec3::UnitY(), kPi / 4)));
    EXPECT_NEAR(box.max.x(), std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(box.max.y(), 1, 1e-12);
    const Aabb s = Shape::sphere(2).bounds(at(Vec3(1, 1, 1)));
    SPINDLE_EXPECT_VEC_NEAR(s.min, Vec3(-1, -1, -1), 1e-15);
}

TEST(ShapeBounds, AxisAlignedPlaneIsBoundedOnItsSolidSide) {
    const Shape p = Shape::plane(Vec3::UnitY(), 1);
    const Aabb box = p.bounds(at(Vec3(0, 2, 0)));
    EXPECT_EQ(box.max.y(), 3);
    EXPECT_EQ(box.min.y(), -kHuge);
    EXPECT_EQ(box.max.x(), kHuge);
}

TEST(MassProperties, SolidSphereMatchesClosedForm) {
    const MassProperties mp = Shape::sphere(0.5).mass_properties(2);
    const Real m = 2 * 4.0 / 3.0 * kPi * 0.125;
    expect_relative(mp.mass, m);
    for (int i = 0; i < 3; ++i) expect_relative(mp.inertia(i, i), 0.4 * m * 0.25);
    EXPECT_TRUE(mp.center_of_mass.isZero());
}

TEST(MassProperties, BoxMatchesClosedForm) {
    const MassProperties mp = Shape::box(Vec3(1, 2, 3)).mass_properties(3);
    const Real m = 3 * 2 * 4 * 6;
    expect_relative(mp.mass, m);
    expect_relative(mp.inertia(0, 0), m / 12 * (16 + 36));
    expect_relative(mp.inertia(1, 1), m / 12 * (4 + 36));
    expect_relative(mp.inertia(2, 2), m / 12 * (4 + 16));
}

TEST(MassProperties, CapsuleMatchesClosedForm) {
    // Independent form: cylinder of height H plus a sphere split in two hemispheres at
    // distance H/2 + 3r/8 (their centres of mass) from the middle.
    const Real r = 0.3, h = 0.8, rho = 5, height = 2 * h;
    const MassProperties mp = Shape::capsule(h, r).mass_properties(rho);
    const Real mc = rho * kPi * r * r * height;
    const Real ms = rho * 4.0 / 3.0 * kPi * r * r * r;
    expect_relative(mp.mass, mc + ms);
    const Real iy = mc * r * r / 2 + 0.4 * ms * r * r;
    const Real hemi_own = (0.4 - 9.0 / 64.0) * ms / 2 * r * r;  // about the hemisphere's centre of mass
    const Real offset = height / 2 + 3 * r / 8;
    const Real ix = mc * (r * r / 4 + height * height / 12) + 2 * (hemi_own + ms / 2 * offset * offset);
    expect_relative(mp.inertia(1, 1), iy);
    expect_relative(mp.inertia(0, 0), ix);
    expect_relative(mp.inertia(2, 2), ix);
}

TEST(MassProperties, HullOfBoxMatchesBox) {
    const Vec3 h(0.5, 1, 1.5);
    std::vector<Vec3> points = test::box_corners(h);
    for (Vec3& p : points) p += Vec3(3, -2, 1);  // off-centre hull: centre of mass follows
    const MassProperties mp = Shape::convex_hull(points).mass_properties(2);
    const MassProperties expected = Shape::box(h).mass_properties(2);
    expect_relative(mp.mass, expected.mass, 1e-9);
    SPINDLE_EXPECT_VEC_NEAR(mp.center_of_mass, Vec3(3, -2, 1), 1e-12);
    EXPECT_LT((mp.inertia - expected.inertia).norm(), 1e-9 * expected.inertia.norm());
}

TEST(MassProperties, HullOfTetrahedronMatchesClosedForm) {
    // Unit right tetrahedron: volume 1/6, centroid (1/4, 1/4, 1/4), and about the centroid
    // Ixx = 1/80 * m (y^2+z^2 moments), products of inertia m/80 (positive sign: -(-1/80)).
    const std::vector<Vec3> points{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    const MassProperties mp = Shape::convex_hull(points).mass_properties(6);
    expect_relative(mp.mass, 1);
    SPINDLE_EXPECT_VEC_NEAR(mp.center_of_mass, Vec3::Constant(0.25), 1e-12);
    // Second moments of the unit tetrahedron about the origin: x^2 -> 1/60 * 6m/6..., shifted.
    const Real xx = 1.0 / 10 - 1.0 / 16;  // E[x^2] - E[x]^2 for density 6 (unit mass)
    const Real xy = 1.0 / 20 - 1.0 / 16;  // E[xy] - E[x]E[y]
    expect_relative(mp.inertia(0, 0), 2 * xx);
    expect_relative(mp.inertia(0, 1), -xy);
}

TEST(MassProperties, StaticShapesAndBadDensityThrow) {
    EXPECT_THROW(Shape::plane(Vec3::UnitY(), 0).mass_properties(1), Error);
    EXPECT_EQ(error_of([] { Shape::sphere(1).mass_properties(-1); }),
              "mass properties: density must be positive and finite, got -1");
}

}  // namespace
}  // namespace spindle
