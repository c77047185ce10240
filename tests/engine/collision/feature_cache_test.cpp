// FeatureCache (collide_cached): a box or hull pair that stays apart is told so by the axis
// that last separated it, with the same result as the whole SAT; a touching pair rebuilds
// its manifold from the feature that last made it while the separation along that
// feature's axis stays within the slop, and that manifold must be one of the pair. Checked
// against collide() without a cache along tumbling paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <spindle/engine/settings.hpp>
#include <spindle/engine/space.hpp>

#include "collision/triangle_mesh.hpp"
#include "collision_test_util.hpp"
#include "static_bodies.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;

// A hull of 32 (or `count`) points on a sphere of radius r, as Box3D's convex_pile draws them.
Shape random_hull(std::uint32_t seed, Real r, int count = 32) {
    std::mt19937 random(seed);
    std::normal_distribution<Real> normal(0, 1);
    std::vector<Vec3> points;
    for (int i = 0; i < count; ++i)
        points.push_back(r * Vec3(normal(random), normal(random), normal(random)).normalized());
    return Shape::convex_hull(points);
}

// How far a point (world) is outside the shape's face planes: 0 on its surface, except
// beside an edge or corner, where it is less than the distance.
Real plane_distance(const Shape& shape, const Transform& x, const Vec3& world) {
    const Vec3 p = x.apply_inverse(world);
    if (shape.type == ShapeType::Box) return (p.cwiseAbs() - shape.half_extents).maxCoeff();
    Real d = -kHuge;
    for (const HullFace& f : shape.hull->faces()) d = std::max(d, f.normal.dot(p) - f.offset);
    return d;
}

void expect_same(const Manifold* x, int nx, const Manifold* y, int ny, int step) {
    ASSERT_EQ(nx, ny) << "step " << step;
    for (int m = 0; m < nx; ++m) {
        ASSERT_EQ(x[m].point_count, y[m].point_count) << "step " << step;
        EXPECT_EQ(x[m].normal, y[m].normal) << "step " << step;
        for (int j = 0; j < x[m].point_count; ++j) {
            EXPECT_EQ(x[m].points[j].point, y[m].points[j].point) << "step " << step;
            EXPECT_EQ(x[m].points[j].separation, y[m].points[j].separation) << "step " << step;
            EXPECT_EQ(x[m].points[j].id, y[m].points[j].id) << "step " << step;
        }
    }
}

// The largest angle between the normals of two faces that share an edge.
Real widest_neighbour_angle(const Shape& shape) {
    if (shape.type == ShapeType::Box) return kPi / 2;
    Real widest = 0;
    for (const HullEdge& e : shape.hull->edges()) {
        const Real cosine = shape.hull->faces()[e.f0].normal.dot(shape.hull->faces()[e.f1].normal);
        widest = std::max(widest, std::acos(std::clamp(cosine, Real(-1), Real(1))));
    }
    return widest;
}

// B tumbles past A (and through it) while both turn: the pair is apart, touching and apart
// again, each way round, with face, edge and swapped (hull-box) axes. Slowly (8 mm and
// 0.2 degrees a call), so that a touching feature is often kept.
struct Tumble {
    Shape a, b;
    Real slop = SolverSettings{}.linear_slop;
    int apart = 0, cached_apart = 0, touching = 0, reused = 0;

    void run(std::uint32_t seed) {
        constexpr int kSteps = 1500;
        constexpr Real kSpeculative = 0.1;
        // How deep a resting pair goes: the solver lets it sink a slop, speculative
        // contacts stop it before much more.
        const Real shallow = 4 * slop;
        const Real neighbour_angle = std::max(widest_neighbour_angle(a), widest_neighbour_angle(b));
        FeatureCache cache;
        TriangleFeatures triangles;  // unused: no mesh
        std::mt19937 random(seed);
        std::uniform_real_distribution<Real> u(-1, 1);
        const Vec3 axis_a(u(random), u(random), u(random)), axis_b(u(random), u(random), u(random));
        const Vec3 start(u(random), 6, u(random)), end(u(random), -6, u(random));
        for (int step = 0; step <= kSteps; ++step) {
            const Real t = Real(step) / kSteps;
            const Transform xa = at(Vec3::Zero(), about(axis_a, 2 * t));
            const Transform xb = at(start + t * (end - start), about(axis_b, 5 * t));
            const FeatureCache before = cache;
            Manifold cached[8], plain[8];
            const int nc = collide_cached(a, xa, b, xb, kSpeculative, cached, 8, cache, triangles, slop);
            const int np = collide(a, xa, b, xb, kSpeculative, plain, 8);
            EXPECT_NE(cache.kind(), FeatureCache::Kind::None) << "step " << step;
            if (np == 0) {
                // Apart: the whole SAT's answer, bit for bit.
                expect_same(cached, nc, plain, np, step);
                apart += 1;
                cached_apart += before.kind() != FeatureCache::Kind::None && before == cache;
                continue;
            }
            ASSERT_EQ(nc, 1) << "step " << step << ": a touching pair lost its manifold";
            touching += 1;
            // The whole SAT writes the separation it finds; a kept feature keeps the old one.
            if (before.kind() == FeatureCache::Kind::None || !(before == cache)) {
                expect_same(cached, nc, plain, np, step);
                continue;
            }
            reused += 1;
            const Manifold& c = cached[0];
            const Manifold& p = plain[0];
            // Each point lies midway between a point of A's surface and one of B's
            // (rounding apart), within reach.
            for (int j = 0; j < c.point_count; ++j) {
                const ManifoldPoint& q = c.points[j];
                EXPECT_LE(q.separation, kSpeculative) << "step " << step;
                EXPECT_NEAR(plane_distance(a, xa, q.point - Real(0.5) * q.separation * c.normal), 0, 1e-9)
                    << "step " << step;
                EXPECT_NEAR(plane_distance(b, xb, q.point + Real(0.5) * q.separation * c.normal), 0, 1e-9)
                    << "step " << step;
            }
            // Overlapping deeply (a path through A, never a resting pair), the whole SAT's
            // least overlap jumps between far apart axes, and a kept feature may be any of
            // them: only the above holds there.
            if (deepest(p) < -shallow) continue;
            // Near touching, the kept feature is the whole SAT's or, where the SAT has just
            // moved on to a neighbour, that neighbour's: its normal is at most one
            // neighbouring face's angle off, and its deepest point within the slop of the
            // SAT's (the kept separation along its axis drifted by less than the slop).
            const Real angle = std::acos(std::clamp(c.normal.dot(p.normal), Real(-1), Real(1)));
            EXPECT_LE(angle, neighbour_angle) << "step " << step;
            EXPECT_NEAR(deepest(c), deepest(p), slop) << "step " << step;
        }
    }
};

TEST(FeatureCache, HullPairsKeepTheSATsAnswerApartAndAValidManifoldTouching) {
    for (std::uint32_t seed = 1; seed <= 12; ++seed) {
        Tumble tumble{random_hull(seed, 2), random_hull(seed + 100, 1.5)};
        tumble.run(seed);
        EXPECT_GT(tumble.touching, 100) << "seed " << seed;
        // Most steps apart keep the axis that separated the step before; a path straight
        // through A changes the separation along a touching feature's axis by more than
        // the slop in most steps, but not in all.
        EXPECT_GT(tumble.cached_apart, tumble.apart / 2) << "seed " << seed;
        EXPECT_GT(tumble.reused, 0) << "seed " << seed;
    }
}

TEST(FeatureCache, BoxHullPairsKeepTheSATsAnswerApartAndAValidManifoldTouchingEitherWayRound) {
    for (std::uint32_t seed = 1; seed <= 6; ++seed) {
        Tumble box_first{Shape::box(Vec3(1.5, 0.4, 1)), random_hull(seed, 1.5)};
        box_first.run(seed);
        Tumble hull_first{random_hull(seed, 1.5), Shape::box(Vec3(1.5, 0.4, 1))};
        hull_first.run(seed);
        for (const Tumble* tumble : {&box_first, &hull_first}) {
            EXPECT_GT(tumble->touching, 100) << "seed " << seed;
            EXPECT_GT(tumble->reused, 0) << "seed " << seed;
        }
    }
}

// A hull resting on a box floor, sliding and spinning about the vertical: the separation
// along the floor's face stays where it was, so after the first test every one keeps the
// floor's face, and the manifold is the whole SAT's.
TEST(FeatureCache, HullSlidingOnAFloorKeepsTheFloorsFace) {
    const Shape floor = Shape::box(Vec3(50, 1, 50));
    const Shape hull = random_hull(7, 1.5);
    const Vec3 down = hull.hull->support(Vec3(0, -1, 0));
    FeatureCache cache;
    TriangleFeatures triangles;
    int reused = 0;
    constexpr int kSteps = 200;
    for (int step = 0; step < kSteps; ++step) {
        const Transform xa = at(Vec3(0, -1, 0));
        // 0.002 into the floor, 5 cm and 3 degrees further each call.
        const Transform xb = at(Vec3(0.05 * step, -0.002 - down.y(), 0.02 * step), about(Vec3::UnitY(), 0.05 * step));
        const FeatureCache before = cache;
        Manifold cached[8], plain[8];
        ASSERT_EQ(collide_cached(floor, xa, hull, xb, 0.1, cached, 8, cache, triangles, 0.005), 1) << "step " << step;
        ASSERT_EQ(collide(floor, xa, hull, xb, 0.1, plain, 8), 1) << "step " << step;
        EXPECT_EQ(cache.kind(), FeatureCache::Kind::FaceA) << "step " << step;  // the box is the pair function's A
        reused += before == cache;
        EXPECT_NEAR(cached[0].normal.dot(plain[0].normal), 1, 1e-12) << "step " << step;
        EXPECT_NEAR(deepest(cached[0]), deepest(plain[0]), 1e-12) << "step " << step;
    }
    EXPECT_EQ(reused, kSteps - 1);
}

// Two cubes touching edge on edge; then B slides along A's edge, past its end. The axis of
// the two edges and the separation along it do not change, but the edges no longer cross:
// the kept pair must not stand for a contact, and the whole SAT finds the cubes apart.
TEST(FeatureCache, EdgesThatNoLongerCrossAreNotKept) {
    const Shape cube = test::hull_box(Vec3(1, 1, 1));
    const Real s2 = std::sqrt(2.0);
    const Transform xa = at(Vec3::Zero(), about(Vec3::UnitZ(), kPi / 4));  // top edge along z
    const Quat qb = about(Vec3::UnitX(), kPi / 4);                         // bottom edge along x
    FeatureCache cache;
    TriangleFeatures triangles;
    Manifold out[8];
    ASSERT_EQ(collide_cached(cube, xa, cube, at(Vec3(0, 2 * s2 - 0.1, 0), qb), 0, out, 8, cache, triangles, 0.005), 1);
    ASSERT_EQ(cache.kind(), FeatureCache::Kind::EdgePair);
    EXPECT_EQ(collide_cached(cube, xa, cube, at(Vec3(0, 2 * s2 - 0.1, 1.5), qb), 0, out, 8, cache, triangles, 0.005),
              0);
}

// With no slop allowed, a touching pair never keeps its feature: the same manifolds,
// bit for bit, as the whole SAT.
TEST(FeatureCache, NoSlopGivesTheSATsManifolds) {
    for (std::uint32_t seed = 1; seed <= 4; ++seed) {
        Tumble tumble{random_hull(seed, 2), random_hull(seed + 100, 1.5)};
        tumble.slop = 0;
        tumble.run(seed);
        EXPECT_GT(tumble.touching, 100) << "seed " << seed;
        EXPECT_EQ(tumble.reused, 0) << "seed " << seed;
    }
}

// A pile of hulls (box-hull with the floor, hull-hull among themselves) keeps touching
// features while it settles; the manifolds they give must still let it come to rest and
// sleep, deep in no contact.
TEST(FeatureCache, HullPileComesToRestAndSleeps) {
    Space space;
    test::add_static_box(space, Vec3(20, 1, 20), Vec3(0, -1, 0));
    std::vector<BodyHandle> hulls;
    for (int layer = 0; layer < 4; ++layer) {
        for (int i = 0; i < 9; ++i) {
            BodyDesc d;
            // Fewer points than convex_pile's: a rounder hull can roll on alone for long.
            d.shape = random_hull(static_cast<std::uint32_t>(10 * layer + i), 0.5, 12);
            d.position = Vec3(1.2 * (i % 3) + 0.2 * layer, 0.6 + 1.1 * layer, 1.2 * (i / 3));
            hulls.push_back(space.create_body(d));
        }
    }
    const auto all_asleep = [&] {
        return std::none_of(hulls.begin(), hulls.end(), [&](BodyHandle h) { return space.internal_is_awake(h); });
    };
    int steps = 0;
    for (; steps < 1200 && !all_asleep(); ++steps) space.update();
    EXPECT_TRUE(all_asleep()) << "after " << steps << " steps";
    for (BodyHandle h : hulls) EXPECT_GT(space.position(h).y(), 0) << "a hull sank through the floor";
}

// A flat mesh of 1 m squares (two triangles each) on y = 0, 10 m a side about the origin.
Shape flat_mesh() {
    constexpr int kCells = 10;
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    for (int z = 0; z <= kCells; ++z)
        for (int x = 0; x <= kCells; ++x) v.emplace_back(x - kCells / 2, 0, z - kCells / 2);
    for (int z = 0; z < kCells; ++z) {
        for (int x = 0; x < kCells; ++x) {
            const auto i = static_cast<std::uint32_t>(z * (kCells + 1) + x);
            const std::uint32_t row = kCells + 1;
            for (const std::uint32_t k : {i, i + row, i + 1, i + 1, i + row, i + row + 1}) idx.push_back(k);
        }
    }
    return Shape::triangle_mesh(v, idx);
}

// Two box hulls side by side and a round hull: flat faces that lie on a flat mesh, each
// part meeting triangles of its own and some the others meet too.
Shape three_parts() {
    const std::vector<CompoundPart> parts = {{test::hull_box(Vec3(0.6, 0.3, 0.4)), Vec3(-0.8, 0, 0)},
                                             {test::hull_box(Vec3(0.5, 0.3, 0.5)), Vec3(0.6, 0, 0.3),
                                              about(Vec3::UnitY(), 0.4)},
                                             {random_hull(5, 0.5), Vec3(0, 0.9, 0)}};
    return Shape::compound(parts);
}

// The compound posed by q at (x, z), sunk `depth` into the plane y = 0.
Transform sunk(const Shape& shape, Real x, Real z, const Quat& q, Real depth) {
    return at(Vec3(x, -depth - shape.bounds(at(Vec3::Zero(), q)).min.y(), z), q);
}

// Each manifold of the cached collide against the whole SAT's, either way round: the same
// count, normals and deepest points (exactly, but for rounding).
void expect_close(const Manifold* x, int nx, const Manifold* y, int ny, int step) {
    ASSERT_EQ(nx, ny) << "step " << step;
    for (int m = 0; m < nx; ++m) {
        EXPECT_NEAR(x[m].normal.dot(y[m].normal), 1, 1e-12) << "step " << step;
        EXPECT_NEAR(deepest(x[m]), deepest(y[m]), 1e-12) << "step " << step;
        EXPECT_EQ(x[m].part_a, y[m].part_a) << "step " << step;
        EXPECT_EQ(x[m].part_b, y[m].part_b) << "step " << step;
    }
}

// A compound sliding and spinning on a mesh, its flat faces a few mm in: the triangles it met
// the call before keep the face that lay on them, found again by part and triangle; the
// manifolds are the whole SAT's.
TEST(FeatureCache, CompoundSlidingOnAMeshKeepsItsTrianglesFeatures) {
    const Shape mesh = flat_mesh();
    const Shape tree = three_parts();
    const Transform xm = at(Vec3::Zero());
    FeatureCache cache;
    TriangleFeatures triangles;
    constexpr int kSteps = 60;
    for (int step = 0; step < kSteps; ++step) {
        const Quat q = about(Vec3::UnitY(), 0.05 * step);
        // 2 to 3 mm in: a feature the whole SAT found again would hold the new depth.
        const Transform xt = sunk(tree, -2 + 0.05 * step, -1 + 0.03 * step, q, 0.002 + 0.0005 * (step % 3));
        const TriangleFeatures before = triangles;
        Manifold cached[8], plain[8];
        for (const bool mesh_first : {true, false}) {
            triangles = before;
            const int nc = mesh_first ? collide_cached(mesh, xm, tree, xt, 0.1, cached, 8, cache, triangles, 0.005)
                                      : collide_cached(tree, xt, mesh, xm, 0.1, cached, 8, cache, triangles, 0.005);
            const int np = mesh_first ? collide(mesh, xm, tree, xt, 0.1, plain, 8)
                                      : collide(tree, xt, mesh, xm, 0.1, plain, 8);
            EXPECT_GT(np, 0) << "step " << step;
            expect_close(cached, nc, plain, np, step);
        }
        ASSERT_FALSE(triangles.empty());
        EXPECT_TRUE(std::is_sorted(triangles.begin(), triangles.end(), [](const auto& x, const auto& y) {
            return std::pair(x.part, x.triangle) < std::pair(y.part, y.triangle);
        }));
        int kept = 0;
        for (const TriangleFeature& now : triangles) {
            for (const TriangleFeature& was : before) {
                kept += was.part == now.part && was.triangle == now.triangle &&
                        was.feature.kind() != FeatureCache::Kind::None && was.feature == now.feature;
            }
        }
        // Both boxes stay on triangles they were on.
        if (step > 0) {
            EXPECT_GE(kept, 2) << "step " << step;
        }
    }
}

// The same compound resting flat, then turned 0.4 rad about a level axis (still 2 mm in),
// then slid 3 m: the boxes' faces kept on the triangles no longer lie on them, or the
// triangles are others, and each collide must be the whole SAT's, bit for bit.
TEST(FeatureCache, MeshTrianglesFeaturesGoStaleWhenTheCompoundTurnsOrMoves) {
    const Shape mesh = flat_mesh();
    const Shape tree = three_parts();
    const Transform xm = at(Vec3::Zero());
    const Quat turned = about(Vec3(1, 0, 0.5), 0.4);
    const Transform poses[] = {sunk(tree, 0.2, 0.1, Quat::Identity(), 0.002), sunk(tree, 0.2, 0.1, turned, 0.002),
                               sunk(tree, 3.2, 0.1, turned, 0.002)};
    FeatureCache cache;
    TriangleFeatures triangles;
    for (int step = 0; step < 3; ++step) {
        Manifold cached[8], plain[8];
        const int nc = collide_cached(tree, poses[step], mesh, xm, 0.1, cached, 8, cache, triangles, 0.005);
        const int np = collide(tree, poses[step], mesh, xm, 0.1, plain, 8);
        EXPECT_GT(np, 0) << "step " << step;
        expect_same(cached, nc, plain, np, step);
    }
}

// The compound creeping on the mesh (1 mm and 0.002 rad a call), jumping 1.5 m halfway:
// while its parts' query boxes stay inside the boxes kept with their triangles the mesh is
// not queried again, after the jump it must be, and every collide gives what the same
// collide without kept queries gives, bit for bit (the features kept the same way).
TEST(MeshQueries, KeptWhileThePartsStayNearAndMadeAgainWhenTheyLeave) {
    const Shape mesh = flat_mesh();
    const Shape tree = three_parts();
    const Transform xm = at(Vec3::Zero());
    FeatureCache cache, plain_cache;
    TriangleFeatures triangles, plain_triangles;
    MeshQueries queries;
    int kept = 0, made = 0;
    constexpr int kSteps = 60;
    for (int step = 0; step < kSteps; ++step) {
        const Real x = -2 + 0.001 * step + (step >= kSteps / 2 ? 1.5 : 0);
        const Transform xt = sunk(tree, x, 0.3, about(Vec3::UnitY(), 0.002 * step), 0.002);
        const std::vector<MeshQuery> before = queries.parts;
        Manifold with[8], without[8];
        const int nw = collide_cached(tree, xt, mesh, xm, 0.1, with, 8, cache, triangles, 0.005, {}, nullptr, &queries);
        const int nn = collide_cached(tree, xt, mesh, xm, 0.1, without, 8, plain_cache, plain_triangles, 0.005);
        EXPECT_GT(nn, 0) << "step " << step;
        expect_same(with, nw, without, nn, step);
        ASSERT_EQ(queries.parts.size(), 2u) << "step " << step;  // the boxes: the round hull is above the mesh's box
        bool same_boxes = before.size() == queries.parts.size();
        for (std::size_t i = 0; same_boxes && i < before.size(); ++i) {
            same_boxes = before[i].box.min == queries.parts[i].box.min && before[i].box.max == queries.parts[i].box.max;
        }
        if (step == kSteps / 2) {
            EXPECT_FALSE(same_boxes) << "the parts left their boxes: the mesh is queried again";
        }
        (same_boxes ? kept : made) += 1;
    }
    // Made at the start and after the jump; a 0.1 m margin holds some 30 mm of creep and turn.
    EXPECT_GT(kept, kSteps - 10);
    EXPECT_GE(made, 2);
}

// The compound resting on the flat mesh with its queries kept, then the same queries met
// with a mesh whose triangles are others (a bump raised under a part, the tree's order
// new): the bump must be found as the whole SAT finds it, not the last mesh's triangles.
TEST(MeshQueries, ATriangleRaisedUnderARestingPartIsFoundOnANewMesh) {
    const Shape flat = flat_mesh();
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    for (const Vec3& p : flat.mesh->vertices()) v.push_back(p);
    for (const MeshTriangle& t : flat.mesh->triangles()) idx.insert(idx.end(), {t.v[0], t.v[1], t.v[2]});
    // A small steep tent under the first box part (about x = -1.8 when the compound is at -1).
    const auto first = static_cast<std::uint32_t>(v.size());
    v.insert(v.end(), {Vec3(-2.0, -0.05, 0.2), Vec3(-1.7, -0.05, 0.6), Vec3(-1.6, 0.05, 0.3)});
    idx.insert(idx.end(), {first, first + 1, first + 2});
    const Shape bumped = Shape::triangle_mesh(v, idx);
    const Shape tree = three_parts();
    const Transform xm = at(Vec3::Zero());
    const Transform xt = sunk(tree, -1, 0.3, Quat::Identity(), 0.002);
    FeatureCache cache;
    TriangleFeatures triangles;
    MeshQueries queries;
    Manifold out[8], plain[8];
    for (int step = 0; step < 5; ++step)
        collide_cached(tree, xt, flat, xm, 0.1, out, 8, cache, triangles, 0.005, {}, nullptr, &queries);
    const int n = collide_cached(tree, xt, bumped, xm, 0.1, out, 8, cache, triangles, 0.005, {}, nullptr, &queries);
    const int np = collide(tree, xt, bumped, xm, 0.1, plain, 8);
    Real flat_deepest = kHuge, deepest_with = kHuge, deepest_plain = kHuge;
    Manifold flat_out[8];
    const int nf = collide(tree, xt, flat, xm, 0.1, flat_out, 8);
    for (int m = 0; m < nf; ++m) flat_deepest = std::min(flat_deepest, deepest(flat_out[m]));
    for (int m = 0; m < n; ++m) deepest_with = std::min(deepest_with, deepest(out[m]));
    for (int m = 0; m < np; ++m) deepest_plain = std::min(deepest_plain, deepest(plain[m]));
    EXPECT_LT(deepest_plain, flat_deepest - 0.02) << "the bump reaches into the part";
    EXPECT_EQ(deepest_with, deepest_plain);
    ASSERT_EQ(n, np);
    for (int m = 0; m < n; ++m) EXPECT_EQ(out[m].normal, plain[m].normal) << "manifold " << m;
}

// A hexagonal log (3 m along x, 0.5 m radius) with a face straight down.
Shape hexagonal_log() {
    std::vector<Vec3> prism;
    for (int k = 0; k < 6; ++k) {
        const Real angle = k * kPi / 3 + kPi / 6;
        for (const Real x : {-1.5, 1.5}) prism.emplace_back(x, 0.5 * std::cos(angle), 0.5 * std::sin(angle));
    }
    return Shape::convex_hull(prism);
}

// A collide of `a` with the flat mesh through its triangles' caches beside one without
// (the whole SAT each triangle): they must touch and give the same manifolds, bit for bit.
void expect_cached_is_whole_sat(const Shape& a, const Transform& xa, const Shape& mesh, FeatureCache& cache,
                                TriangleFeatures& triangles, int step) {
    const Transform xm = at(Vec3::Zero());
    Manifold cached[8], plain[8];
    const int nc = collide_cached(a, xa, mesh, xm, 0.1, cached, 8, cache, triangles, 0.005);
    const int np = collide(a, xa, mesh, xm, 0.1, plain, 8);
    ASSERT_GT(np, 0) << "step " << step;
    expect_same(cached, nc, plain, np, step);
}

// A hexagonal log (3 m, 0.5 m radius) lying on a face on the flat mesh, one end 1.15 degrees
// up, creeping along: the triangles under its raised length meet its bottom face (or an edge)
// in the SAT, whose normal the mesh does not admit, and the contact is measured again against
// each triangle's face. That face is kept as the triangle's feature, so the next collide clips
// it alone (no whole SAT and no second clip), and every collide is the whole SAT's, bit for bit.
TEST(FeatureCache, ATrianglesFaceAContactWasMeasuredAgainIsKeptAndMakesTheSameManifold) {
    const Shape log = hexagonal_log();
    const Shape mesh = flat_mesh();
    const Quat q = about(Vec3::UnitY(), 0.3) * about(Vec3::UnitZ(), 0.02);
    FeatureCache cache;
    TriangleFeatures triangles;
    int faces_kept = 0;
    for (int step = 0; step < 20; ++step) {
        const Transform xl = sunk(log, -0.5 + 0.002 * step, 0.2, q, 0.003);
        const TriangleFeatures before = triangles;
        ASSERT_NO_FATAL_FAILURE(expect_cached_is_whole_sat(log, xl, mesh, cache, triangles, step));
        int faces = 0;
        for (const TriangleFeature& t : triangles) {
            const bool face = t.feature == FeatureCache(FeatureCache::Kind::FaceB, 0, 0, t.feature.separation());
            faces += face;
            for (const TriangleFeature& was : before)
                faces_kept += face && was.triangle == t.triangle && was.feature == t.feature;
        }
        // Of its 30 triangles, the SAT gives the low end's two their own face; the raised
        // length's (ten or more) are measured again and keep it too.
        EXPECT_GE(faces, 8) << "step " << step;
    }
    EXPECT_GT(faces_kept, 0);
}

// The same log rolled onto a long edge (29 degrees: its two faces there lean 29 and 31 degrees
// off the mesh): a triangle beside that edge, under the steeper face, gets the SAT's face of
// the log, and measured again against the triangle's face the incident face (the other one)
// clips to nothing over it, so the log's faces over the triangle are clipped instead. That
// face is kept too, marked as measured over it (FaceB, index_a 1): the next collide measures
// it over the face again, with no whole SAT, and every collide is the whole SAT's bit for bit.
TEST(FeatureCache, ATrianglesFaceMeasuredPastTheIncidentFaceIsKeptAndMakesTheSameManifold) {
    const Shape log = hexagonal_log();
    const Shape mesh = flat_mesh();
    const Quat q = about(Vec3::UnitY(), 0.3) * about(Vec3::UnitX(), kPi / 6 - 0.035);
    const FeatureCache over(FeatureCache::Kind::FaceB, 1, 0);
    FeatureCache cache;
    TriangleFeatures triangles;
    int measured_over = 0, kept = 0;
    for (int step = 0; step < 20; ++step) {
        // Sinking 0.2 mm a call: a face kept is kept with the separation it was measured at.
        const Transform xl = sunk(log, -0.5 + 0.002 * step, 0.2, q, 0.003 + 0.0002 * step);
        const TriangleFeatures before = triangles;
        ASSERT_NO_FATAL_FAILURE(expect_cached_is_whole_sat(log, xl, mesh, cache, triangles, step));
        for (const TriangleFeature& t : triangles) {
            const bool is_over = t.feature == FeatureCache(over.kind(), 1, 0, t.feature.separation());
            measured_over += is_over;
            for (const TriangleFeature& was : before)
                kept += is_over && was.triangle == t.triangle && was.feature == t.feature;
        }
    }
    EXPECT_GT(measured_over, 0);
    EXPECT_GT(kept, 0);
}

TEST(FeatureCache, OtherPairsClearIt) {
    FeatureCache cache(FeatureCache::Kind::FaceA, 3, 0);
    TriangleFeatures triangles;
    Manifold out[8];
    const Shape box = Shape::box(Vec3(1, 1, 1));
    EXPECT_EQ(collide_cached(box, at(Vec3::Zero()), box, at(Vec3(0, 1.9, 0)), 0, out, 8, cache, triangles, 0.005), 1);
    EXPECT_EQ(cache.kind(), FeatureCache::Kind::None);
}

}  // namespace
}  // namespace spindle
