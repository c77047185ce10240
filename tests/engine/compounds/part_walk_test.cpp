// The compound walk's shortcuts (parts posed and bounded once per pair, a loose box before
// the exact one, a mesh searched once for all parts, the broadphase's part boxes taken as
// the exact ones) give, bit for bit, the manifolds of every part pair tested alone through
// collide() with the parts' exact bounds as the cull.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "collision/collide.hpp"
#include "collision/compound.hpp"

namespace spindle {
namespace {

// A hexagonal prism of radius r from y0 to y1 (a segment of Box3D's tree).
Shape prism(Real r, Real y0, Real y1) {
    std::vector<Vec3> points;
    for (int k = 0; k < 6; ++k) {
        const Real angle = kPi * k / 3;
        for (const Real y : {y0, y1}) points.emplace_back(r * std::cos(angle), y, r * std::sin(angle));
    }
    return Shape::convex_hull(points);
}

// Six prisms stacked into a trunk, a leaning box of a branch, and a capsule and a ball in
// the trunk's foot. Every part sits at the compound's origin, unturned, its place baked
// into its points: then a part's pose (the body's times the part's) is exact here and in
// the engine alike, whatever either compiler fuses into multiply-adds.
Shape tree() {
    std::vector<CompoundPart> parts;
    for (int i = 0; i < 6; ++i)
        parts.push_back({prism(0.4 * std::pow(0.9, i), i, i + 1), Vec3::Zero(), Quat::Identity()});
    std::vector<Vec3> branch;
    const Quat lean(Eigen::AngleAxis<Real>(0.3, Vec3::UnitZ()));
    for (int k = 0; k < 8; ++k) {
        const Vec3 corner(k & 1 ? 0.8 : -0.8, k & 2 ? 0.1 : -0.1, k & 4 ? 0.1 : -0.1);
        branch.push_back(Vec3(0.7, 3.5, 0) + lean * corner);
    }
    parts.push_back({Shape::convex_hull(branch), Vec3::Zero(), Quat::Identity()});
    parts.push_back({Shape::capsule(0.3, 0.35), Vec3::Zero(), Quat::Identity()});
    parts.push_back({Shape::sphere(0.45), Vec3::Zero(), Quat::Identity()});
    return Shape::compound(parts);
}

// Wavy ground of 2 x 2 m cells, 16 x 16 of them, about the origin.
Shape ground() {
    constexpr int kCells = 16;
    std::vector<Vec3> vertices;
    for (int i = 0; i <= kCells; ++i) {
        for (int j = 0; j <= kCells; ++j) {
            const Real x = 2.0 * (i - kCells / 2), z = 2.0 * (j - kCells / 2);
            vertices.emplace_back(x, 0.4 * std::sin(0.7 * x) * std::sin(0.45 * z), z);
        }
    }
    std::vector<std::uint32_t> indices;
    const auto at = [](int i, int j) { return static_cast<std::uint32_t>(i * (kCells + 1) + j); };
    for (int i = 0; i < kCells; ++i) {
        for (int j = 0; j < kCells; ++j) {
            indices.insert(indices.end(),
                           {at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
        }
    }
    return Shape::triangle_mesh(vertices, indices);
}

struct Part {
    const Shape* shape;
    Transform pose;
    std::uint32_t index;
};

std::vector<Part> parts_of(const Shape& s, const Transform& x) {
    if (s.type != ShapeType::Compound) return {{&s, x, 0}};
    std::vector<Part> out;
    for (std::uint32_t i = 0; i < s.parts->size(); ++i) out.push_back({&s.parts->shape(i), x * s.parts->pose(i), i});
    return out;
}

// What the walk must give: every part pair whose exact bounds (a's fattened) overlap,
// collided alone, in part-pair order.
std::vector<Manifold> part_by_part(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                                   Real speculative) {
    std::vector<Manifold> out;
    for (const Part& pa : parts_of(a, xa)) {
        const Aabb a_box = pa.shape->bounds(pa.pose).fattened(speculative);
        for (const Part& pb : parts_of(b, xb)) {
            if (!a_box.overlaps(pb.shape->bounds(pb.pose))) continue;
            Manifold found[4];
            const int n = collide(*pa.shape, pa.pose, *pb.shape, pb.pose, speculative, found, 4);
            for (int m = 0; m < n; ++m) {
                found[m].part_a = pa.index;
                found[m].part_b = pb.index;
                out.push_back(found[m]);
            }
        }
    }
    return out;
}

std::vector<Manifold> walked(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                             Real speculative) {
    std::vector<Manifold> out(64);
    out.resize(static_cast<std::size_t>(collide(a, xa, b, xb, speculative, out.data(), 64)));
    return out;
}

// The narrowphase's call: collide_cached with each compound's part boxes as the broadphase
// makes them (Compound::bounds), and fresh caches with no slop (the whole SAT).
std::vector<Manifold> boxed(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                            Real speculative) {
    const auto boxes_of = [](const Shape& s, const Transform& x) {
        std::vector<Aabb> boxes;
        if (s.type == ShapeType::Compound) {
            boxes.resize(s.parts->size());
            s.parts->bounds(x, boxes);
        }
        return boxes;
    };
    const std::vector<Aabb> boxes_a = boxes_of(a, xa), boxes_b = boxes_of(b, xb);
    FeatureCache cache;
    TriangleFeatures triangles;
    std::vector<Manifold> out(64);
    out.resize(static_cast<std::size_t>(
        collide_cached(a, xa, b, xb, speculative, out.data(), 64, cache, triangles, 0, PartBoxes{boxes_a, boxes_b})));
    return out;
}

// Equal to the bit: the same parts, normals, points, separations and ids in the same order.
void expect_same(const std::vector<Manifold>& expected, const std::vector<Manifold>& got, int sample) {
    ASSERT_EQ(got.size(), expected.size()) << "sample " << sample;
    for (std::size_t m = 0; m < got.size(); ++m) {
        const Manifold& e = expected[m];
        const Manifold& g = got[m];
        EXPECT_EQ(g.part_a, e.part_a) << "sample " << sample << " manifold " << m;
        EXPECT_EQ(g.part_b, e.part_b) << "sample " << sample << " manifold " << m;
        EXPECT_EQ(g.normal, e.normal) << "sample " << sample << " manifold " << m;
        ASSERT_EQ(g.point_count, e.point_count) << "sample " << sample << " manifold " << m;
        for (int k = 0; k < g.point_count; ++k) {
            EXPECT_EQ(g.points[k].point, e.points[k].point) << "sample " << sample << " manifold " << m;
            EXPECT_EQ(g.points[k].separation, e.points[k].separation) << "sample " << sample << " manifold " << m;
            EXPECT_EQ(g.points[k].id, e.points[k].id) << "sample " << sample << " manifold " << m;
        }
    }
}

Quat random_turn(std::mt19937& rng) {
    std::normal_distribution<Real> g;
    Quat q(g(rng), g(rng), g(rng), g(rng));
    q.normalize();
    return q;
}

TEST(CompoundPartWalk, TwoCompoundsGiveWhatEachPartPairGivesAlone) {
    const Shape a = tree(), b = tree();
    std::mt19937 rng(19);
    std::uniform_real_distribution<Real> offset(-1.2, 1.2);
    int touching = 0, total = 0;
    for (int sample = 0; sample < 400; ++sample) {
        const Transform xa{Vec3(offset(rng), offset(rng) + 3, offset(rng)), random_turn(rng)};
        const Transform xb{Vec3(offset(rng), offset(rng) + 3, offset(rng)), random_turn(rng)};
        const Real speculative = sample % 2 ? 0.04 : 0.2;
        const std::vector<Manifold> expected = part_by_part(a, xa, b, xb, speculative);
        expect_same(expected, walked(a, xa, b, xb, speculative), sample);
        expect_same(expected, boxed(a, xa, b, xb, speculative), sample);
        // One part alone against the other compound, either way round: as collide() gives it
        // (the compound's order turns a convex pair round, which is not the pair's own order).
        const Shape& alone = a.parts->shape(static_cast<std::uint32_t>(sample) % a.parts->size());
        expect_same(walked(alone, xa, b, xb, speculative), boxed(alone, xa, b, xb, speculative), sample);
        expect_same(walked(b, xb, alone, xa, speculative), boxed(b, xb, alone, xa, speculative), sample);
        touching += expected.empty() ? 0 : 1;
        total += static_cast<int>(expected.size());
    }
    // The samples reach both sides of the culls: part pairs that touch and ones that do not.
    EXPECT_GT(touching, 100);
    EXPECT_LT(touching, 400);
    EXPECT_GT(total, 3 * touching / 2);
}

TEST(CompoundPartWalk, ACompoundOnAMeshGivesWhatEachPartGivesAlone) {
    const Shape trunk = tree(), terrain = ground();
    // Moved and turned, and at the identity, where a part's mesh query takes its world box
    // as the box in the mesh's frame: half the samples each.
    const Transform moved_mesh{Vec3(0.3, -0.2, 0.1), Quat(Eigen::AngleAxis<Real>(0.05, Vec3(1, 0, 1).normalized()))};
    const Transform world_mesh;
    std::mt19937 rng(7);
    std::uniform_real_distribution<Real> spread(-10, 10), height(-0.5, 1.5);
    int touching = 0, total = 0;
    for (int sample = 0; sample < 300; ++sample) {
        // Lying, leaning or standing, its lowest parts near the ground.
        const Quat q = random_turn(rng);
        const Transform xt{Vec3(spread(rng), height(rng), spread(rng)), q};
        const Real speculative = sample % 2 ? 0.04 : 0.2;
        const Transform& mesh_pose = sample % 4 < 2 ? moved_mesh : world_mesh;
        const std::vector<Manifold> expected = part_by_part(terrain, mesh_pose, trunk, xt, speculative);
        expect_same(expected, walked(terrain, mesh_pose, trunk, xt, speculative), sample);
        expect_same(expected, boxed(terrain, mesh_pose, trunk, xt, speculative), sample);
        // The other order: the compound first, normals turned round.
        const std::vector<Manifold> turned_round = part_by_part(trunk, xt, terrain, mesh_pose, speculative);
        expect_same(turned_round, walked(trunk, xt, terrain, mesh_pose, speculative), sample);
        expect_same(turned_round, boxed(trunk, xt, terrain, mesh_pose, speculative), sample);
        touching += expected.empty() ? 0 : 1;
        total += static_cast<int>(expected.size());
    }
    EXPECT_GT(touching, 100);
    EXPECT_LT(touching, 300);
    EXPECT_GT(total, 3 * touching / 2);
}

}  // namespace
}  // namespace spindle
