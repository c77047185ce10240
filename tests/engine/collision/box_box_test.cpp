// Box-box: face contacts clipped to four points, edge-edge single points, speculative
// contacts, and feature ids that hold while one box slides on another.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <set>
#include <string>

#include "collision/pair_functions.hpp"
#include "collision_test_util.hpp"

namespace spindle {
namespace {

using test::about;
using test::at;
using test::run;

const Shape kFloor = Shape::box(Vec3(2, 0.5, 2));
const Shape kCube = Shape::box(Vec3(0.5, 0.5, 0.5));

std::set<std::uint32_t> ids(const Manifold& m) {
    std::set<std::uint32_t> s;
    for (int i = 0; i < m.point_count; ++i) s.insert(m.points[i].id);
    return s;
}

TEST(BoxBox, RestingCubeHasFourCornerPoints) { test::expect_resting_cube_contact(kFloor, kCube); }

TEST(BoxBox, SeparatedGivesNothingOrSpeculativePoints) {
    EXPECT_TRUE(run(kFloor, at(Vec3::Zero()), kCube, at(Vec3(0, 1.1, 0))).empty());
    const auto m = run(kFloor, at(Vec3::Zero()), kCube, at(Vec3(0, 1.1, 0)), 0.2);
    ASSERT_EQ(m.size(), 1u);
    ASSERT_EQ(m[0].point_count, 4);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(m[0].points[i].separation, 0.1, 1e-12);
}

TEST(BoxBox, TouchingHasZeroSeparation) {
    const auto m = run(kFloor, at(Vec3::Zero()), kCube, at(Vec3(0, 1.0, 0)));
    ASSERT_EQ(m.size(), 1u);
    EXPECT_NEAR(deepest(m[0]), 0, 1e-12);
}

TEST(BoxBox, RotatedCubeKeepsItsRotatedCorners) {
    const auto m = run(kFloor, at(Vec3::Zero()), kCube, at(Vec3(0, 0.98, 0), about(Vec3::UnitY(), kPi / 4)));
    ASSERT_EQ(m.size(), 1u);
    ASSERT_EQ(m[0].point_count, 4);
    const Real r = std::sqrt(0.5);
    EXPECT_TRUE(test::has_point(m[0], Vec3(r, 0.49, 0), 1e-12));
    EXPECT_TRUE(test::has_point(m[0], Vec3(0, 0.49, -r), 1e-12));
    EXPECT_NEAR(deepest(m[0]), -0.02, 1e-12);
}

TEST(BoxBox, TiltedCubeRestsOnOneEdgeWithTwoPoints) {
    // Cube turned 30 degrees about z, its lowest edge 0.01 into the floor.
    const Quat q = about(Vec3::UnitZ(), kPi / 6);
    const Real low = 0.5 * (std::cos(kPi / 6) + std::sin(kPi / 6));
    const auto m = run(kFloor, at(Vec3::Zero()), kCube, at(Vec3(0, 0.5 + low - 0.01, 0), q));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-12);
    ASSERT_EQ(m[0].point_count, 2);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(m[0].points[i].separation, -0.01, 1e-12);
}

TEST(BoxBox, CrossedEdgesGiveOneEdgePoint) { test::expect_crossed_edges_contact(Shape::box(Vec3(1, 1, 1))); }

TEST(BoxBox, DeepOverlapPushesOutAlongShallowestFace) {
    const Shape cube = Shape::box(Vec3(1, 1, 1));
    const auto m = run(cube, at(Vec3::Zero()), cube, at(Vec3(0.2, 1.5, 0.1)));
    ASSERT_EQ(m.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(m[0].normal, Vec3(0, 1, 0), 1e-12);
    EXPECT_NEAR(deepest(m[0]), -0.5, 1e-12);
    EXPECT_EQ(m[0].point_count, 4);
}

TEST(BoxBox, OverhangingCubeIsClippedAtTheEdge) {
    const Shape floor = Shape::box(Vec3(1, 0.5, 1));
    const auto m = run(floor, at(Vec3::Zero()), kCube, at(Vec3(1.2, 0.99, 0)));
    ASSERT_EQ(m.size(), 1u);
    ASSERT_EQ(m[0].point_count, 4);
    for (const Real x : {0.7, 1.0}) {
        for (const Real z : {-0.5, 0.5}) EXPECT_TRUE(test::has_point(m[0], Vec3(x, 0.495, z), 1e-12));
    }
}

TEST(BoxBox, FeatureIdsHoldWhileSlidingAcrossTheFloor) {
    std::set<std::uint32_t> first;
    for (int step = 0; step < 100; ++step) {
        const auto m = run(kFloor, at(Vec3::Zero()), kCube, at(Vec3(-0.5 + 0.01 * step, 0.99, 0.1)));
        ASSERT_EQ(m.size(), 1u);
        ASSERT_EQ(m[0].point_count, 4);
        if (step == 0) first = ids(m[0]);
        EXPECT_EQ(ids(m[0]), first) << "step " << step;
    }
}

TEST(BoxBox, FeatureIdsHoldWhileSlidingOverAnEdge) {
    // The clipped points are named by (incident edge, side plane) and keep their names.
    const Shape floor = Shape::box(Vec3(1, 0.5, 1));
    std::set<std::uint32_t> first;
    for (int step = 0; step < 30; ++step) {
        const auto m = run(floor, at(Vec3::Zero()), kCube, at(Vec3(0.7 + 0.01 * step, 0.99, 0)));
        ASSERT_EQ(m.size(), 1u);
        ASSERT_EQ(m[0].point_count, 4);
        if (step == 0) first = ids(m[0]);
        EXPECT_EQ(ids(m[0]), first) << "step " << step;
    }
}

TEST(BoxBox, SwappedOrderFlipsTheNormal) {
    const Transform xa = at(Vec3::Zero(), about(Vec3(1, 1, 0), 0.2));
    const Transform xb = at(Vec3(0.1, 0.95, 0.2), about(Vec3(0, 1, 1), 0.3));
    test::expect_swapped_order_flips(kFloor, xa, kCube, xb);
}

TEST(BoxBox, MatchesHullHullOnRandomPoses) {
    // The dedicated 15-axis SAT and the general polyhedron SAT agree on depth and normal.
    // (No speculative margin: when apart, the 15 axes include non-Minkowski ones that
    // can separate a little more than the pruned set, which is fine but not comparable.)
    const Vec3 ha(1, 0.5, 0.8), hb(0.4, 0.6, 0.3);
    const Shape box_a = Shape::box(ha), box_b = Shape::box(hb);
    const Shape hull_a = test::hull_box(ha), hull_b = test::hull_box(hb);
    unsigned seed = 1;
    const auto rnd = [&seed] {
        seed = seed * 1664525u + 1013904223u;
        return Real(seed >> 8) / Real(1 << 24) * 2 - 1;
    };
    int compared = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const Transform xa = at(Vec3(rnd(), rnd(), rnd()) * 0.2, about(Vec3(rnd(), rnd(), rnd()), 3 * rnd()));
        const Transform xb = at(Vec3(rnd(), rnd(), rnd()) * 1.4, about(Vec3(rnd(), rnd(), rnd()), 3 * rnd()));
        const auto boxes = run(box_a, xa, box_b, xb);
        const auto hulls = run(hull_a, xa, hull_b, xb);
        ASSERT_EQ(boxes.size(), hulls.size()) << "trial " << trial;
        if (boxes.empty()) continue;
        ++compared;
        EXPECT_NEAR(deepest(boxes[0]), deepest(hulls[0]), 1e-6) << "trial " << trial;
        EXPECT_GT(boxes[0].normal.dot(hulls[0].normal), 0.999) << "trial " << trial;
    }
    EXPECT_GT(compared, 30);
}

// Two cards leaning at 68 degrees, their inner top edges meeting as at a card house's
// apex: a sharp edge has no one normal, and either card's face normal would tilt the push
// 22 degrees off the symmetric one. Meeting exactly, the normal is the faces' bisector
// (horizontal); with one edge 1 mm down the other card's face, well past the edges'
// rounding, that face carries the edge and its normal is kept.
TEST(BoxBox, CardsMeetingAtAnApexPushAlongTheBisector) {
    const Vec3 half(0.044, 0.001, 0.0315);
    const Shape card = Shape::box(half);
    const Real lean = 68 * kPi / 180, c = std::cos(lean), s = std::sin(lean);
    const Real x = half.x() * c + half.y() * s;  // apex to a card's centre
    const Transform left = at(Vec3(-x, 0, 0), about(Vec3::UnitZ(), lean));
    const Transform right = at(Vec3(x, 0, 0), about(Vec3::UnitZ(), -lean));
    const auto apex = run(card, left, card, right, 0.01);
    ASSERT_EQ(apex.size(), 1u);
    EXPECT_NEAR(apex[0].normal.x(), 1, 1e-9);
    EXPECT_NEAR(deepest(apex[0]), 0, 1e-9);

    const Vec3 down_the_face = -Vec3(c, s, 0) * 0.001;
    const auto lower = run(card, left, card, at(right.p + down_the_face, right.q), 0.01);
    ASSERT_EQ(lower.size(), 1u);
    SPINDLE_EXPECT_VEC_NEAR(lower[0].normal, Vec3(s, -c, 0), 1e-9);  // the left card's inner face
}

// FNV-1a over every bit of box-box collides: what the stored-bits tests below compare.
struct CollideBits {
    std::uint64_t hash = 0xcbf29ce484222325ull;
    int touching = 0, points = 0;

    void mix(std::uint64_t word) { hash = (hash ^ word) * 0x100000001b3ull; }
    void mix(const Vec3& v) {
        for (int i = 0; i < 3; ++i) mix(std::bit_cast<std::uint64_t>(v[i]));
    }
    void collide(const Vec3& ha, const Transform& xa, const Vec3& hb, const Transform& xb) {
        Manifold found[2];
        const int n = detail::collide_box_box(Shape::box(ha), xa, Shape::box(hb), xb, 0.05, found, 2);
        mix(static_cast<std::uint64_t>(n));
        for (int m = 0; m < n; ++m) {
            mix(found[m].normal);
            mix(static_cast<std::uint64_t>(found[m].point_count));
            for (int i = 0; i < found[m].point_count; ++i) {
                mix(found[m].points[i].point);
                mix(std::bit_cast<std::uint64_t>(found[m].points[i].separation));
                mix(found[m].points[i].id);
            }
            points += found[m].point_count;
        }
        touching += n > 0 ? 1 : 0;
    }
    std::string hex() const {
        char text[19];
        std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(hash));
        return text;
    }
};

// splitmix64: the same numbers on every standard library.
struct Numbers {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    Real uniform(Real lo, Real hi) { return lo + (hi - lo) * static_cast<Real>(next() >> 11) * 0x1p-53; }
    Quat turn() { return Quat(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)).normalized(); }
};

// Every bit of many box-box collides, against a stored hash. The SAT's axes and the points'
// turn run in lanes that keep the scalar sums' order (exact, by the scenes' hashes); a sum
// reordered moves a last bit in a few poses out of thousands, which no scene test sees. A
// change meant to move these bits updates the hash on purpose and says why.
TEST(BoxBox, ManyPosesGiveTheStoredBits) {
    Numbers numbers{0x5eed};
    CollideBits bits;
    for (int pose = 0; pose < 20000; ++pose) {
        const Vec3 ha(numbers.uniform(0.05, 2), numbers.uniform(0.05, 2), numbers.uniform(0.05, 2));
        const Vec3 hb(numbers.uniform(0.05, 2), numbers.uniform(0.05, 2), numbers.uniform(0.05, 2));
        const Real reach = 0.9 * (ha.norm() + hb.norm());
        const Transform xa = at(Vec3(numbers.uniform(-1, 1), numbers.uniform(-1, 1), numbers.uniform(-1, 1)),
                                numbers.turn());
        const Vec3 offset = Vec3(numbers.uniform(-1, 1), numbers.uniform(-1, 1), numbers.uniform(-1, 1)).normalized() *
                            numbers.uniform(0, reach);
        bits.collide(ha, xa, hb, at(xa.p + offset, numbers.turn()));
    }
    // The poses reach the SAT's face and edge cases alike, not only the separated ones.
    EXPECT_GT(bits.touching, 10000);
    EXPECT_GT(bits.points, 30000);
    EXPECT_EQ(bits.hex(), "0xec2b6388fdbc607e");
}

// The same for boxes lying square on and beside each other, as a pyramid's do: a box on two
// (the incident face cut by one side of the reference face), on a larger one or beside one of
// its size (nothing cut), at a corner (cut by two sides), a little turned about the normal or
// not at all, the pair anywhere and sometimes turned as a whole. Random turns almost never
// give faces square to each other, and these take their own ways through the face clip.
TEST(BoxBox, SquarePosesGiveTheStoredBits) {
    Numbers numbers{0xa11};
    CollideBits bits;
    const Real halves[] = {0.5, 0.5, 0.25, 1, 0.3};
    for (int pose = 0; pose < 20000; ++pose) {
        const auto half = [&] { return halves[numbers.next() % 5]; };
        const Vec3 ha(half(), half(), half());
        const Vec3 hb = numbers.next() % 2 ? ha : Vec3(half(), half(), half());
        const int up = static_cast<int>(numbers.next() % 3);  // the axis B lies along from A
        Vec3 offset;
        for (int k = 0; k < 3; ++k) {
            const Real span = ha[k] + hb[k];
            // On the face: in line, half off (a box on two), or anywhere over it.
            const std::uint64_t how = numbers.next() % 4;
            offset[k] = how == 0 ? 0 : how == 1 ? ha[k] : how == 2 ? -ha[k] : numbers.uniform(-span, span);
        }
        offset[up] = (numbers.next() % 2 ? 1 : -1) * (ha[up] + hb[up] + numbers.uniform(-0.02, 0.04));
        const std::uint64_t how = numbers.next() % 4;
        const Quat whole = how == 0 ? numbers.turn() : Quat::Identity();
        const Quat own = how == 1 ? Quat(Eigen::AngleAxis<Real>(numbers.uniform(-0.2, 0.2), Vec3::Unit(up)))
                                  : Quat::Identity();
        const Vec3 where(numbers.uniform(-50, 50), numbers.uniform(0, 20), numbers.uniform(-50, 50));
        bits.collide(ha, at(where, whole), hb, at(where + whole * offset, whole * own));
    }
    EXPECT_GT(bits.touching, 10000);
    EXPECT_GT(bits.points, 30000);
    EXPECT_EQ(bits.hex(), "0x5f05686cd1762374");
}

}  // namespace
}  // namespace spindle
