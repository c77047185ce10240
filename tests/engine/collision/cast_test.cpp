// Ray casts, shape casts and overlap tests against analytic answers for every shape type,
// in turned and moved poses, with misses, grazing contacts, starts inside and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "collision/cast.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;

const Real kSqrt2 = std::sqrt(Real(2));
const Real kSqrt3 = std::sqrt(Real(3));

// The sweep stops at most 1e-5 m short of the contact and never past it.
constexpr Real kSweepSlack = 1e-5;

Shape octahedron() {
    const std::vector<Vec3> p = {Vec3(1, 0, 0),  Vec3(-1, 0, 0), Vec3(0, 1, 0),
                                 Vec3(0, -1, 0), Vec3(0, 0, 1),  Vec3(0, 0, -1)};
    return Shape::convex_hull(p);
}

// An n x n grid of unit squares in the xz plane at height y, centred on the origin, two
// counter-clockwise (seen from +y) triangles per square; height(x, z) lifts the vertices.
template <typename Height>
Shape grid(int n, Height height) {
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    const Real half = Real(n) / 2;
    for (int i = 0; i <= n; ++i) {
        for (int k = 0; k <= n; ++k) v.emplace_back(i - half, height(i - half, k - half), k - half);
    }
    const auto at_ik = [n](int i, int k) { return static_cast<std::uint32_t>(i * (n + 1) + k); };
    for (int i = 0; i < n; ++i) {
        for (int k = 0; k < n; ++k) {
            idx.insert(idx.end(), {at_ik(i, k), at_ik(i, k + 1), at_ik(i + 1, k + 1)});
            idx.insert(idx.end(), {at_ik(i, k), at_ik(i + 1, k + 1), at_ik(i + 1, k)});
        }
    }
    return Shape::triangle_mesh(v, idx);
}

Shape flat_grid(int n, Real y = 0) {
    return grid(n, [y](Real, Real) { return y; });
}

// Whether world point p lies on triangle t of the mesh posed by x.
bool on_triangle(const Shape& mesh_shape, const Transform& x, std::uint32_t t, const Vec3& p, Real tol = 1e-9) {
    const TriangleMesh& mesh = *mesh_shape.mesh;
    if (t >= mesh.triangles().size()) return false;
    const MeshTriangle& tri = mesh.triangles()[t];
    const Vec3 q = x.apply_inverse(p);
    const Vec3 a = mesh.vertices()[tri.v[0]], b = mesh.vertices()[tri.v[1]], c = mesh.vertices()[tri.v[2]];
    const Vec3 n = (b - a).cross(c - a);
    if (std::abs(n.normalized().dot(q - a)) > tol) return false;
    for (const auto& [u, w] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
        if ((w - u).cross(q - u).dot(n) < -tol * n.norm()) return false;
    }
    return true;
}

CastHit must_ray(const Shape& s, const Transform& x, const Vec3& from, const Vec3& to) {
    CastHit hit;
    hit.fraction = -1;
    EXPECT_TRUE(ray_cast(s, x, from, to, hit))
        << "expected a hit from " << from.transpose() << " to " << to.transpose();
    EXPECT_NEAR(hit.normal.norm(), 1, 1e-12);
    return hit;
}

bool ray_hits(const Shape& s, const Transform& x, const Vec3& from, const Vec3& to) {
    CastHit hit;
    return ray_cast(s, x, from, to, hit);
}

CastHit must_sweep(const Shape& moving, const Transform& start, const Vec3& translation, const Shape& target,
                   const Transform& target_pose) {
    CastHit hit;
    hit.fraction = -1;
    EXPECT_TRUE(shape_cast(moving, start, translation, target, target_pose, hit));
    EXPECT_NEAR(hit.normal.norm(), 1, 1e-9);
    return hit;
}

bool sweep_hits(const Shape& moving, const Transform& start, const Vec3& translation, const Shape& target,
                const Transform& target_pose) {
    CastHit hit;
    return shape_cast(moving, start, translation, target, target_pose, hit);
}

// The sweep's fraction is never past the exact one, and short of it by at most the gap
// tolerance covered at the closing speed (length per unit fraction along the normal).
void expect_fraction(Real actual, Real exact, Real closing_speed) {
    EXPECT_LE(actual, exact + 1e-12);
    EXPECT_GE(actual, exact - kSweepSlack / closing_speed);
}

// ---- Ray casts ----------------------------------------------------------------------------

TEST(RayCast, SphereHitOnAxisAndOffAxis) {
    const Shape sphere = Shape::sphere(1);
    CastHit hit = must_ray(sphere, at(Vec3(5, 0, 0)), Vec3::Zero(), Vec3(10, 0, 0));
    EXPECT_NEAR(hit.fraction, 0.4, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(4, 0, 0), 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(-1, 0, 0), 1e-14);
    // Entry at x = 5 - 0.8: the normal leans up by the 0.6 offset.
    hit = must_ray(sphere, at(Vec3(5, 0, 0)), Vec3(0, 0.6, 0), Vec3(10, 0.6, 0));
    EXPECT_NEAR(hit.fraction, 0.42, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(-0.8, 0.6, 0), 1e-14);
}

TEST(RayCast, SphereGrazingHitsAndMissesJustBeyond) {
    const Shape sphere = Shape::sphere(1);
    const CastHit hit = must_ray(sphere, at(Vec3(5, 0, 0)), Vec3(0, 1, 0), Vec3(10, 1, 0));
    EXPECT_NEAR(hit.fraction, 0.5, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-14);
    EXPECT_FALSE(ray_hits(sphere, at(Vec3(5, 0, 0)), Vec3(0, 1.001, 0), Vec3(10, 1.001, 0)));
    EXPECT_FALSE(ray_hits(sphere, at(Vec3(5, 0, 0)), Vec3::Zero(), Vec3(3.9, 0, 0)));   // ends short
    EXPECT_FALSE(ray_hits(sphere, at(Vec3(5, 0, 0)), Vec3(10, 0, 0), Vec3(20, 0, 0)));  // beyond, going away
}

TEST(RayCast, StartInsideSolidIsNoHitStartOnSurfaceGoingInIsFractionZero) {
    const Shape sphere = Shape::sphere(1);
    EXPECT_FALSE(ray_hits(sphere, at(Vec3::Zero()), Vec3(0.5, 0, 0), Vec3(5, 0, 0)));
    EXPECT_FALSE(ray_hits(sphere, at(Vec3::Zero()), Vec3(0.5, 0, 0), Vec3(-5, 0, 0)));
    CastHit hit = must_ray(sphere, at(Vec3::Zero()), Vec3(1, 0, 0), Vec3(-5, 0, 0));
    EXPECT_EQ(hit.fraction, 0);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(1, 0, 0), 1e-14);
    EXPECT_FALSE(ray_hits(sphere, at(Vec3::Zero()), Vec3(1, 0, 0), Vec3(5, 0, 0)));  // on it, leaving

    const Shape box = Shape::box(Vec3(1, 2, 3));
    EXPECT_FALSE(ray_hits(box, at(Vec3(1, 1, 1)), Vec3(1, 1, 1), Vec3(10, 1, 1)));
    hit = must_ray(box, at(Vec3::Zero()), Vec3(0, 2, 0), Vec3(0, -2, 0));
    EXPECT_EQ(hit.fraction, 0);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-15);
    EXPECT_FALSE(ray_hits(box, at(Vec3::Zero()), Vec3(0, 2, 0), Vec3(0, 4, 0)));

    const Shape capsule = Shape::capsule(1, 0.5);
    EXPECT_FALSE(ray_hits(capsule, at(Vec3::Zero()), Vec3(0, 1.2, 0), Vec3(0, 5, 0)));  // in a cap ball
    EXPECT_FALSE(ray_hits(capsule, at(Vec3::Zero()), Vec3(0.3, 0, 0), Vec3(5, 0, 0)));  // in the cylinder
    EXPECT_FALSE(ray_hits(octahedron(), at(Vec3::Zero()), Vec3(0.1, 0.1, 0.1), Vec3(5, 5, 5)));
    EXPECT_FALSE(ray_hits(Shape::plane(Vec3::UnitY(), 0), at(Vec3::Zero()), Vec3(0, -1, 0), Vec3(0, -5, 0)));
    EXPECT_FALSE(ray_hits(Shape::plane(Vec3::UnitY(), 0), at(Vec3::Zero()), Vec3(0, -1, 0), Vec3(0, 5, 0)));
}

TEST(RayCast, TurnedAndMovedBoxFace) {
    // Turned 90 degrees about z: local y (half extent 2) lies along world x.
    const Shape box = Shape::box(Vec3(1, 2, 3));
    const Transform x = at(Vec3(10, 0, 0), about(Vec3::UnitZ(), kPi / 2));
    CastHit hit = must_ray(box, x, Vec3::Zero(), Vec3(20, 0, 0));
    EXPECT_NEAR(hit.fraction, 0.4, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(8, 0, 0), 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(-1, 0, 0), 1e-14);
    // From above: world y is local -x (half extent 1).
    hit = must_ray(box, x, Vec3(10.5, 5, 2.9), Vec3(10.5, -5, 2.9));
    EXPECT_NEAR(hit.fraction, 0.4, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-14);
    EXPECT_FALSE(ray_hits(box, x, Vec3(10.5, 5, 3.1), Vec3(10.5, -5, 3.1)));  // past the z face
}

TEST(RayCast, BoxEdgeAndGrazingFace) {
    const Shape box = Shape::box(Vec3::Ones());
    // Through the edge x = y = -1 exactly: either face there is a right normal.
    CastHit hit = must_ray(box, at(Vec3::Zero()), Vec3(-2, -2, 0), Vec3(2, 2, 0));
    EXPECT_NEAR(hit.fraction, 0.25, 1e-15);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(-1, -1, 0), 1e-15);
    EXPECT_TRUE((hit.normal - Vec3(-1, 0, 0)).norm() < 1e-15 || (hit.normal - Vec3(0, -1, 0)).norm() < 1e-15)
        << hit.normal.transpose();
    // Sliding along the top face: it touches the -x face's top edge.
    hit = must_ray(box, at(Vec3::Zero()), Vec3(-2, 1, 0), Vec3(2, 1, 0));
    EXPECT_NEAR(hit.fraction, 0.25, 1e-15);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(-1, 0, 0), 1e-15);
    EXPECT_FALSE(ray_hits(box, at(Vec3::Zero()), Vec3(-2, 1 + 1e-12, 0), Vec3(2, 1 + 1e-12, 0)));
    // The line y = x + 2.001 passes just beyond the corner (-1, 1).
    EXPECT_FALSE(ray_hits(box, at(Vec3::Zero()), Vec3(-3, -0.999, 0), Vec3(0, 2.001, 0)));
}

TEST(RayCast, CapsuleSideAndCaps) {
    // Turned 90 degrees about z: the axis lies along world x, caps centred at x = -1 and 1.
    const Shape capsule = Shape::capsule(1, 0.5);
    const Transform x = at(Vec3::Zero(), about(Vec3::UnitZ(), kPi / 2));
    CastHit hit = must_ray(capsule, x, Vec3(0.3, 5, 0), Vec3(0.3, -5, 0));
    EXPECT_NEAR(hit.fraction, 0.45, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-14);
    hit = must_ray(capsule, x, Vec3(5, 0, 0), Vec3(-5, 0, 0));
    EXPECT_NEAR(hit.fraction, 0.35, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(1, 0, 0), 1e-14);
    // Off the axis, the cap ball at x = 1 is entered at 1 + 0.4.
    hit = must_ray(capsule, x, Vec3(5, 0.3, 0), Vec3(-5, 0.3, 0));
    EXPECT_NEAR(hit.fraction, 0.36, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0.8, 0.6, 0), 1e-14);
    // Down onto the cap beyond the cylinder's end.
    hit = must_ray(capsule, x, Vec3(1.3, 5, 0), Vec3(1.3, -5, 0));
    EXPECT_NEAR(hit.fraction, 0.46, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0.6, 0.8, 0), 1e-14);
    EXPECT_FALSE(ray_hits(capsule, x, Vec3(1.6, 5, 0), Vec3(1.6, -5, 0)));
    EXPECT_FALSE(ray_hits(capsule, x, Vec3(0, 0.6, -5), Vec3(0, 0.6, 5)));
}

TEST(RayCast, HullFacesFromBothSidesAndMissBeside) {
    const Shape hull = octahedron();
    const Vec3 n = Vec3::Ones().normalized();
    CastHit hit = must_ray(hull, at(Vec3::Zero()), Vec3(2, 2, 2), Vec3(-2, -2, -2));
    EXPECT_NEAR(hit.fraction, 5.0 / 12, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3::Constant(1.0 / 3), 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, n, 1e-14);
    hit = must_ray(hull, at(Vec3::Zero()), Vec3(-2, -2, -2), Vec3(2, 2, 2));
    EXPECT_NEAR(hit.fraction, 5.0 / 12, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, -n, 1e-14);
    // |x| + 0.9 + 0.9 > 1 everywhere on this line: it passes beside every face.
    for (const Real sign : {-1.0, 1.0}) {
        EXPECT_FALSE(ray_hits(hull, at(Vec3::Zero()), Vec3(-2 * sign, 0.9, 0.9), Vec3(2 * sign, 0.9, 0.9)));
        EXPECT_FALSE(ray_hits(hull, at(Vec3::Zero()), Vec3(-2 * sign, -0.9, -0.9), Vec3(2 * sign, -0.9, -0.9)));
    }
}

TEST(RayCast, TurnedAndMovedHullMatchesTheLocalCast) {
    const Shape hull = octahedron();
    const Transform x = at(Vec3(3, -2, 7), about(Vec3(1, 2, -0.5), 0.9));
    const CastHit hit = must_ray(hull, x, x.apply(Vec3(2, 2, 2)), x.apply(Vec3(-2, -2, -2)));
    EXPECT_NEAR(hit.fraction, 5.0 / 12, 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, x.apply(Vec3::Constant(1.0 / 3)), 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, x.rotate(Vec3::Ones().normalized()), 1e-13);
}

TEST(RayCast, PlaneHitsFromTheFrontOnly) {
    // Local plane y = 1, turned so local +y is world +x and raised by 2: world plane x = 1.
    const Shape plane = Shape::plane(Vec3::UnitY(), 1);
    const Transform x = at(Vec3(0, 2, 0), about(Vec3::UnitZ(), -kPi / 2));
    CastHit hit = must_ray(plane, x, Vec3(5, 3, 4), Vec3(-3, 3, 4));
    EXPECT_NEAR(hit.fraction, 0.5, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(1, 3, 4), 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(1, 0, 0), 1e-14);
    EXPECT_FALSE(ray_hits(plane, x, Vec3(5, 3, 4), Vec3(2, 3, 4)));   // ends short
    EXPECT_FALSE(ray_hits(plane, x, Vec3(5, 3, 4), Vec3(5, 9, 4)));   // parallel
    EXPECT_FALSE(ray_hits(plane, x, Vec3(5, 3, 4), Vec3(9, 3, 4)));   // going away
    EXPECT_FALSE(ray_hits(plane, x, Vec3(0, 3, 4), Vec3(-3, 3, 4)));  // behind it
    hit = must_ray(plane, x, Vec3(1, 3, 4), Vec3(-3, 3, 4));          // on it (to round-off), going in
    EXPECT_NEAR(hit.fraction, 0, 1e-15);
}

TEST(RayCast, MeshIsTwoSidedAndNamesTheTriangle) {
    const Shape mesh = flat_grid(10);
    const Transform x = at(Vec3(0, 1, 0));
    CastHit hit = must_ray(mesh, x, Vec3(0.3, 5, -2.2), Vec3(0.3, -5, -2.2));
    EXPECT_NEAR(hit.fraction, 0.4, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(0.3, 1, -2.2), 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-14);
    EXPECT_TRUE(on_triangle(mesh, x, hit.part, hit.point));
    hit = must_ray(mesh, x, Vec3(-3.7, -4, 1.1), Vec3(-3.7, 6, 1.1));
    EXPECT_NEAR(hit.fraction, 0.5, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, -1, 0), 1e-14);
    EXPECT_TRUE(on_triangle(mesh, x, hit.part, hit.point));
    EXPECT_FALSE(ray_hits(mesh, x, Vec3(5.5, 5, 0), Vec3(5.5, -5, 0)));  // beside the grid
    EXPECT_FALSE(ray_hits(mesh, x, Vec3(-6, 1, 0.3), Vec3(6, 1, 0.3)));  // in its plane
}

TEST(RayCast, MeshGivesTheNearestOfStackedLayers) {
    // Two layers one apart; the tree must not stop at the first triangle it meets.
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    for (const Real y : {0.0, 1.0}) {
        const auto base = static_cast<std::uint32_t>(v.size());
        v.insert(v.end(), {Vec3(-2, y, -2), Vec3(-2, y, 2), Vec3(2, y, 2), Vec3(2, y, -2)});
        idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    const Shape mesh = Shape::triangle_mesh(v, idx);
    const Transform x = at(Vec3(0, 0, 5), about(Vec3::UnitX(), kPi / 2));  // layers at z = 5 and 6
    CastHit hit = must_ray(mesh, x, Vec3(0.5, 0.5, 10), Vec3(0.5, 0.5, 0));
    EXPECT_NEAR(hit.fraction, 0.4, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 0, 1), 1e-14);
    hit = must_ray(mesh, x, Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, 10));
    EXPECT_NEAR(hit.fraction, 0.5, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 0, -1), 1e-14);
}

TEST(RayCast, MeshTreeWalkAgreesWithEveryTriangleAlone) {
    // A bumpy 8 x 8 grid: the tree's answer must be the nearest over all triangles.
    const Shape mesh = grid(8, [](Real x, Real z) { return 0.4 * std::sin(1.3 * x) * std::cos(0.9 * z); });
    const Transform pose = at(Vec3(1, 2, 3), about(Vec3(0.3, 1, 0.2), 0.7));
    const TriangleMesh& m = *mesh.mesh;
    std::mt19937 rng(17);
    std::uniform_real_distribution<Real> u(-5, 5);
    int hits = 0;
    for (int r = 0; r < 60; ++r) {
        const Vec3 from = pose.apply(Vec3(u(rng), 3 + u(rng) * 0.2, u(rng)));
        const Vec3 to = pose.apply(Vec3(u(rng), -3 + u(rng) * 0.2, u(rng)));
        Real nearest = kHuge;
        for (std::uint32_t t = 0; t < m.triangles().size(); ++t) {
            const std::uint32_t idx[3] = {0, 1, 2};
            const Vec3 v[3] = {m.vertices()[m.triangles()[t].v[0]], m.vertices()[m.triangles()[t].v[1]],
                               m.vertices()[m.triangles()[t].v[2]]};
            CastHit one;
            if (ray_cast(Shape::triangle_mesh(v, idx), pose, from, to, one)) nearest = std::min(nearest, one.fraction);
        }
        CastHit hit;
        const bool found = ray_cast(mesh, pose, from, to, hit);
        ASSERT_EQ(found, nearest != kHuge) << "ray " << r;
        if (!found) continue;
        ++hits;
        EXPECT_NEAR(hit.fraction, nearest, 1e-12) << "ray " << r;
        EXPECT_TRUE(on_triangle(mesh, pose, hit.part, hit.point, 1e-9)) << "ray " << r;
        EXPECT_LT(hit.normal.dot(to - from), 0) << "ray " << r;
    }
    EXPECT_GT(hits, 30);
}

TEST(RayCast, ZeroLengthSegmentNeverHits) {
    const std::vector<std::pair<Shape, Vec3>> cases = {{Shape::sphere(1), Vec3(1, 0, 0)},
                                                       {Shape::capsule(1, 0.5), Vec3(0, 1.5, 0)},
                                                       {Shape::box(Vec3::Ones()), Vec3(1, 0, 0)},
                                                       {octahedron(), Vec3(1, 0, 0)},
                                                       {Shape::plane(Vec3::UnitY(), 0), Vec3::Zero()},
                                                       {flat_grid(2), Vec3(0.2, 0, 0.3)}};
    for (const auto& [shape, on_surface] : cases) {
        EXPECT_FALSE(ray_hits(shape, at(Vec3::Zero()), on_surface, on_surface)) << to_string(shape.type);
    }
}

TEST(RayCast, NonFiniteInputIsNoHit) {
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    const Real inf = std::numeric_limits<Real>::infinity();
    const std::vector<Shape> shapes = {Shape::sphere(1), Shape::capsule(1, 0.5),         Shape::box(Vec3::Ones()),
                                       octahedron(),     Shape::plane(Vec3::UnitY(), 0), flat_grid(4)};
    for (const Shape& shape : shapes) {
        for (const Real bad : {nan, inf, -inf}) {
            EXPECT_FALSE(ray_hits(shape, at(Vec3::Zero()), Vec3(0, 5, 0), Vec3(0, bad, 0))) << to_string(shape.type);
            EXPECT_FALSE(ray_hits(shape, at(Vec3::Zero()), Vec3(bad, 5, 0), Vec3(0, -5, 0))) << to_string(shape.type);
            EXPECT_FALSE(ray_hits(shape, at(Vec3(0, bad, 0)), Vec3(0, 5, 0), Vec3(0, -5, 0))) << to_string(shape.type);
        }
    }
}

// ---- Shape casts --------------------------------------------------------------------------

TEST(ShapeCast, SphereAgainstBoxFace) {
    const CastHit hit = must_sweep(Shape::sphere(0.5), at(Vec3(-5, 0.2, 0)), Vec3(10, 0, 0), Shape::box(Vec3::Ones()),
                                   at(Vec3::Zero()));
    expect_fraction(hit.fraction, 0.35, 10);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(-1, 0, 0), 1e-9);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(-1, 0.2, 0), 1e-9);
    EXPECT_EQ(hit.part, 0u);
}

TEST(ShapeCast, SphereAgainstSphereOffCentre) {
    // Centres 2 apart when (x - 5)^2 + 1 = 4: the normal leans by the offset.
    const CastHit hit = must_sweep(Shape::sphere(1), at(Vec3::Zero()), Vec3(10, 0, 0), Shape::sphere(1),
                                   at(Vec3(5, 1, 0)));
    expect_fraction(hit.fraction, (5 - kSqrt3) / 10, 10 * kSqrt3 / 2);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(-kSqrt3 / 2, -0.5, 0), 1e-5);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(5 - kSqrt3 / 2, 0.5, 0), 1e-5);
}

TEST(ShapeCast, TurnedBoxFallingOntoMovedPlane) {
    // Box rolled 45 degrees about z: its lowest edge is 1.5 / sqrt(2) below its centre.
    const Shape box = Shape::box(Vec3(1, 0.5, 1));
    const Transform start = at(Vec3(0, 5, 0), about(Vec3::UnitZ(), kPi / 4));
    const Shape ground = Shape::plane(Vec3::UnitY(), 0);
    CastHit hit = must_sweep(box, start, Vec3(0, -10, 0), ground, at(Vec3::Zero()));
    EXPECT_NEAR(hit.fraction, (5 - 1.5 / kSqrt2) / 10, 1e-14);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-15);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(-0.5 / kSqrt2, 0, 0), 1e-13);  // the middle of the edge
    // The same scene turned and moved as a whole.
    const Transform whole = at(Vec3(-4, 7, 2), about(Vec3(1, -1, 2), 1.1));
    hit = must_sweep(box, whole * start, whole.rotate(Vec3(0, -10, 0)), ground, whole);
    EXPECT_NEAR(hit.fraction, (5 - 1.5 / kSqrt2) / 10, 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, whole.rotate(Vec3(0, 1, 0)), 1e-13);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, whole.apply(Vec3(-0.5 / kSqrt2, 0, 0)), 1e-12);
    EXPECT_FALSE(sweep_hits(box, start, Vec3(10, 0, 0), ground, at(Vec3::Zero())));       // parallel
    EXPECT_FALSE(sweep_hits(box, start, Vec3(0, 10, 0), ground, at(Vec3::Zero())));       // away
    EXPECT_FALSE(sweep_hits(box, start, Vec3(0, -3, 0), ground, at(Vec3::Zero())));       // short
    hit = must_sweep(box, at(Vec3(0, 0.2, 0)), Vec3(5, 0, 0), ground, at(Vec3::Zero()));  // 0.3 deep
    EXPECT_EQ(hit.fraction, 0);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-15);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(0, 0, 0), 1e-15);
}

TEST(ShapeCast, CapsuleOntoMeshFromAboveAndBelow) {
    const Shape mesh = flat_grid(10);
    const Shape capsule = Shape::capsule(1, 0.25);
    const Transform lying = at(Vec3(0.2, 2, 0.3), about(Vec3::UnitZ(), kPi / 2));
    CastHit hit = must_sweep(capsule, lying, Vec3(1, -4, 0), mesh, at(Vec3::Zero()));
    expect_fraction(hit.fraction, 1.75 / 4, 4);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-9);
    EXPECT_NEAR(hit.point.y(), 0, 1e-12);
    EXPECT_TRUE(on_triangle(mesh, at(Vec3::Zero()), hit.part, hit.point));
    const Transform below = at(Vec3(0.2, -2, 0.3), about(Vec3::UnitZ(), kPi / 2));
    hit = must_sweep(capsule, below, Vec3(1, 4, 0), mesh, at(Vec3::Zero()));
    expect_fraction(hit.fraction, 1.75 / 4, 4);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, -1, 0), 1e-9);
    EXPECT_FALSE(sweep_hits(capsule, lying, Vec3(0, -1.5, 0), mesh, at(Vec3::Zero())));            // short
    EXPECT_FALSE(sweep_hits(capsule, at(Vec3(9, 2, 0)), Vec3(0, -4, 0), mesh, at(Vec3::Zero())));  // beside
}

TEST(ShapeCast, CapsuleOntoTiltedMeshTakesTheNearestTriangle) {
    // A grid tilted 0.3 rad about x, raised 1: the capsule's lower cap meets it first.
    const Shape mesh = flat_grid(10);
    const Transform pose = at(Vec3(0, 1, 0), about(Vec3::UnitX(), 0.3));
    const Shape capsule = Shape::capsule(0.5, 0.25);
    const CastHit hit = must_sweep(capsule, at(Vec3(0.4, 4, 0.5)), Vec3(0, -6, 0), mesh, pose);
    // The lower cap's centre (0.4, y - 0.5, 0.5) reaches 0.25 from the plane.
    const Vec3 n = pose.rotate(Vec3::UnitY());
    const Real start_gap = n.dot(Vec3(0.4, 3.5, 0.5) - pose.p) - 0.25;
    expect_fraction(hit.fraction, start_gap / (6 * n.y()), 6 * n.y());
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, n, 1e-6);
    EXPECT_TRUE(on_triangle(mesh, pose, hit.part, hit.point, 1e-9));
}

TEST(ShapeCast, HullAgainstTurnedHull) {
    // The target cube turned 45 degrees about y puts a vertical edge at x = sqrt(2).
    const Shape cube = test::hull_box(Vec3::Ones());
    const Transform target = at(Vec3::Zero(), about(Vec3::UnitY(), kPi / 4));
    CastHit hit = must_sweep(octahedron(), at(Vec3(5, 0.3, 0)), Vec3(-10, 0, 0), cube, target);
    expect_fraction(hit.fraction, (4 - kSqrt2) / 10, 10);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(1, 0, 0), 1e-6);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(kSqrt2, 0.3, 0), 1e-5);
    // The octahedron turned 45 degrees about z leads with an edge at x = -1/sqrt(2).
    hit = must_sweep(octahedron(), at(Vec3(5, 0, 0), about(Vec3::UnitZ(), kPi / 4)), Vec3(-10, 0, 0), cube, target);
    expect_fraction(hit.fraction, (5 - 1 / kSqrt2 - kSqrt2) / 10, 10);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(1, 0, 0), 1e-6);
    EXPECT_NEAR(hit.point.x(), kSqrt2, 1e-5);
    EXPECT_LE(std::abs(hit.point.y()), 1 / kSqrt2 + 1e-9);
    // Passing above the cube.
    EXPECT_FALSE(sweep_hits(octahedron(), at(Vec3(5, 2.01, 0)), Vec3(-10, 0, 0), cube, target));
}

TEST(ShapeCast, AgreesWithOverlapSampledAlongTheSweep) {
    // Random turned convex pairs: a hit is never past the first sampled overlap and the
    // caster is still apart there; a sweep with any sampled overlap is a hit.
    const std::vector<Shape> shapes = {Shape::sphere(0.4), Shape::capsule(0.5, 0.3), Shape::box(Vec3(0.6, 0.3, 0.9)),
                                       octahedron()};
    std::mt19937 rng(11);
    std::uniform_real_distribution<Real> u(-1, 1);
    constexpr int kSamples = 2000;
    int hits = 0;
    for (int i = 0; i < 120; ++i) {
        const Shape& moving = shapes[static_cast<std::size_t>(i) % shapes.size()];
        const Shape& target = shapes[static_cast<std::size_t>(i / 4) % shapes.size()];
        const Transform start = at(Vec3(u(rng), u(rng), u(rng)) * 4, about(Vec3(u(rng), u(rng), u(rng)), 3 * u(rng)));
        const Transform target_pose = at(Vec3(u(rng), u(rng), u(rng)), about(Vec3(u(rng), u(rng), u(rng)), 3 * u(rng)));
        const Vec3 translation = (target_pose.p - start.p) * 2 + Vec3(u(rng), u(rng), u(rng));
        int first_overlap = -1;
        for (int k = 0; k <= kSamples && first_overlap < 0; ++k) {
            const Transform at_k{start.p + translation * (Real(k) / kSamples), start.q};
            if (overlaps(moving, at_k, target, target_pose)) first_overlap = k;
        }
        CastHit hit;
        const bool found = shape_cast(moving, start, translation, target, target_pose, hit);
        if (first_overlap >= 0) {
            ASSERT_TRUE(found) << "case " << i;
        }
        if (!found) continue;
        ++hits;
        if (first_overlap >= 0) {
            EXPECT_LE(hit.fraction, Real(first_overlap) / kSamples + 1e-12) << "case " << i;
        }
        if (hit.fraction > 0) {
            EXPECT_FALSE(overlaps(moving, {start.p + translation * hit.fraction, start.q}, target, target_pose))
                << "case " << i;
        }
    }
    EXPECT_GT(hits, 60);
}

TEST(ShapeCast, OverlappingAtStartGivesFractionZeroAndLeastSeparation) {
    const Shape box = Shape::box(Vec3::Ones());
    // 0.5 deep into the box's +x face, whichever way it moves.
    for (const Vec3& translation : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 3, 0), Vec3(0, 0, 0)}) {
        const CastHit hit = must_sweep(Shape::sphere(1), at(Vec3(1.5, 0.1, 0)), translation, box, at(Vec3::Zero()));
        EXPECT_EQ(hit.fraction, 0);
        SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(1, 0, 0), 1e-9);
        EXPECT_NEAR(hit.point.x(), 1, 1e-9);
    }
    // Box on box, 0.1 deep along y.
    const CastHit hit = must_sweep(box, at(Vec3(0.3, 1.9, 0)), Vec3(1, 0, 0), box, at(Vec3::Zero()));
    EXPECT_EQ(hit.fraction, 0);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-9);
    // A sphere sunk into a mesh: the triangle under it.
    const Shape mesh = flat_grid(4);
    const CastHit on_mesh = must_sweep(Shape::sphere(0.5), at(Vec3(0.3, 0.2, 0.6)), Vec3(1, 0, 0), mesh,
                                       at(Vec3::Zero()));
    EXPECT_EQ(on_mesh.fraction, 0);
    SPINDLE_EXPECT_VEC_NEAR(on_mesh.normal, Vec3(0, 1, 0), 1e-9);
    EXPECT_TRUE(on_triangle(mesh, at(Vec3::Zero()), on_mesh.part, on_mesh.point, 1e-9));
}

TEST(ShapeCast, ApartWithinToleranceHitsOnlyWhenClosing) {
    const Shape box = Shape::box(Vec3::Ones());
    const Transform start = at(Vec3(0, 2 + 2e-6, 0));
    const CastHit hit = must_sweep(box, start, Vec3(0, -10, 0), box, at(Vec3::Zero()));
    EXPECT_EQ(hit.fraction, 0);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(0, 1, 0), 1e-9);
    EXPECT_FALSE(sweep_hits(box, start, Vec3(10, 0, 0), box, at(Vec3::Zero())));
    EXPECT_FALSE(sweep_hits(box, start, Vec3(0, 10, 0), box, at(Vec3::Zero())));
}

TEST(ShapeCast, MissesAndZeroTranslation) {
    const Shape sphere = Shape::sphere(0.5);
    const Shape box = Shape::box(Vec3::Ones());
    EXPECT_FALSE(sweep_hits(sphere, at(Vec3(-5, 1.6, 0)), Vec3(10, 0, 0), box, at(Vec3::Zero())));  // above
    EXPECT_FALSE(sweep_hits(sphere, at(Vec3(-5, 0, 0)), Vec3(-10, 0, 0), box, at(Vec3::Zero())));   // away
    EXPECT_FALSE(sweep_hits(sphere, at(Vec3(-5, 0, 0)), Vec3(3, 0, 0), box, at(Vec3::Zero())));     // short
    EXPECT_FALSE(sweep_hits(sphere, at(Vec3(-5, 0, 0)), Vec3::Zero(), box, at(Vec3::Zero())));
    // Grazing the top edge: 1e-3 above it passes, 1e-3 into it hits, the normal nearly
    // upright, so the closing speed along it is small and the fraction less exact.
    EXPECT_FALSE(sweep_hits(sphere, at(Vec3(-5, 1.501, 0)), Vec3(10, 0, 0), box, at(Vec3::Zero())));
    const CastHit hit = must_sweep(sphere, at(Vec3(-5, 1.499, 0)), Vec3(10, 0, 0), box, at(Vec3::Zero()));
    const Real dx = std::sqrt(0.25 - 0.499 * 0.499);
    expect_fraction(hit.fraction, (4 - dx) / 10, 10 * dx / 0.5);
    SPINDLE_EXPECT_VEC_NEAR(hit.normal, Vec3(-dx, 0.499, 0) / 0.5, 1e-3);
    SPINDLE_EXPECT_VEC_NEAR(hit.point, Vec3(-1, 1, 0), 1e-9);
}

TEST(ShapeCast, StaticMoversAndNonFiniteInputAreNoHit) {
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    const Real inf = std::numeric_limits<Real>::infinity();
    const Shape box = Shape::box(Vec3::Ones());
    const std::vector<Shape> targets = {Shape::sphere(1), Shape::capsule(1, 0.5),          box,
                                        octahedron(),     Shape::plane(Vec3::UnitY(), -3), flat_grid(4)};
    for (const Shape& target : targets) {
        for (const Real bad : {nan, inf, -inf}) {
            EXPECT_FALSE(sweep_hits(box, at(Vec3(0, 5, 0)), Vec3(0, bad, 0), target, at(Vec3::Zero())))
                << to_string(target.type);
            EXPECT_FALSE(sweep_hits(box, at(Vec3(bad, 5, 0)), Vec3(0, -10, 0), target, at(Vec3::Zero())))
                << to_string(target.type);
            EXPECT_FALSE(sweep_hits(box, at(Vec3(0, 5, 0)), Vec3(0, -10, 0), target, at(Vec3(0, 0, bad))))
                << to_string(target.type);
        }
    }
    EXPECT_FALSE(sweep_hits(Shape::plane(Vec3::UnitY(), 0), at(Vec3::Zero()), Vec3(0, -1, 0), box, at(Vec3::Zero())));
    EXPECT_FALSE(sweep_hits(flat_grid(2), at(Vec3::Zero()), Vec3(0, -1, 0), box, at(Vec3::Zero())));
}

// ---- Overlap ------------------------------------------------------------------------------

TEST(Overlaps, SpheresApartTouchingAndOverlapping) {
    const Shape sphere = Shape::sphere(1);
    EXPECT_FALSE(overlaps(sphere, at(Vec3::Zero()), sphere, at(Vec3(2 + 1e-9, 0, 0))));
    EXPECT_TRUE(overlaps(sphere, at(Vec3::Zero()), sphere, at(Vec3(2, 0, 0))));
    EXPECT_TRUE(overlaps(sphere, at(Vec3::Zero()), sphere, at(Vec3(1, 1, 0))));
}

TEST(Overlaps, BoxCornerAgainstTurnedBox) {
    // The turned box's corner reaches sqrt(2) along x.
    const Shape box = Shape::box(Vec3::Ones());
    const Transform turned = at(Vec3::Zero(), about(Vec3::UnitZ(), kPi / 4));
    EXPECT_FALSE(overlaps(box, turned, box, at(Vec3(1 + kSqrt2 + 1e-6, 0, 0))));
    EXPECT_TRUE(overlaps(box, turned, box, at(Vec3(1 + kSqrt2 - 1e-6, 0, 0))));
    EXPECT_TRUE(overlaps(box, at(Vec3::Zero()), box, at(Vec3(2, 2, 0))));  // corner on corner
    EXPECT_FALSE(overlaps(box, at(Vec3::Zero()), box, at(Vec3(2, 2 + 1e-9, 0))));
}

TEST(Overlaps, TouchingThroughRoundOffCounts) {
    // A sphere resting on a face of a box turned every which way: its distance comes out
    // a few ulps either side of the radius, and touching must still count.
    const Shape box = Shape::box(Vec3(1, 0.7, 0.4));
    const Shape sphere = Shape::sphere(0.5);
    std::mt19937 rng(3);
    std::uniform_real_distribution<Real> u(-1, 1);
    for (int i = 0; i < 50; ++i) {
        const Transform x = at(Vec3(u(rng), u(rng), u(rng)) * 10, about(Vec3(u(rng), u(rng), u(rng)), 3 * u(rng)));
        EXPECT_TRUE(overlaps(sphere, at(x.apply(Vec3(1.5, 0.3, -0.2))), box, x)) << "pose " << i;
        EXPECT_FALSE(overlaps(sphere, at(x.apply(Vec3(1.5 + 1e-9, 0.3, -0.2))), box, x)) << "pose " << i;
    }
}

TEST(Overlaps, CapsuleAgainstHull) {
    const Shape capsule = Shape::capsule(1, 0.5);
    EXPECT_TRUE(overlaps(capsule, at(Vec3(0, 2.4, 0)), octahedron(), at(Vec3::Zero())));   // cap tip 0.1 in
    EXPECT_FALSE(overlaps(capsule, at(Vec3(0, 2.6, 0)), octahedron(), at(Vec3::Zero())));  // 0.1 above
    EXPECT_TRUE(overlaps(octahedron(), at(Vec3::Zero()), capsule, at(Vec3(0, 2.4, 0))));
}

TEST(Overlaps, PlaneAndMeshEitherOrder) {
    const Shape ground = Shape::plane(Vec3::UnitY(), 0);
    const Shape sphere = Shape::sphere(0.5);
    EXPECT_TRUE(overlaps(sphere, at(Vec3(0, 0.5, 0)), ground, at(Vec3::Zero())));
    EXPECT_FALSE(overlaps(sphere, at(Vec3(0, 0.5 + 1e-9, 0)), ground, at(Vec3::Zero())));
    EXPECT_TRUE(overlaps(ground, at(Vec3::Zero()), sphere, at(Vec3(0, -3, 0))));  // deep in the solid
    const Shape mesh = flat_grid(4);
    EXPECT_TRUE(overlaps(sphere, at(Vec3(0.3, 0.4, 0.2)), mesh, at(Vec3::Zero())));
    EXPECT_TRUE(overlaps(mesh, at(Vec3::Zero()), sphere, at(Vec3(0.3, -0.4, 0.2))));
    EXPECT_FALSE(overlaps(sphere, at(Vec3(0.3, 0.6, 0.2)), mesh, at(Vec3::Zero())));
    EXPECT_FALSE(overlaps(sphere, at(Vec3(0.3, -3, 0.2)), mesh, at(Vec3::Zero())));  // a mesh has no inside
    EXPECT_FALSE(overlaps(ground, at(Vec3::Zero()), mesh, at(Vec3::Zero())));        // static pair
}

}  // namespace
}  // namespace spindle
