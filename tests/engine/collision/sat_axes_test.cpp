// The polyhedron SAT's answer against a brute-force search: random hull pairs (and box-hull
// pairs) in random poses near touching, every face normal and every edge pair's cross
// product tried both ways with the supports of all vertices. The SAT skips edges and pairs
// it can bound out; whatever it skips must never change which axis wins.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "collision/pair_functions.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::at;
using test::random_turn;

// A hull of `count` points on a sphere of radius r (as Box3D's convex_pile draws them).
Shape random_hull(std::mt19937& random, Real r, int count) {
    std::normal_distribution<Real> normal(0, 1);
    std::vector<Vec3> points;
    for (int i = 0; i < count; ++i)
        points.push_back(r * Vec3(normal(random), normal(random), normal(random)).normalized());
    return Shape::convex_hull(points);
}

// A shape's vertices, face normals and edge directions in the world.
struct WorldPoly {
    std::vector<Vec3> vertices, normals, edges;
};

WorldPoly world_poly(const Shape& shape, const Transform& x) {
    const ConvexHull hull = shape.type == ShapeType::Box ? ConvexHull(test::box_corners(shape.half_extents))
                                                         : *shape.hull;
    WorldPoly w;
    for (const Vec3& v : hull.vertices()) w.vertices.push_back(x.apply(v));
    for (const HullFace& f : hull.faces()) w.normals.push_back(x.rotate(f.normal));
    for (const HullEdge& e : hull.edges()) w.edges.push_back(x.rotate(hull.vertices()[e.v1] - hull.vertices()[e.v0]));
    return w;
}

// How far apart the shapes are along unit axis l (from A to B): negative when they overlap.
Real separation_along(const WorldPoly& a, const WorldPoly& b, const Vec3& l) {
    Real reach_a = -kHuge, reach_b = kHuge;
    for (const Vec3& v : a.vertices) reach_a = std::max(reach_a, l.dot(v));
    for (const Vec3& v : b.vertices) reach_b = std::min(reach_b, l.dot(v));
    return reach_b - reach_a;
}

struct BruteForce {
    Real face_a = -kHuge, face_b = -kHuge, edge = -kHuge;
};

BruteForce brute_force(const WorldPoly& a, const WorldPoly& b) {
    BruteForce best;
    for (const Vec3& n : a.normals) best.face_a = std::max(best.face_a, separation_along(a, b, n));
    for (const Vec3& n : b.normals) best.face_b = std::max(best.face_b, separation_along(a, b, -n));
    for (const Vec3& ea : a.edges) {
        for (const Vec3& eb : b.edges) {
            const Vec3 cross = ea.cross(eb);
            if (cross.squaredNorm() <= 1e-12 * ea.squaredNorm() * eb.squaredNorm()) continue;
            const Vec3 l = cross.normalized();
            best.edge = std::max({best.edge, separation_along(a, b, l), separation_along(a, b, -l)});
        }
    }
    return best;
}

// Closer than this, two candidate answers count as a tie and the pose is not judged.
constexpr Real kTie = 1e-9;

struct Tally {
    int apart = 0, edge = 0, face = 0;
};

// B placed along a random direction so that the shapes' separation along it is between
// -1.2 and the speculative distance: the SAT's answer is at least that, so the pair
// overlaps, is within reach or just apart. Face axes are tried alike by both searches, so
// collide() must find the pair apart exactly when a face shows more than the speculative
// distance (an edge pair past it is left unjudged: the brute force tries crossings the
// SAT rightly skips, which can show more than any face of the Minkowski difference while
// the shapes are apart). While they overlap the deepest axis of both searches is the
// same, and collide()'s normal must show the separation of the one the SAT picks: an
// edge pair's when it beats both faces clearly, else the face of A, or of B when B's is
// clearly deeper. The SAT's A is the lower shape type (a box before a hull).
void expect_brute_force_axes(const Shape& a, const Shape& b, int poses, std::uint32_t seed, Tally& tally) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<Real> target(-1.2, 0.05);
    std::normal_distribution<Real> normal(0, 1);
    const Real speculative = 0.04;
    const bool swapped = b.type < a.type;
    for (int i = 0; i < poses; ++i) {
        const Transform xa = at(Vec3(normal(random), normal(random), normal(random)), random_turn(random));
        const Quat qb = random_turn(random);
        const Vec3 u = Vec3(normal(random), normal(random), normal(random)).normalized();
        const WorldPoly wa = world_poly(a, xa);
        const WorldPoly wb_at_origin = world_poly(b, at(Vec3::Zero(), qb));
        const Real distance = target(random) - separation_along(wa, wb_at_origin, u);
        const Transform xb = at(distance * u, qb);
        const WorldPoly wb = world_poly(b, xb);
        const BruteForce truth = brute_force(wa, wb);
        const Real face = std::max(truth.face_a, truth.face_b);
        const Real deepest = std::max(face, truth.edge);

        const auto m = test::run(a, xa, b, xb, speculative);
        if (face > speculative + kTie) {
            EXPECT_TRUE(m.empty()) << "seed " << seed << " pose " << i << ": apart by " << face;
            ++tally.apart;
            continue;
        }
        if (deepest > -kTie) continue;
        ASSERT_EQ(m.size(), 1u) << "seed " << seed << " pose " << i << ": overlapping by " << deepest;
        const Real shown = separation_along(wa, wb, m[0].normal);
        const Real sat_a = swapped ? truth.face_b : truth.face_a;
        const Real sat_b = swapped ? truth.face_a : truth.face_b;
        const Real edge_bar = face + 0.02 * std::abs(face) + 5e-4;  // clearly_greater's
        const Real face_bar = sat_a + 0.02 * std::abs(sat_a) + 5e-4;
        if (std::abs(truth.edge - edge_bar) < kTie || std::abs(sat_b - face_bar) < kTie) continue;
        if (detail::clearly_greater(truth.edge, face)) {
            EXPECT_NEAR(shown, truth.edge, kTie) << "seed " << seed << " pose " << i << ": the edge pair's axis";
            EXPECT_EQ(m[0].point_count, 1) << "seed " << seed << " pose " << i;
            ++tally.edge;
        } else {
            const Real expected = detail::clearly_greater(sat_b, sat_a) ? sat_b : sat_a;
            EXPECT_NEAR(shown, expected, kTie) << "seed " << seed << " pose " << i << ": a face's axis";
            ++tally.face;
        }
    }
}

TEST(SatAxes, HullPairsPickTheBruteForceAxis) {
    std::mt19937 random(7);
    const Shape pile_hull = random_hull(random, 2, 32);
    const Shape other_pile_hull = random_hull(random, 2, 32);
    const Shape coarse = random_hull(random, 1.2, 8);
    const Shape flat = Shape::convex_hull(
        std::vector<Vec3>{Vec3(-1.5, -0.2, -1), Vec3(1.5, -0.2, -1), Vec3(1.5, -0.2, 1), Vec3(-1.5, -0.2, 1),
                          Vec3(-1, 0.2, -0.6), Vec3(1, 0.2, -0.6), Vec3(1, 0.2, 0.6), Vec3(-1, 0.2, 0.6)});
    Tally tally;
    expect_brute_force_axes(pile_hull, other_pile_hull, 150, 1, tally);
    expect_brute_force_axes(pile_hull, pile_hull, 100, 2, tally);
    expect_brute_force_axes(coarse, pile_hull, 200, 3, tally);
    expect_brute_force_axes(pile_hull, coarse, 200, 4, tally);
    expect_brute_force_axes(flat, coarse, 300, 5, tally);
    expect_brute_force_axes(coarse, coarse, 300, 6, tally);
    // Each answer is judged often enough that a dropped winner would show.
    EXPECT_GT(tally.edge, 150);
    EXPECT_GT(tally.face, 250);
    EXPECT_GT(tally.apart, 400);
}

TEST(SatAxes, BoxHullPairsPickTheBruteForceAxisEitherWayRound) {
    std::mt19937 random(11);
    const Shape hull = random_hull(random, 1.5, 20);
    const Shape box = Shape::box(Vec3(1.2, 0.4, 0.7));
    Tally tally;
    expect_brute_force_axes(box, hull, 300, 7, tally);
    expect_brute_force_axes(hull, box, 300, 8, tally);
    EXPECT_GT(tally.edge, 80);
    EXPECT_GT(tally.face, 80);
    EXPECT_GT(tally.apart, 200);
}

}  // namespace
}  // namespace spindle
