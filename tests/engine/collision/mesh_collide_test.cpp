// Convex shapes against triangle meshes: one merged manifold on flat ground, no ghost
// normals at the seams between triangles, edge normals on real ridges, several
// manifolds in a valley (deepest first, capped by capacity).
#include <gtest/gtest.h>

#include <cmath>

#include "collision/pair_functions.hpp"
#include "collision/polyhedron.hpp"
#include "collision/sat_prepared.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;
using test::run;

// n x n unit quads in y = 0 from (0, 0) to (n, n), two triangles each, facing +y.
Shape unit_grid(int n) {
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    for (int z = 0; z <= n; ++z) {
        for (int x = 0; x <= n; ++x) v.emplace_back(x, 0, z);
    }
    const auto at_ = [n](int x, int z) { return static_cast<std::uint32_t>(z * (n + 1) + x); };
    for (int z = 0; z < n; ++z) {
        for (int x = 0; x < n; ++x) {
            idx.insert(idx.end(), {at_(x, z), at_(x, z + 1), at_(x + 1, z + 1)});
            idx.insert(idx.end(), {at_(x, z), at_(x + 1, z + 1), at_(x + 1, z)});
        }
    }
    return Shape::triangle_mesh(v, idx);
}

// A V-shaped valley along z: two planes at 45 degrees meeting at x = 0, y = 0.
Shape valley() {
    const std::vector<Vec3> v{Vec3(-2, 2, -2), Vec3(-2, 2, 2), Vec3(0, 0, -2),
                              Vec3(0, 0, 2),   Vec3(2, 2, -2), Vec3(2, 2, 2)};
    const std::vector<std::uint32_t> idx{0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};
    return Shape::triangle_mesh(v, idx);
}

TEST(ConvexMesh, SphereOnASeamVertexGetsOneFaceNormal) {
    const auto m = run(Shape::sphere(0.5), at(Vec3(2, 0.45, 2)), unit_grid(4), at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-9);
    EXPECT_NEAR(deepest(m[0]), -0.05, 1e-9);
}

TEST(ConvexMesh, BoxOnGridMergesIntoOneFourPointManifold) {
    const auto m = run(Shape::box(Vec3(0.7, 0.5, 0.6)), at(Vec3(2.1, 0.49, 1.9)), unit_grid(4), at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-9);
    ASSERT_EQ(m[0].point_count, 4);
    for (const Real x : {1.4, 2.8}) {
        for (const Real z : {1.3, 2.5}) EXPECT_TRUE(test::has_point(m[0], Vec3(x, -0.005, z), 1e-9));
    }
}

// A face lying across two triangles, tilted a little along both its sides (as a rolling
// log's face lands), keeps its four corners: the triangles' manifolds merge into one whose
// points are chosen from all of theirs, whatever the order the triangles come in. Reduced
// at each merge, the far corner of the low side was lost to a point on the triangles'
// shared edge x = 4 that had come first and lay barely deeper.
TEST(ConvexMesh, AFaceAcrossTwoTrianglesKeepsItsFourCorners) {
    const Shape ground = unit_grid(8);
    const Vec3 h(0.375, 0.5, 1.5);
    for (const Shape& shape : {Shape::box(h), test::hull_box(h)}) {
        for (const Real tilt : {0.0003, 0.0006, -0.0003, -0.0006}) {
            // The z = +1.5 side 2.6 cm lower than the other, 1 mm into the ground.
            const Quat q = about(Vec3::UnitX(), 0.026 / 3) * about(Vec3::UnitZ(), tilt);
            const Transform xa = at(Vec3(4.25, 0.512, 4), q);
            const auto m = run(shape, xa, ground, at(Vec3::Zero()), 0.04);
            ASSERT_EQ(m.size(), 1u) << "tilt " << tilt;
            ASSERT_EQ(m[0].point_count, 4) << "tilt " << tilt;
            for (const Real x : {-h.x(), h.x()}) {
                for (const Real z : {-h.z(), h.z()}) {
                    const Vec3 corner = xa.apply(Vec3(x, -h.y(), z));
                    bool kept = false;
                    for (int i = 0; i < m[0].point_count; ++i) {
                        const Vec3& p = m[0].points[i].point;
                        kept = kept || (std::abs(p.x() - corner.x()) < 1e-3 && std::abs(p.z() - corner.z()) < 1e-3);
                    }
                    EXPECT_TRUE(kept) << "tilt " << tilt << ": corner (" << corner.x() << ", " << corner.z() << ")";
                }
            }
        }
    }
}

TEST(ConvexMesh, SlidingBoxNeverCatchesOnInteriorEdges) {
    const Shape ground = unit_grid(6);
    const Shape box = Shape::box(Vec3(0.3, 0.3, 0.3));
    for (int step = 0; step < 100; ++step) {
        const Transform xb = at(Vec3(1.05 + 0.04 * step, 0.295, 3.0), about(Vec3::UnitY(), 0.3));
        const auto m = run(box, xb, ground, at(Vec3::Zero()));
        ASSERT_EQ(m.size(), 1u) << "step " << step;
        SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-9);
        EXPECT_NEAR(deepest(m[0]), -0.005, 1e-9) << "step " << step;
    }
}

TEST(ConvexMesh, RollingCapsuleAndHullStayOnFaceNormals) {
    const Shape ground = unit_grid(4);
    const Shape capsule = Shape::capsule(0.6, 0.2);
    const Shape hull = test::hull_box(Vec3(0.3, 0.2, 0.4));
    for (int step = 0; step < 40; ++step) {
        const Real x = 0.7 + 0.05 * step;
        const auto mc = run(capsule, at(Vec3(x, 0.19, 2), about(Vec3::UnitX(), kPi / 2)), ground, at(Vec3::Zero()));
        ASSERT_EQ(mc.size(), 1u);
        SPINDLE_EXPECT_VEC_NEAR(mc[0].normal, Vec3(0, -1, 0), 1e-9);
        EXPECT_EQ(mc[0].point_count, 2);
        const auto mh = run(hull, at(Vec3(x, 0.19, 2)), ground, at(Vec3::Zero()));
        ASSERT_EQ(mh.size(), 1u);
        SPINDLE_EXPECT_VEC_NEAR(mh[0].normal, Vec3(0, -1, 0), 1e-9);
        EXPECT_EQ(mh[0].point_count, 4);
    }
}

// A long body's end coming down on the flat mesh from well within a large speculative
// distance (a fast-turning pole's end, h50 in docs/benchmarks.md): every triangle the
// reach finds, beside the end as well as under it, must give the face normal and a gap no
// less than the end's true height. The SAT's axis for a triangle beside the end is a
// sideways one; its points lay off both shapes and measured the gap as zero, or, with the
// side taken from a slanted end face, as a depth below the mesh with the normal upwards.
TEST(ConvexMesh, CornerFarAboveTheMeshGetsItsHeightWithinALargeReach) {
    std::vector<Vec3> prism;
    for (int k = 0; k < 6; ++k) {
        for (const Real y : {-1.0, 1.0})
            prism.emplace_back(0.25 * std::cos(k * kPi / 3), y, 0.25 * std::sin(k * kPi / 3));
    }
    const Shape segment = Shape::convex_hull(prism);
    const Shape cube = test::hull_box(Vec3(0.4, 0.4, 0.4));
    const Shape box = Shape::box(Vec3(0.4, 0.4, 0.4));
    const Shape ground = unit_grid(8);
    constexpr Real kReach = 1.2;
    struct Body {
        const Shape* shape;
        Quat q;
    };
    const Body bodies[] = {
        {&segment, about(Vec3::UnitZ(), -kPi / 2 - 0.1)},          // lying along x, its +x end lower
        {&cube, about(Vec3(1, 0, 1), std::atan(std::sqrt(2.0)))},  // a corner straight down
        {&box, about(Vec3(1, 0, 1), std::atan(std::sqrt(2.0)))},
        {&cube, about(Vec3(1, 0.3, -0.5), 0.6)},  // a corner, tilted
    };
    for (const Body& body : bodies) {
        for (const Vec3& over : {Vec3(4, 0, 4.1), Vec3(4.3, 0, 3.8), Vec3(4.55, 0, 4.45)}) {
            for (const Real height : {0.05, 0.1, 0.16, 0.3, 0.6, 0.9, 1.0}) {
                const Transform x = at(over, body.q);
                const Real lowest = body.shape->bounds(x).min.y();
                const auto m = run(*body.shape, at(over + Vec3(0, height - lowest, 0), body.q), ground,
                                   at(Vec3::Zero()), kReach);
                ASSERT_EQ(m.size(), 1u) << "height " << height << " over " << over.transpose();
                SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-9);
                EXPECT_NEAR(deepest(m[0]), height, 1e-9) << "over " << over.transpose();
            }
        }
    }
}

// A shape pushed into the mesh's front past the middle of its depth, its centre still in
// front of the plane, is pushed back out of the front: the triangles count as one-sided for
// it. Two-sided, an edge axis or the triangle's back face could win the SAT and push it on
// through (issue 19: tree tops and pole ends sinking into the trees' mesh).
TEST(ConvexMesh, ShapeDeepInTheFrontWithItsCentreInFrontIsPushedOutOfTheFront) {
    std::vector<Vec3> prism;
    for (int k = 0; k < 6; ++k) {
        for (const Real y : {-1.0, 1.0})
            prism.emplace_back(0.25 * std::cos(k * kPi / 3), y, 0.25 * std::sin(k * kPi / 3));
    }
    // A pyramid, apex down, its centroid (a quarter of its height above its base) at its
    // origin and the middle of its height under it: the triangle's back face can win the
    // SAT while the centroid is still in front.
    const Shape pyramid = Shape::convex_hull(std::vector<Vec3>{
        Vec3(0, -0.9, 0), Vec3(-0.5, 0.3, -0.5), Vec3(0.5, 0.3, -0.5), Vec3(-0.5, 0.3, 0.5), Vec3(0.5, 0.3, 0.5)});
    const Shape shapes[] = {Shape::convex_hull(prism), test::hull_box(Vec3(0.4, 0.4, 0.4)),
                            Shape::box(Vec3(0.6, 0.3, 0.4)), Shape::capsule(0.8, 0.3), pyramid};
    const Quat turns[] = {Quat::Identity(), about(Vec3::UnitZ(), -kPi / 2 - 0.1),
                          about(Vec3(1, 0, 1), std::atan(std::sqrt(2.0))), about(Vec3(1, 0.3, -0.5), 0.6),
                          about(Vec3(0.2, 1, 0.7), 1.1)};
    const Shape ground = unit_grid(8);
    int checked = 0;
    for (const Shape& shape : shapes) {
        for (const Quat& q : turns) {
            for (const Vec3& over : {Vec3(4, 0, 4.1), Vec3(4.3, 0, 3.8), Vec3(4.55, 0, 4.45)}) {
                const Real lowest = shape.bounds(at(over, q)).min.y();
                // The centre from just above the plane to nearly as high as the shape reaches
                // down from it: the shape always lies across the plane, its centre in front.
                for (const Real share : {0.05, 0.2, 0.4, 0.6, 0.8, 0.95}) {
                    const Real height = -lowest * share;
                    const auto m = run(shape, at(over + Vec3(0, height, 0), q), ground, at(Vec3::Zero()));
                    ASSERT_FALSE(m.empty());
                    for (const Manifold& manifold : m) {
                        EXPECT_TRUE(manifold.normal.isApprox(Vec3(0, -1, 0), 1e-9))
                            << "centre " << height << " up, its lowest point " << lowest + height << " over "
                            << over.transpose() << ": normal " << manifold.normal.transpose();
                        // Measured against the front face from the shape's deep side: each
                        // point midway between the shape's surface under the plane and the
                        // plane, no deeper than the shape's lowest point.
                        for (int i = 0; i < manifold.point_count; ++i) {
                            const ManifoldPoint& p = manifold.points[i];
                            EXPECT_NEAR(p.separation, 2 * p.point.y(), 1e-9);
                            EXPECT_GE(p.separation, lowest + height - 1e-9);
                            EXPECT_LT(p.separation, 0);
                        }
                    }
                    ++checked;
                }
            }
        }
    }
    EXPECT_EQ(checked, 5 * 5 * 3 * 6);
}

// Past the middle, a shape lying across the plane with its centre behind gets no contact
// from the triangles (pushed on out of their backs it would lever its body about parts
// still in front); one wholly behind, within reach, is pushed on out of the back.
TEST(ConvexMesh, ShapeAcrossTheMeshWithItsCentreBehindGetsNothingAndOneWhollyBehindGoesOutTheBack) {
    const Shape ground = unit_grid(8);
    const Quat q = about(Vec3(1, 0.3, -0.5), 0.6);
    for (const Shape& shape : {Shape::box(Vec3(0.6, 0.3, 0.4)), test::hull_box(Vec3(0.4, 0.4, 0.4)),
                               Shape::capsule(0.8, 0.3), Shape::sphere(0.4)}) {
        const Vec3 over(4.3, 0, 3.8);
        const Real highest = shape.bounds(at(over, q)).max.y();
        for (const Real share : {0.05, 0.5, 0.95})
            EXPECT_TRUE(run(shape, at(over - Vec3(0, highest * share, 0), q), ground, at(Vec3::Zero())).empty())
                << to_string(shape.type) << " centre " << highest * share << " under";
        const auto m = run(shape, at(over - Vec3(0, highest + 0.01, 0), q), ground, at(Vec3::Zero()), 0.05);
        ASSERT_FALSE(m.empty()) << to_string(shape.type);
        SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-9);
        EXPECT_NEAR(deepest(m[0]), 0.01, 1e-9);
    }
}

TEST(ConvexMesh, SphereOnARidgeTakesTheEdgeNormal) {
    // Roof ridge along x at y = 1: a sharp (active) edge.
    const std::vector<Vec3> v{Vec3(-2, 1, 0), Vec3(2, 1, 0),  Vec3(-2, 0, -1),
                              Vec3(2, 0, -1), Vec3(-2, 0, 1), Vec3(2, 0, 1)};
    const Shape roof = Shape::triangle_mesh(v, std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2, 1, 0, 4, 1, 4, 5});
    const auto m = run(Shape::sphere(0.5), at(Vec3(0, 1.45, 0)), roof, at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, -1, 0), 1e-9);
    EXPECT_NEAR(deepest(m[0]), -0.05, 1e-9);
}

TEST(ConvexMesh, SphereInAValleyGetsTwoManifoldsDeepestFirst) {
    const Shape v = valley();
    // Closer to the right slope (x > 0) than to the left one.
    const Vec3 c(0.1, 0.6, 0);
    const auto m = run(Shape::sphere(0.5), at(c), v, at(Vec3::Zero()));
    ASSERT_EQ(m.size(), 2u);
    const Vec3 right = Vec3(1, -1, 0).normalized(), left = Vec3(-1, -1, 0).normalized();
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, right, 1e-9);
    SPINDLE_EXPECT_VEC_NEAR(m[1].normal, left, 1e-9);
    EXPECT_NEAR(deepest(m[0]), (c.y() - c.x()) / std::sqrt(2.0) - 0.5, 1e-9);
    EXPECT_NEAR(deepest(m[1]), (c.y() + c.x()) / std::sqrt(2.0) - 0.5, 1e-9);
    const auto capped = run(Shape::sphere(0.5), at(c), v, at(Vec3::Zero()), 0, 1);
    ASSERT_EQ(capped.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(capped[0].normal, right, 1e-9);
}

TEST(ConvexMesh, SwappedOrderFlipsAndFarAwayGivesNothing) {
    const Shape ground = unit_grid(2);
    const auto m = run(ground, at(Vec3::Zero()), Shape::sphere(0.5), at(Vec3(1, 0.4, 1)));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-9);
    EXPECT_TRUE(run(Shape::sphere(0.5), at(Vec3(1, 0.6, 1)), ground, at(Vec3::Zero())).empty());
    EXPECT_TRUE(run(Shape::sphere(0.5), at(Vec3(10, 0, 1)), ground, at(Vec3::Zero())).empty());
}

TEST(ConvexMesh, MovedAndRotatedMeshKeepsWorldResults) {
    const Quat q = about(Vec3(1, 0, 1), 0.7);
    const Transform xm = at(Vec3(3, -1, 2), q);
    const Vec3 c = xm.apply(Vec3(1, 0.45, 1));
    const auto m = run(Shape::sphere(0.5), at(c), unit_grid(2), xm);
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(q * Vec3(0, -1, 0)), 1e-9);
    EXPECT_NEAR(deepest(m[0]), -0.05, 1e-9);
}

// A cube rolled 30 degrees about z, its lowest edge 0.1 deep in the triangle's plane but
// 5 cm beside its long side: measured over the triangle's face, the incident face (the
// cube's bottom, turned to face down and right) lies wholly beside the triangle and clips to
// nothing, and the deepest vertex is beside it too; the face turned down and left leans back
// over the triangle and is what lies there. Its one corner within reach, where it crosses the
// triangle's side at the triangle's corner, is the manifold's.
TEST(ConvexMesh, AFaceOverTheTriangleIsMeasuredWhenTheIncidentFaceLiesBesideIt) {
    const Real turn = kPi / 6;
    const Real beside = 0.05, depth = -0.1;
    // The cube's lowest edge, local (-0.5, -0.5, z), turned: (-0.183, -0.683, z).
    const Vec3 lowest = Vec3(-0.5 * std::cos(turn) + 0.5 * std::sin(turn), -0.5 * std::sin(turn) - 0.5 * std::cos(turn),
                             0);
    const Transform xa = at(Vec3(1 + beside, depth, 0.3) - lowest, about(Vec3::UnitZ(), turn));
    const detail::BoxPoly cube(Vec3(0.5, 0.5, 0.5));
    const detail::PreparedPolyhedron prepared(cube.view());
    // Corners (0, 0, 0), (0, 0, 1), (1, 0, 0): facing +y, its long side on x + z = 1.
    const detail::TrianglePoly triangle(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 0));
    ASSERT_NEAR(triangle.normal().y(), 1.0, 1e-12);
    const Transform identity;
    Manifold m;
    ASSERT_TRUE(
        detail::face_of_b_manifold(prepared, xa, triangle.view(), detail::RelativePose(xa, identity), 0, 0.02, m));
    SPINDLE_EXPECT_VEC_NEAR(m.normal, Vec3(0, -1, 0), 1e-12);
    ASSERT_EQ(m.point_count, 1);
    // The face rises at 60 degrees from the lowest edge: at x = 1 it is beside * tan(60) higher.
    const Real expected = depth + beside * std::tan(kPi / 3);
    EXPECT_NEAR(m.points[0].separation, expected, 1e-9);
    SPINDLE_EXPECT_VEC_NEAR(m.points[0].point, Vec3(1, 0.5 * expected, 0), 1e-9);
}

bool same_bits(const Manifold& a, const Manifold& b) {
    if (a.point_count != b.point_count || a.normal != b.normal) return false;
    for (int k = 0; k < a.point_count; ++k) {
        if (a.points[k].point != b.points[k].point || a.points[k].separation != b.points[k].separation ||
            a.points[k].id != b.points[k].id)
            return false;
    }
    return true;
}

void expect_same_bits(const Manifold& got, const Manifold& expected, int pose) {
    for (int i = 0; i < 3; ++i) EXPECT_EQ(got.normal[i], expected.normal[i]) << "pose " << pose;
    ASSERT_EQ(got.point_count, expected.point_count) << "pose " << pose;
    for (int k = 0; k < got.point_count; ++k) {
        for (int i = 0; i < 3; ++i) EXPECT_EQ(got.points[k].point[i], expected.points[k].point[i]) << "pose " << pose;
        EXPECT_EQ(got.points[k].separation, expected.points[k].separation) << "pose " << pose;
        EXPECT_EQ(got.points[k].id, expected.points[k].id) << "pose " << pose;
    }
}

// collide_polyhedron_triangle is collide_polyhedra followed, when the mesh's rule asks, by
// face_of_b_manifold over the triangle's face, in one posing of the triangle; with a rule that
// reads the normal alone it makes no points the rule throws away. A hull and a box drift and
// turn across a tilted triangle, each with its own cache carried from pose to pose both ways:
// the answers, manifolds and caches must be the two calls', bit for bit, for a rule on the
// normal (asked before any point is made) and one on the points. Under the rule on the normal,
// a cache that keeps the face measured over may have it measured over again without the SAT
// (AKeptTriangleFacePastTheSlopIsMeasuredOverItWithoutTheSat): there the one call may be
// face_of_b_manifold's alone, to the bit, and both caches go on from it.
TEST(ConvexMesh, ATriangleMeasuredAgainInOnePosingIsTheTwoCallsToTheBit) {
    std::vector<Vec3> cloud;
    for (int i = 0; i < 12; ++i)
        cloud.emplace_back(std::cos(i * 1.3) * 0.4, std::sin(i * 2.1) * 0.3, std::cos(i * 0.7) * 0.5);
    const Shape hull = Shape::convex_hull(cloud);
    const detail::BoxPoly box(Vec3(0.3, 0.4, 0.5));
    const detail::PreparedPolyhedron shapes[] = {detail::PreparedPolyhedron(detail::view_of(*hull.hull)),
                                                 detail::PreparedPolyhedron(box.view())};
    const Transform xm = at(Vec3(0.1, -0.05, 0.2), about(Vec3(1, 0, 2), 0.3));
    const detail::TrianglePoly triangle(Vec3(-1, 0, -1), Vec3(-0.5, 0.2, 1.5), Vec3(1.5, -0.1, -0.5));
    const Vec3 up = xm.rotate(triangle.normal());
    int normal_only = 0, measured = 0, touching = 0, kept_face = 0;
    for (const bool on_points : {false, true}) {
        for (const detail::PreparedPolyhedron& shape : shapes) {
            FeatureCache kept_two, kept_one;
            for (int pose = 0; pose < 400; ++pose) {
                const Real s = 0.01 * pose;
                const Transform xa =
                    at(xm.apply(Vec3(std::sin(3 * s) - 0.2, 0.3 + 0.3 * std::sin(7 * s), std::cos(2 * s))),
                       about(Vec3(std::sin(s), 1, std::cos(5 * s)), 4 * s));
                const detail::RelativePose triangle_in_a(xa, xm);
                const std::uint32_t face = pose % 7 == 0 ? 1 : 0;
                // The rules' normals are in the world here (xa places the shape there).
                const auto again = [&](const Manifold& m) {
                    if (m.point_count == 0) ++normal_only;
                    if (!on_points) return m.normal.dot(up) > -0.95;
                    for (int k = 0; k < m.point_count; ++k)
                        if (m.points[k].separation < -0.02) return true;
                    return false;
                };
                Manifold two, one;
                bool two_touch = detail::collide_polyhedra(shape, xa, triangle.view(), triangle_in_a, 0.05, two,
                                                           &kept_two, 0.005);
                const bool two_again = two_touch && again(two);
                if (two_again)
                    two_touch = detail::face_of_b_manifold(shape, xa, triangle.view(), triangle_in_a, face, 0.05, two,
                                                           &kept_two);
                const detail::FaceMeasure measure{face, on_points, again};
                // Under the rule on the normal, a kept face measured over may be measured over
                // again without the SAT: the one call is then face_of_b_manifold's alone.
                const bool face_kept = !on_points && kept_one.kind() == FeatureCache::Kind::FaceB &&
                                       kept_one.index_b() == face;
                FeatureCache kept_over = kept_one;
                Manifold over;
                const bool over_touch = face_kept &&
                                        detail::face_of_b_manifold(shape, xa, triangle.view(), triangle_in_a, face,
                                                                   0.05, over, &kept_over);
                const bool one_touch = detail::collide_polyhedron_triangle(shape, xa, triangle.view(), triangle_in_a,
                                                                           0.05, one, &kept_one, 0.005, measure);
                if (over_touch && one_touch && kept_one == kept_over && same_bits(one, over)) {
                    kept_two = kept_one;
                    ++kept_face;
                    continue;
                }
                ASSERT_EQ(one_touch, two_touch) << "pose " << pose;
                EXPECT_TRUE(kept_one == kept_two) << "pose " << pose;
                measured += two_again;
                touching += two_touch;
                if (two_touch) expect_same_bits(one, two, pose);
            }
        }
    }
    EXPECT_GT(normal_only, 100);
    EXPECT_GT(measured, 100);
    EXPECT_GT(touching, 400);
    EXPECT_GT(kept_face, 100);
}

// A triangle's face kept (the mesh's rule had the contact measured over it), whose separation
// has moved past the slop, is measured over that face again instead of chosen anew by the whole
// SAT, on a triangle whose rule reads the normal alone: the SAT would mostly choose an edge or a
// face of the hull that the rule sends back to the same face. A log lies at 30 degrees, its
// centre in front of the triangle and its lower end under it, 0.3 m and more below the face: the
// SAT finds it apart (its top face has the triangle 0.15 m above it), yet what lies under the
// triangle is measured over the kept face, deep, as face_of_b_manifold measures it, and the face
// stays kept.
TEST(ConvexMesh, AKeptTriangleFacePastTheSlopIsMeasuredOverItWithoutTheSat) {
    const detail::BoxPoly log(Vec3(1.0, 0.1, 0.1));
    const detail::PreparedPolyhedron prepared(log.view());
    // Corners (0, 0, 0), (0, 0, 1), (1, 0, 0): facing +y.
    const detail::TrianglePoly triangle(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 0));
    ASSERT_NEAR(triangle.normal().y(), 1.0, 1e-12);
    const Real tilt = kPi / 6;
    const Vec3 along(std::cos(tilt), -std::sin(tilt), 0), up(std::sin(tilt), std::cos(tilt), 0);
    // The log's top face crosses the triangle's plane at x = -0.3, 0.3 before the triangle's
    // edge; its centre lies 0.3 back along the log from there.
    const Vec3 centre = Vec3(-0.3, 0, 0.3) - 0.3 * along - 0.1 * up;
    ASSERT_GT(centre.y(), 0);
    const Transform xa = at(centre, about(Vec3::UnitZ(), -tilt));
    const Transform identity;
    const detail::RelativePose triangle_in_a(xa, identity);
    Manifold sat;
    FeatureCache fresh;
    ASSERT_FALSE(detail::collide_polyhedra(prepared, xa, triangle.view(), triangle_in_a, 0.05, sat, &fresh, 0.005));
    Manifold over;
    ASSERT_TRUE(detail::face_of_b_manifold(prepared, xa, triangle.view(), triangle_in_a, 0, 0.05, over));
    ASSERT_GT(over.point_count, 0);
    EXPECT_LT(deepest(over), -0.3);
    // The mesh's rule for a triangle with no active edge: measured over the face unless the
    // normal is the face's.
    const auto again = [](const Manifold& m) { return std::abs(m.normal.y()) < 1 - 1e-6; };
    const detail::FaceMeasure measure{0, false, again};
    FeatureCache kept(FeatureCache::Kind::FaceB, 0, 0, -0.005f);  // as it lay on the face
    Manifold m;
    ASSERT_TRUE(detail::collide_polyhedron_triangle(prepared, xa, triangle.view(), triangle_in_a, 0.05, m, &kept, 0.005,
                                                    measure));
    expect_same_bits(m, over, 0);
    EXPECT_EQ(kept.kind(), FeatureCache::Kind::FaceB);
    EXPECT_EQ(kept.index_b(), 0u);
}

TEST(ConvexMesh, RandomPosesGiveWellFormedManifolds) {
    // run() checks every normal, point and separation; the mesh mixes flat seams, a
    // ridge and a valley.
    const std::vector<Vec3> v{Vec3(-2, 0, -2), Vec3(-2, 0, 2), Vec3(0, 1, -2), Vec3(0, 1, 2),
                              Vec3(2, 0, -2),  Vec3(2, 0, 2),  Vec3(4, 1, -2), Vec3(4, 1, 2)};
    const Shape mesh =
        Shape::triangle_mesh(v, std::vector<std::uint32_t>{0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4, 4, 5, 7, 4, 7, 6});
    std::vector<Vec3> cloud;
    for (int i = 0; i < 12; ++i)
        cloud.emplace_back(std::cos(i * 1.3) * 0.4, std::sin(i * 2.1) * 0.3, std::cos(i * 0.7) * 0.5);
    const Shape shapes[] = {Shape::sphere(0.4), Shape::capsule(0.4, 0.2), Shape::box(Vec3(0.3, 0.4, 0.5)),
                            Shape::convex_hull(cloud)};
    unsigned seed = 3;
    const auto rnd = [&seed] {
        seed = seed * 1664525u + 1013904223u;
        return Real(seed >> 8) / Real(1 << 24) * 2 - 1;
    };
    int hits = 0;
    for (const Shape& s : shapes) {
        for (int trial = 0; trial < 100; ++trial) {
            const Transform x = at(Vec3(1 + 3 * rnd(), 0.5 + 0.6 * rnd(), 1.5 * rnd()),
                                   about(Vec3(rnd(), rnd(), rnd()), 3 * rnd()));
            const auto m = run(s, x, mesh, at(Vec3::Zero()), 0.05, 4);
            hits += m.empty() ? 0 : 1;
            for (std::size_t i = 1; i < m.size(); ++i) EXPECT_LE(deepest(m[i - 1]), deepest(m[i]));
        }
    }
    EXPECT_GT(hits, 100);
}

}  // namespace
}  // namespace spindle
