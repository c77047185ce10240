// Checks shared by the box and hull tests: the same scenes must give the same contacts
// whichever code path (dedicated box SAT or general polyhedron SAT) handles them.
#include "collision_test_util.hpp"

#include <cmath>
#include <set>

namespace spindle::test {

void expect_resting_cube_contact(const Shape& floor, const Shape& cube) {
    const auto m = run(floor, at(Vec3::Zero()), cube, at(Vec3(0.3, 0.99, -0.2)));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-12);
    ASSERT_EQ(m[0].point_count, 4);
    for (const Real x : {-0.2, 0.8}) {
        for (const Real z : {-0.7, 0.3}) EXPECT_TRUE(has_point(m[0], Vec3(x, 0.495, z), 1e-12));
    }
    std::set<std::uint32_t> ids;
    for (int i = 0; i < 4; ++i) {
        EXPECT_NEAR(m[0].points[i].separation, -0.01, 1e-12);
        ids.insert(m[0].points[i].id);
    }
    EXPECT_EQ(ids.size(), 4u);
}

void expect_crossed_edges_contact(const Shape& cube) {
    // A's top edge runs along z at height sqrt 2; B's bottom edge along x, 0.1 lower.
    const Real s2 = std::sqrt(2.0);
    const auto m = run(cube, at(Vec3::Zero(), about(Vec3::UnitZ(), kPi / 4)), cube,
                       at(Vec3(0, 2 * s2 - 0.1, 0), about(Vec3::UnitX(), kPi / 4)));
    ASSERT_EQ(m.size(), 1u);
    ASSERT_EQ(m[0].point_count, 1);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-9);
    EXPECT_NEAR(m[0].points[0].separation, -0.1, 1e-9);
    SPINDLE_EXPECT_VEC_NEAR(m[0].points[0].point, Vec3(0, s2 - 0.05, 0), 1e-9);
    EXPECT_EQ(m[0].points[0].id >> 30, 2u);  // an edge-edge id
}

void expect_swapped_order_flips(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb) {
    const auto ab = run(a, xa, b, xb);
    const auto ba = run(b, xb, a, xa);
    ASSERT_EQ(ab.size(), 1u);
    ASSERT_EQ(ba.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(ab[0].normal, Vec3(-ba[0].normal), 1e-12);
    ASSERT_EQ(ab[0].point_count, ba[0].point_count);
    for (int i = 0; i < ab[0].point_count; ++i) EXPECT_TRUE(has_point(ba[0], ab[0].points[i].point, 1e-12));
}

}  // namespace spindle::test
