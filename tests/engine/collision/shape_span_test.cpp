// ShapeSpan, the plane test that rules mesh triangles out before the pair test: its extent
// along a direction is the shape's, and a triangle it calls clear of the shape is one the
// pair test finds no contact with, while it does rule out most triangles that are clear.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "collision/pair_functions.hpp"
#include "collision/shape_span.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

using namespace test;
using detail::ShapeSpan;

std::vector<Shape> shapes() {
    const std::vector<Vec3> rock = {{0.5, 0, 0},       {-0.45, 0.05, 0},   {0, 0.35, 0.1},    {0.05, -0.3, 0},
                                    {0, 0, 0.4},       {0.1, 0, -0.45},    {0.3, 0.25, 0.25}, {-0.3, -0.2, 0.2},
                                    {-0.2, 0.2, -0.3}, {0.25, -0.2, -0.25}};
    return {Shape::sphere(0.5), Shape::capsule(0.5, 0.3), Shape::box(Vec3(0.4, 0.5, 0.6)), Shape::convex_hull(rock)};
}

// The pair test the mesh walk runs on a triangle (mesh frame = identity).
bool pair_test_touches(const Shape& a, const Transform& xa, const detail::TrianglePoly& tri, Real speculative) {
    Manifold m;
    const Transform identity;
    switch (a.type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule: {
            Vec3 p0, p1;
            detail::rounded_core(a, p0, p1);
            return detail::collide_rounded_polyhedron(p0, p1, a.radius, xa, tri.view(), identity, speculative, m);
        }
        case ShapeType::Box: {
            const detail::BoxPoly box(a.half_extents);
            return detail::collide_polyhedra(box.view(), xa, tri.view(), identity, speculative, m);
        }
        default: return detail::collide_polyhedra(detail::view_of(*a.hull), xa, tri.view(), identity, speculative, m);
    }
}

TEST(ShapeSpan, ExtentAlongADirectionIsTheShapes) {
    std::mt19937 rng(3);
    for (const Shape& shape : shapes()) {
        for (int sample = 0; sample < 50; ++sample) {
            const Transform x{Vec3(1, -2, 0.5), random_turn(rng)};
            const Vec3 n = random_turn(rng).vec().normalized();
            Real lo, hi;
            ShapeSpan(shape, x).along(n, lo, hi);
            // Brute force: the shape's points (a round shape's core, widened by its radius).
            std::vector<Vec3> points;
            Real radius = 0;
            if (shape.type == ShapeType::Box) points = box_corners(shape.half_extents);
            if (shape.type == ShapeType::ConvexHull)
                points = {shape.hull->vertices().begin(), shape.hull->vertices().end()};
            if (shape.type == ShapeType::Sphere || shape.type == ShapeType::Capsule) {
                points = {Vec3(0, -shape.half_height, 0), Vec3(0, shape.half_height, 0)};
                radius = shape.radius;
            }
            Real want_lo = kHuge, want_hi = -kHuge;
            for (const Vec3& p : points) {
                want_lo = std::min(want_lo, n.dot(x.apply(p)) - radius);
                want_hi = std::max(want_hi, n.dot(x.apply(p)) + radius);
            }
            EXPECT_NEAR(lo, want_lo, 1e-12) << to_string(shape.type) << " sample " << sample;
            EXPECT_NEAR(hi, want_hi, 1e-12) << to_string(shape.type) << " sample " << sample;
        }
    }
}

TEST(ShapeSpan, ATriangleClearOfTheShapeHasNoContactAndMostWithoutOneAreClear) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<Real> corner(-1.2, 1.2), place(-1.5, 1.5);
    for (const Shape& shape : shapes()) {
        int clear = 0, untouched = 0, touched = 0;
        for (int sample = 0; sample < 3000; ++sample) {
            const Vec3 v[3] = {Vec3(corner(rng), corner(rng) * 0.3, corner(rng)),
                               Vec3(corner(rng), corner(rng) * 0.3, corner(rng)),
                               Vec3(corner(rng), corner(rng) * 0.3, corner(rng))};
            if ((v[1] - v[0]).cross(v[2] - v[0]).norm() < 1e-3) continue;
            const detail::TrianglePoly tri(v[0], v[1], v[2]);
            const Transform x{Vec3(place(rng), place(rng), place(rng)), random_turn(rng)};
            const Real speculative = sample % 3 == 0 ? 0 : 0.05 * (sample % 3);
            const bool is_clear = ShapeSpan(shape, x).clear_of_plane(v, speculative);
            const bool touches = pair_test_touches(shape, x, tri, speculative);
            EXPECT_FALSE(is_clear && touches) << to_string(shape.type) << " sample " << sample;
            clear += is_clear ? 1 : 0;
            untouched += touches ? 0 : 1;
            touched += touches ? 1 : 0;
        }
        // Both kinds are sampled, and the plane rules out over half of what has no contact.
        EXPECT_GT(touched, 150) << to_string(shape.type);
        EXPECT_GT(clear, untouched / 2) << to_string(shape.type);
    }
}

}  // namespace
}  // namespace spindle
