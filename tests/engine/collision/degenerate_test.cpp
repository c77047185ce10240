// Degenerate input: coincident centres, identical poses, zero-thickness hulls and
// zero-area triangles give clean results or clear errors, never NaN or a crash.
#include <gtest/gtest.h>

#include <vector>

#include <spindle/platform/error.hpp>

#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;
using test::run;

std::vector<Shape> all_shapes() {
    const std::vector<Vec3> tri_vertices{Vec3(-1, 0, -1), Vec3(-1, 0, 1), Vec3(1, 0, 1), Vec3(1, 0, 1)};
    return {Shape::sphere(0.5),
            Shape::capsule(0.5, 0.3),
            Shape::box(Vec3(0.5, 0.4, 0.3)),
            test::hull_box(Vec3(0.4, 0.5, 0.6)),
            Shape::plane(Vec3::UnitY(), 0),
            Shape::triangle_mesh(tri_vertices, std::vector<std::uint32_t>{0, 1, 2, 1, 2, 3})};
}

TEST(Degenerate, CoincidentSpheresPickADeterministicNormal) {
    const auto m = run(Shape::sphere(1), at(Vec3(1, 2, 3)), Shape::sphere(0.5), at(Vec3(1, 2, 3)));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-15);
    EXPECT_DOUBLE_EQ(m[0].points[0].separation, -1.5);
}

TEST(Degenerate, IdenticalBoxesAndCapsulesPushApartAlongAnAxis) {
    const Transform x = at(Vec3(0.5, 1, -2), about(Vec3(1, 2, 3), 0.4));
    const auto boxes = run(Shape::box(Vec3(1, 1, 1)), x, Shape::box(Vec3(1, 1, 1)), x);
    ASSERT_EQ(boxes.size(), 1u);
    EXPECT_NEAR(deepest(boxes[0]), -2, 1e-9);
    const auto capsules = run(Shape::capsule(1, 0.5), x, Shape::capsule(1, 0.5), x);
    ASSERT_EQ(capsules.size(), 1u);
    EXPECT_NEAR(deepest(capsules[0]), -1, 1e-12);
    EXPECT_NEAR(capsules[0].normal.dot(x.rotate(Vec3::UnitY())), 0, 1e-12);  // across the axis
}

TEST(Degenerate, EveryPairAtIdenticalPosesIsFinite) {
    // run() checks every normal, point and separation for NaN and range.
    const std::vector<Shape> shapes = all_shapes();
    for (const Transform& x : {at(Vec3::Zero()), at(Vec3(0.3, -0.2, 0.1), about(Vec3(1, 1, 0), 0.8))}) {
        for (const Shape& a : shapes) {
            for (const Shape& b : shapes) {
                SCOPED_TRACE(std::string(to_string(a.type)) + " vs " + to_string(b.type));
                const auto m = run(a, x, b, x, 0.01);
                if (!a.static_only() || !b.static_only()) {
                    EXPECT_FALSE(m.empty());
                }
            }
        }
    }
}

TEST(Degenerate, SphereCentreOnCapsuleAxisAndInsideHull) {
    const auto m = run(Shape::sphere(0.2), at(Vec3(0, 0.3, 0)), Shape::capsule(0.5, 0.3), at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    EXPECT_NEAR(m[0].points[0].separation, -0.5, 1e-12);
    const auto h = run(Shape::sphere(0.2), at(Vec3(0, 0, 0)), test::hull_box(Vec3(1, 2, 3)), at(Vec3::Zero()));
    ASSERT_EQ(h.size(), 1u);
    EXPECT_NEAR(std::abs(h[0].normal.x()), 1, 1e-12);  // out through the nearest face, x = +-1
    EXPECT_NEAR(deepest(h[0]), -1.2, 1e-12);
}

TEST(Degenerate, ZeroThicknessHullIsRejectedAtBuild) {
    const std::vector<Vec3> flat{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 1)};
    EXPECT_THROW(Shape::convex_hull(flat), Error);
}

TEST(Degenerate, ZeroAreaTriangleIsDroppedAndNeverCollides) {
    // The sliver sits right under the sphere; only the real triangle far away remains.
    const std::vector<Vec3> v{Vec3(0, 0, 0),  Vec3(1, 0, 0),  Vec3(2, 0, 0),
                              Vec3(10, 0, 0), Vec3(10, 0, 1), Vec3(11, 0, 0)};
    const Shape mesh = Shape::triangle_mesh(v, std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5});
    EXPECT_EQ(mesh.mesh->triangles().size(), 1u);
    EXPECT_TRUE(run(Shape::sphere(0.5), at(Vec3(1, 0.2, 0)), mesh, at(Vec3::Zero())).empty());
}

}  // namespace
}  // namespace spindle
