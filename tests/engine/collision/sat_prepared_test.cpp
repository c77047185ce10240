// What a hull keeps made for the SAT (its vertices in lanes, its edges' Gauss-map arcs)
// must be what the SAT would make from the hull's vertices, faces and edges: read in
// place of arcs made per pair, it must give the same bits.
#include <gtest/gtest.h>

#include <random>

#include "collision/pair_functions.hpp"
#include "collision/polyhedron.hpp"
#include "collision/sat_prepared.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::at;
using test::random_turn;

std::vector<Vec3> sphere_points(std::mt19937& random, Real r, int count) {
    std::normal_distribution<Real> normal(0, 1);
    std::vector<Vec3> points;
    for (int i = 0; i < count; ++i)
        points.push_back(r * Vec3(normal(random), normal(random), normal(random)).normalized());
    return points;
}

// The hull's view without what it keeps made: the SAT makes the lanes and arcs per test.
detail::PolyView unprepared(const ConvexHull& hull) {
    detail::PolyView v = detail::view_of(hull);
    v.vertex_lanes = nullptr;
    v.arc_edges = nullptr;
    v.arc_lanes = nullptr;
    return v;
}

void expect_same_bits(const Vec3& got, const Vec3& expected, const char* what, std::size_t j) {
    for (int i = 0; i < 3; ++i) EXPECT_EQ(got[i], expected[i]) << what << " of edge " << j << ", coordinate " << i;
}

void expect_same_manifold(const Manifold& got, const Manifold& expected, int pose) {
    ASSERT_EQ(got.point_count, expected.point_count) << "pose " << pose;
    for (int i = 0; i < 3; ++i) EXPECT_EQ(got.normal[i], expected.normal[i]) << "pose " << pose;
    for (int k = 0; k < got.point_count; ++k) {
        for (int i = 0; i < 3; ++i) EXPECT_EQ(got.points[k].point[i], expected.points[k].point[i]) << "pose " << pose;
        EXPECT_EQ(got.points[k].separation, expected.points[k].separation) << "pose " << pose;
        EXPECT_EQ(got.points[k].id, expected.points[k].id) << "pose " << pose;
    }
}

TEST(SatPrepared, HullKeepsTheArcsOfItsEdges) {
    std::mt19937 random(11);
    for (const int count : {4, 8, 32, 64}) {
        const ConvexHull hull(sphere_points(random, 1.5, count));
        const auto vertices = hull.vertices();
        const auto faces = hull.faces();
        ASSERT_EQ(hull.arc_edges().size(), hull.edges().size());
        for (std::size_t j = 0; j < hull.edges().size(); ++j) {
            const HullEdge& e = hull.edges()[j];
            const detail::ArcEdge& a = hull.arc_edges()[j];
            const Vec3 direction = vertices[e.v1] - vertices[e.v0];
            expect_same_bits(a.origin, vertices[e.v0], "origin", j);
            expect_same_bits(a.direction, direction, "direction", j);
            expect_same_bits(a.n0, faces[e.f0].normal, "n0", j);
            expect_same_bits(a.n1, faces[e.f1].normal, "n1", j);
            expect_same_bits(a.t0, direction.cross(faces[e.f0].normal), "t0", j);
            expect_same_bits(a.t1, faces[e.f1].normal.cross(direction), "t1", j);
        }
        // The same arcs four in lanes; lanes past the last edge a unit direction, zero normals.
        ASSERT_EQ(hull.arc_lanes().size(), (hull.edges().size() + 3) / 4);
        for (std::size_t j = 0; j < 4 * hull.arc_lanes().size(); ++j) {
            const detail::ArcLanes& l = hull.arc_lanes()[j / 4];
            const std::size_t k = j % 4;
            const bool edge = j < hull.edges().size();
            const detail::ArcEdge none{Vec3::Zero(), Vec3::UnitX(), Vec3::Zero(),
                                       Vec3::Zero(), Vec3::Zero(),  Vec3::Zero()};
            const detail::ArcEdge& a = edge ? hull.arc_edges()[j] : none;
            expect_same_bits(Vec3(l.dx[k], l.dy[k], l.dz[k]), a.direction, "direction in lanes", j);
            expect_same_bits(Vec3(l.n0x[k], l.n0y[k], l.n0z[k]), a.n0, "n0 in lanes", j);
            expect_same_bits(Vec3(l.n1x[k], l.n1y[k], l.n1z[k]), a.n1, "n1 in lanes", j);
            expect_same_bits(Vec3(l.t0x[k], l.t0y[k], l.t0z[k]), a.t0, "t0 in lanes", j);
            expect_same_bits(Vec3(l.t1x[k], l.t1y[k], l.t1z[k]), a.t1, "t1 in lanes", j);
            EXPECT_EQ(l.dd[k], a.direction.squaredNorm()) << "squared length of edge " << j;
        }
        ASSERT_EQ(hull.vertex_lanes().size(), (vertices.size() + 3) / 4);
        for (std::size_t i = 0; i < 4 * hull.vertex_lanes().size(); ++i) {
            const detail::VertexLanes& group = hull.vertex_lanes()[i / 4];
            const Vec3& v = vertices[i < vertices.size() ? i : 0];  // past the end: vertex 0
            EXPECT_EQ(group.x[i % 4], v.x()) << "lane " << i;
            EXPECT_EQ(group.y[i % 4], v.y()) << "lane " << i;
            EXPECT_EQ(group.z[i % 4], v.z()) << "lane " << i;
        }
    }
}

// The edge query bounds each of A's edges by how far its arc reaches along a direction,
// four edges at a time: each lane must give the bits of the single edge's bound, on the
// arc (the square root) and at its ends, for hulls' edges and a box's, and for directions
// of any length, among them ones on an arc's end planes.
TEST(SatPrepared, ArcsInLanesReachAsFarAsEachArcAlone) {
    std::mt19937 random(17);
    std::vector<detail::ArcEdge> arcs;
    for (const int count : {8, 24}) {
        const ConvexHull hull(sphere_points(random, 1.3, count));
        arcs.insert(arcs.end(), hull.arc_edges().begin(), hull.arc_edges().end());
    }
    const ConvexHull cube(std::vector<Vec3>{Vec3(-1, -1, -1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(1, 1, -1),
                                            Vec3(-1, -1, 1), Vec3(1, -1, 1), Vec3(-1, 1, 1), Vec3(1, 1, 1)});
    arcs.insert(arcs.end(), cube.arc_edges().begin(), cube.arc_edges().end());
    arcs.resize(arcs.size() - arcs.size() % 4 - 2);  // a last group with two lanes past the end
    std::vector<detail::ArcLanes> lanes((arcs.size() + 3) / 4);
    detail::fill_arc_lanes(arcs.data(), static_cast<std::uint32_t>(arcs.size()), lanes.data());
    std::normal_distribution<Real> normal(0, 1);
    std::uniform_real_distribution<Real> length(0.01, 5);
    int on_arc = 0, at_end = 0;
    for (int trial = 0; trial < 400; ++trial) {
        Vec3 d = length(random) * Vec3(normal(random), normal(random), normal(random)).normalized();
        if (trial % 8 == 0) d = arcs[trial % arcs.size()].n0;  // on an end plane of that arc
        for (std::size_t j = 0; j < arcs.size(); ++j) {
            const Real alone = detail::arc_reach(arcs[j], d);
            const Real in_lanes = detail::arc_reach(lanes[j / 4], d)[j % 4];
            EXPECT_EQ(in_lanes, alone) << "edge " << j << ", trial " << trial;
            const bool across = d.dot(arcs[j].t0) >= 0 && d.dot(arcs[j].t1) >= 0;
            on_arc += across;
            at_end += !across;
        }
    }
    // Both ways of bounding are compared, else the test says little.
    EXPECT_GT(on_arc, 1000);
    EXPECT_GT(at_end, 1000);
}

// A triangle's edges (B in the edge query) are made in one group of lanes and bounded
// there: each lane must hold the bits of the arc made for that edge alone (its direction and
// squared length, its faces' normals, and the two products), the lane past the last edge a
// unit direction and zero normals.
TEST(SatPrepared, ATrianglesArcsInLanesAreTheArcsOfItsEdges) {
    std::mt19937 random(19);
    std::normal_distribution<Real> normal(0, 1);
    for (int trial = 0; trial < 200; ++trial) {
        const auto corner = [&] { return Vec3(normal(random), normal(random), normal(random)); };
        const detail::TrianglePoly triangle(corner(), corner(), corner());
        const detail::PolyView v = triangle.view();
        const detail::ArcLanes l = detail::own_arc_lanes(v);
        for (std::uint32_t j = 0; j < 4; ++j) {
            const bool edge = j < v.edge_count;
            const Vec3 direction = edge ? Vec3(v.vertices[v.edges[j].v1] - v.vertices[v.edges[j].v0]) : Vec3::UnitX();
            const Vec3 n0 = edge ? v.faces[v.edges[j].f0].normal : Vec3::Zero();
            const Vec3 n1 = edge ? v.faces[v.edges[j].f1].normal : Vec3::Zero();
            expect_same_bits(Vec3(l.dx[j], l.dy[j], l.dz[j]), direction, "direction", j);
            expect_same_bits(Vec3(l.n0x[j], l.n0y[j], l.n0z[j]), n0, "n0", j);
            expect_same_bits(Vec3(l.n1x[j], l.n1y[j], l.n1z[j]), n1, "n1", j);
            expect_same_bits(Vec3(l.t0x[j], l.t0y[j], l.t0z[j]), direction.cross(n0), "t0", j);
            expect_same_bits(Vec3(l.t1x[j], l.t1y[j], l.t1z[j]), n1.cross(direction), "t1", j);
            EXPECT_EQ(l.dd[j], direction.squaredNorm()) << "squared length of edge " << j;
        }
    }
}

// Hull-hull and box-hull pairs near touching, the hull as A and as B, through the SAT with
// the hulls' kept lanes and arcs and through the SAT making them per test: the same
// manifold and the same cached feature, bit for bit, in every pose.
TEST(SatPrepared, KeptArcsGiveTheBitsOfArcsMadePerTest) {
    std::mt19937 random(5);
    const ConvexHull big(sphere_points(random, 2, 32));
    const ConvexHull small(sphere_points(random, 1.2, 8));
    const detail::BoxPoly box(Vec3(1.5, 0.4, 0.9));
    const detail::PolyView views[] = {detail::view_of(big), detail::view_of(small), box.view()};
    const detail::PolyView plain[] = {unprepared(big), unprepared(small), box.view()};
    std::normal_distribution<Real> normal(0, 1);
    std::uniform_real_distribution<Real> gap(-1.0, 0.2);
    const Real speculative = 0.04;
    int touching = 0, edge_pairs = 0;
    for (int pose = 0; pose < 600; ++pose) {
        const int ia = pose % 3, ib = (pose / 3) % 2;  // B is always a hull
        const Transform xa = at(Vec3(normal(random), normal(random), normal(random)), random_turn(random));
        const Vec3 u = Vec3(normal(random), normal(random), normal(random)).normalized();
        const Transform xb = at(xa.p + (2.5 + gap(random)) * u, random_turn(random));
        FeatureCache kept_cache, plain_cache;
        for (int repeat = 0; repeat < 2; ++repeat) {  // the second time from the cached feature
            Manifold kept, made;
            const bool kept_touch = detail::collide_polyhedra(views[ia], xa, views[ib], xb, speculative, kept,
                                                              &kept_cache, 0.01);
            const bool made_touch = detail::collide_polyhedra(plain[ia], xa, plain[ib], xb, speculative, made,
                                                              &plain_cache, 0.01);
            ASSERT_EQ(kept_touch, made_touch) << "pose " << pose;
            EXPECT_EQ(kept_cache, plain_cache) << "pose " << pose;
            if (!kept_touch) continue;
            ++touching;
            if (kept_cache.kind() == FeatureCache::Kind::EdgePair) ++edge_pairs;
            expect_same_manifold(kept, made, pose);
        }
    }
    // The poses reach both kinds of answer, else the comparison says little.
    EXPECT_GT(touching, 200);
    EXPECT_GT(edge_pairs, 10);
}

// A triangle as B (three vertices) has its support walked vertex by vertex, not in lanes;
// the same triangle padded to five vertices (the last two repeat the first, so the first of
// equals is the same vertex) goes through the lanes. Boxes and hulls near touching it, half
// of them lying square on it (ties in the supports), must get the same manifold and cached
// feature from both, bit for bit.
TEST(SatPrepared, ATriangleWalkedVertexByVertexGivesTheBitsOfLanes) {
    std::mt19937 random(7);
    const ConvexHull hull(sphere_points(random, 1.2, 16));
    const detail::BoxPoly box(Vec3(1.5, 0.4, 0.9));
    const detail::PolyView shapes[] = {box.view(), detail::view_of(hull)};
    const Real heights[] = {0.4, 1.2};
    const detail::TrianglePoly triangle(Vec3(-2, 0, -1), Vec3(0, 0, 2), Vec3(2, 0, -1));
    const detail::PolyView walked = triangle.view();
    const Vec3 padded_vertices[5] = {walked.vertices[0], walked.vertices[1], walked.vertices[2], walked.vertices[0],
                                     walked.vertices[0]};
    detail::PolyView in_lanes = walked;
    in_lanes.vertices = padded_vertices;
    in_lanes.vertex_count = 5;
    const Transform xt = at(Vec3::Zero());
    std::uniform_real_distribution<Real> across(-1.5, 1.5), gap(-0.3, 0.05);
    const Real speculative = 0.04;
    int touching = 0;
    for (int pose = 0; pose < 400; ++pose) {
        const int ia = pose % 2;
        const bool square = pose % 4 < 2;
        const Vec3 p(across(random), heights[ia] + gap(random), across(random));
        const Transform xa = at(p, square ? Quat::Identity() : random_turn(random));
        FeatureCache walked_cache, lanes_cache;
        for (int repeat = 0; repeat < 2; ++repeat) {  // the second time from the cached feature
            Manifold by_vertex, by_lanes;
            const bool touch = detail::collide_polyhedra(shapes[ia], xa, walked, xt, speculative, by_vertex,
                                                         &walked_cache, 0.01);
            const bool lanes_touch = detail::collide_polyhedra(shapes[ia], xa, in_lanes, xt, speculative, by_lanes,
                                                               &lanes_cache, 0.01);
            ASSERT_EQ(touch, lanes_touch) << "pose " << pose;
            EXPECT_EQ(walked_cache, lanes_cache) << "pose " << pose;
            if (!touch) continue;
            ++touching;
            expect_same_manifold(by_vertex, by_lanes, pose);
        }
    }
    EXPECT_GT(touching, 300);
}

// A box or hull near a tilted triangle of a mesh posed off the origin: the feature one test
// keeps, its axis then told from the triangle's three corners (kept_axis_separates) after the
// shape moves and turns a little, must say "apart" exactly when the SAT with that cache ends
// on it (no manifold, the cache untouched), for A's faces and for edge pairs alike.
TEST(SatPrepared, AKeptAxisToldFromTheCornersEndsTheTestAsTheSatDoes) {
    std::mt19937 random(13);
    const ConvexHull hull(sphere_points(random, 1.2, 16));
    const detail::BoxPoly box(Vec3(1.5, 0.4, 0.9));
    const detail::PolyView shapes[] = {box.view(), detail::view_of(hull)};
    const Real reach[] = {1.8, 1.2};  // how far each shape reaches from its centre, about
    const Vec3 corners[3] = {Vec3(-2, 0.3, -1), Vec3(0, -0.2, 2), Vec3(2, 0.1, -1)};
    const Vec3 normal = detail::triangle_normal(corners[0], corners[1], corners[2]);
    const detail::TrianglePoly triangle(corners[0], corners[1], corners[2], normal);
    const Transform xm = at(Vec3(3, -1, 2), test::about(Vec3(1, 2, 0.5), 0.7));
    std::normal_distribution<Real> gauss(0, 1);
    std::uniform_real_distribution<Real> across(-2.5, 2.5), gap(-0.1, 0.3), nudge(-0.05, 0.05), closer(0, 0.3);
    const Real speculative = 0.04;
    int told = 0, told_edges = 0, not_told = 0;
    for (int pose = 0; pose < 1000; ++pose) {
        const int ia = pose % 2;
        const detail::PreparedPolyhedron prepared(shapes[ia]);
        const Vec3 over = corners[1] / 3 + (corners[0] + corners[2]) / 3 + Vec3(across(random), 0, across(random));
        const Vec3 local = over + (reach[ia] + gap(random)) * normal;
        const Transform x0 = at(xm.apply(local), random_turn(random));
        FeatureCache cache;
        Manifold m;
        detail::collide_polyhedra(prepared, x0, triangle.view(), detail::RelativePose(x0, xm), speculative, m, &cache,
                                  0.01);
        const Vec3 turn_axis(gauss(random), gauss(random), gauss(random));
        // Nearer by up to 0.3 m: the kept axis separates them still, or no longer does.
        const Vec3 nearer = -closer(random) * xm.rotate(normal);
        const Transform x1 = at(x0.p + nearer + Vec3(nudge(random), nudge(random), nudge(random)),
                                test::about(turn_axis, nudge(random)) * x0.q);
        const detail::RelativePose b_in_a(x1, xm);
        const bool says_apart = detail::kept_axis_separates(prepared, corners, normal, b_in_a, cache, speculative);
        FeatureCache after = cache;
        const bool touch = detail::collide_polyhedra(prepared, x1, triangle.view(), b_in_a, speculative, m, &after,
                                                     0.01);
        // The triangle's own faces are told by the plane cull before: never here.
        const bool told_here = cache.kind() == FeatureCache::Kind::FaceA ||
                               cache.kind() == FeatureCache::Kind::EdgePair;
        EXPECT_EQ(says_apart, told_here && !touch && after == cache) << "pose " << pose;
        told += says_apart;
        told_edges += says_apart && cache.kind() == FeatureCache::Kind::EdgePair;
        not_told += told_here && !says_apart;
    }
    // Both answers, and edge pairs among them, else the comparison says little.
    EXPECT_GT(told, 200);
    EXPECT_GT(told_edges, 15);
    EXPECT_GT(not_told, 50);
}

}  // namespace
}  // namespace spindle
