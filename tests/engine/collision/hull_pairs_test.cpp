// Hull pairs: the general polyhedron SAT against hand-computed contacts and against
// the dedicated box code; ids hold while a hull slides; order swaps flip the normal.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;
using test::run;

Shape tetrahedron_point_down() {
    // Apex at the origin, base triangle at y = 1.
    const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(-0.5, 1, 0.8), Vec3(-0.5, 1, -0.8)};
    return Shape::convex_hull(p);
}

TEST(HullHull, RestingCubeHasFourCornerPoints) {
    test::expect_resting_cube_contact(test::hull_box(Vec3(2, 0.5, 2)), test::hull_box(Vec3(0.5, 0.5, 0.5)));
}

TEST(HullHull, CrossedEdgesGiveOneEdgePoint) { test::expect_crossed_edges_contact(test::hull_box(Vec3(1, 1, 1))); }

TEST(HullHull, TetrahedronApexPokesIntoAFace) {
    const auto m = run(test::hull_box(Vec3(1, 1, 1)), at(Vec3::Zero()), tetrahedron_point_down(),
                       at(Vec3(0.2, 0.95, 0.1)));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-12);
    ASSERT_EQ(m[0].point_count, 1);
    EXPECT_NEAR(m[0].points[0].separation, -0.05, 1e-12);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(0.2, 0.975, 0.1), 1e-12);
}

TEST(HullHull, SpeculativeFaceContact) {
    const Shape cube = test::hull_box(Vec3(0.5, 0.5, 0.5));
    EXPECT_TRUE(run(cube, at(Vec3::Zero()), cube, at(Vec3(0, 1.2, 0))).empty());
    const auto m = run(cube, at(Vec3::Zero()), cube, at(Vec3(0, 1.2, 0)), 0.25);
    ASSERT_EQ(m.size(), 1u);
    EXPECT_EQ(m[0].point_count, 4);
    EXPECT_NEAR(deepest(m[0]), 0.2, 1e-12);
}

TEST(HullHull, FeatureIdsHoldWhileSliding) {
    const Shape floor = test::hull_box(Vec3(2, 0.5, 2));
    const Shape cube = test::hull_box(Vec3(0.5, 0.5, 0.5));
    std::set<std::uint32_t> first;
    for (int step = 0; step < 100; ++step) {
        const auto m = run(floor, at(Vec3::Zero()), cube, at(Vec3(-0.5 + 0.01 * step, 0.99, 0)));
        ASSERT_EQ(m.size(), 1u);
        std::set<std::uint32_t> now;
        for (int i = 0; i < m[0].point_count; ++i) now.insert(m[0].points[i].id);
        if (step == 0) first = now;
        EXPECT_EQ(now, first) << "step " << step;
    }
}

TEST(BoxHull, MatchesBoxBox) {
    const Shape box = Shape::box(Vec3(0.5, 0.5, 0.5));
    const Shape floor_box = Shape::box(Vec3(2, 0.5, 2));
    const Shape floor_hull = test::hull_box(Vec3(2, 0.5, 2));
    const Transform xa = at(Vec3(0.2, 0.97, 0.1), about(Vec3(0.1, 1, 0.2), 0.5));
    const auto expected = run(box, xa, floor_box, at(Vec3::Zero()));
    const auto actual = run(box, xa, floor_hull, at(Vec3::Zero()));
    ASSERT_EQ(expected.size(), 1u);
    ASSERT_EQ(actual.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(actual[0].normal, expected[0].normal, 1e-12);
    ASSERT_EQ(actual[0].point_count, expected[0].point_count);
    for (int i = 0; i < actual[0].point_count; ++i) {
        EXPECT_TRUE(test::has_point(expected[0], actual[0].points[i].point, 1e-9));
    }
}

TEST(HullCapsule, SwappedOrderFlipsTheNormal) {
    const Shape hull = tetrahedron_point_down();
    const Shape capsule = Shape::capsule(0.5, 0.2);
    const Transform xh = at(Vec3::Zero(), about(Vec3(1, 0, 1), 0.3));
    const Transform xc = at(Vec3(0.1, 1.25, 0), about(Vec3::UnitZ(), 1.2));
    test::expect_swapped_order_flips(capsule, xc, hull, xh);
}

TEST(HullSphere, SphereOnTetrahedronVertexUsesTheVertexDirection) {
    // Sphere below the apex, off to the side: the normal points from the sphere centre at the apex.
    const Vec3 c(0.3, -0.4, 0);
    const auto m = run(Shape::sphere(0.6), at(c), tetrahedron_point_down(), at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(-c.normalized()), 1e-9);
    EXPECT_NEAR(m[0].points[0].separation, 0.5 - 0.6, 1e-9);
}

}  // namespace
}  // namespace spindle
