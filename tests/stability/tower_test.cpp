// Towers of small or round pieces at the default settings (issue 16): a Jenga tower of
// real-size blocks and a log pile of crossing capsules. Issue 16 measured both (with a
// card house, an arch and a small 2D pyramid) collapsing or sagging by 10 cm or more at
// the defaults. Each must stand, come to rest and stay where it settled.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "scene_util.hpp"

namespace spindle::stability {
namespace {

struct TowerRun {
    double built_top = 0;  // m, the top piece's height as built
    double sag = 0;        // m, how far the top piece came down by the end
    double aside = 0;      // m, how far the top piece moved sideways by the end
    double creep = 0;      // m, the most any piece moved between 2 s and 10 s
    double speed = 0;      // m/s, the fastest piece at the end
    bool finite = true;
};

// Runs 10 s with sleep off; the top piece is the last.
TowerRun run_tower(Space& space, const std::vector<BodyHandle>& pieces) {
    TowerRun run;
    const Vec3 built = space.internal_position(pieces.back());
    run.built_top = built.y();
    for (int step = 0; step < 120; ++step) space.update();
    const std::vector<Vec3> settled = positions(space, pieces);
    for (int step = 120; step < 600; ++step) {
        space.update();
        run.creep = std::max(run.creep, max_displacement(space, pieces, settled));
    }
    const Vec3 top = space.internal_position(pieces.back());
    run.sag = built.y() - top.y();
    run.aside = std::hypot(top.x() - built.x(), top.z() - built.z());
    run.speed = max_speed(space, pieces);
    run.finite = all_finite(space, pieces);
    return run;
}

}  // namespace

// 18 levels of three 7.5 x 2.5 x 1.5 cm wooden blocks (17 g), each level crossing the
// one below, on a static floor, friction 0.5. The issue found it collapsing or sagging
// 10 cm or more at the defaults. The soft contacts compress under the load of the levels
// above (30 Hz springs: about 1.5 mm per level near the bottom), so the tower stands
// shorter than built; it must not lean, slide or keep moving. On main when the issue was
// filed (2321258, this test built there): the top fell 255 mm and 486 mm aside.
TEST(Tower, JengaOfEighteenLevelsStands) {
    auto space = make_space();
    add_static_box(*space, Vec3(1, 0.5, 1), Vec3(0, -0.5, 0), Quat::Identity(), 0.5);
    constexpr int kLevels = 18;
    constexpr double kLong = 0.0375, kTall = 0.0075, kWide = 0.0125;  // half extents
    std::vector<BodyHandle> blocks;
    for (int level = 0; level < kLevels; ++level) {
        const double y = kTall + 2 * kTall * level;
        for (int i = -1; i <= 1; ++i) {
            const bool along_x = level % 2 == 0;
            const Vec3 half = along_x ? Vec3(kLong, kTall, kWide) : Vec3(kWide, kTall, kLong);
            const Vec3 at = along_x ? Vec3(0, y, 2 * kWide * i) : Vec3(2 * kWide * i, y, 0);
            blocks.push_back(add_box(*space, half, at, 600 * 8 * kLong * kTall * kWide, 0.5));
        }
    }
    const TowerRun run = run_tower(*space, blocks);
    std::printf(
        "[ measure  ] Jenga %d levels: top built at %.4f m sagged %.1f mm and moved %.1f mm aside; most any block "
        "moved from 2 s to 10 s %.3f mm; fastest at the end %.2g m/s\n",
        kLevels, run.built_top, 1000 * run.sag, 1000 * run.aside, 1000 * run.creep, run.speed);
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.sag, 0.05);      // a sixth of the tower's 27 cm: soft contacts, not a fall
    EXPECT_LT(run.aside, 0.0125);  // less than half a block's width
    EXPECT_LT(run.creep, 0.002);
    EXPECT_LT(run.speed, 0.001);
}

namespace {

// A horizontal log along x or z: a capsule of radius 10 cm, 1.2 m long, 40 kg.
BodyHandle add_log(Space& space, const Vec3& at, bool along_x) {
    // A capsule's segment is along its y axis: turn it to x or z.
    BodyDesc d;
    d.shape = Shape::capsule(0.5, 0.1);
    d.position = at;
    d.orientation = along_x ? Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()))
                            : Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()));
    d.mass = 40;
    return space.create_body(d);
}

}  // namespace

// Logs (capsules of radius 10 cm, 1.2 m long, 40 kg) on a static floor, friction 0.6, in
// two piles: six crossing layers of four, each layer across the one below (each log on
// round contacts only), and a triangle of parallel logs, 3, 2, 1, each resting in the
// groove of two below, which only friction keeps from rolling apart (it needs 2 - sqrt(3)
// = 0.27; a 4, 3, 2, 1 triangle needs more than 0.6 at the bottom, where the wedged logs
// push each other out: it falls at 0.6 in Box3D as here). The issue found crossing layers
// of horizontal capsules collapsing or sagging 10 cm or more at the defaults; on main then
// (2321258, this test built there) the crossing pile fell 1 m, a log still at 10 m/s after
// 10 s. Without friction the triangle spreads flat (shown: the crossing pile alone stood
// even then).
TEST(Tower, LogPilesStand) {
    auto space = make_space();
    add_static_box(*space, Vec3(5, 0.5, 5), Vec3(0, -0.5, 0));
    constexpr double kRadius = 0.1;
    std::vector<BodyHandle> logs;
    for (int layer = 0; layer < 6; ++layer) {
        for (int i = 0; i < 4; ++i) {
            const double across = -0.45 + 0.3 * i, y = kRadius + 2 * kRadius * layer;
            logs.push_back(add_log(*space, layer % 2 == 0 ? Vec3(0, y, across) : Vec3(across, y, 0), layer % 2 == 0));
        }
    }
    // The triangle, along z, beside the crossing pile; its top log last.
    std::vector<BodyHandle> triangle;
    for (int row = 0; row < 3; ++row) {
        for (int i = 0; i < 3 - row; ++i) {
            const double x = 2 + 2 * kRadius * (i - 0.5 * (2 - row));
            triangle.push_back(add_log(*space, Vec3(x, kRadius + row * std::sqrt(3.0) * kRadius, 0), false));
        }
    }
    logs.insert(logs.end(), triangle.begin(), triangle.end() - 1);
    logs.push_back(triangle.back());  // the top of the triangle is the piece run_tower follows
    const BodyHandle crossing_top = logs[23];
    const double crossing_built = space->internal_position(crossing_top).y();
    const TowerRun run = run_tower(*space, logs);
    const double crossing_sag = crossing_built - space->internal_position(crossing_top).y();
    std::printf(
        "[ measure  ] log piles: crossing pile's top sagged %.1f mm; triangle's top built at %.3f m sagged %.1f mm "
        "and moved %.1f mm aside; most any log moved from 2 s to 10 s %.3f mm; fastest at the end %.2g m/s\n",
        1000 * crossing_sag, run.built_top, 1000 * run.sag, 1000 * run.aside, 1000 * run.creep, run.speed);
    EXPECT_TRUE(run.finite);
    EXPECT_LT(crossing_sag, 0.02);
    EXPECT_LT(run.sag, 0.02);
    EXPECT_LT(run.aside, 0.02);
    EXPECT_LT(run.creep, 0.002);
    EXPECT_LT(run.speed, 0.001);
}

namespace {

// splitmix64: the same numbers on every standard library (std's distributions differ).
std::uint64_t splitmix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

}  // namespace

// The triangle of LogPilesStand alone (3, 2, 1 parallel logs, friction 0.6), made in 40
// creation orders: the first bottom row first, the others shuffled (Fisher-Yates, seeded).
// The creation order sets the order the solver meets the contacts in. The middle bottom
// log's two contacts above it sit at the friction cone from the first step: the pile is
// statically indeterminate there, and with friction solved only after the biased pass had
// moved the logs without it, whether it stood was set by that order (12 of 40 stood).
// Each order runs until its top log has come down 2 cm (a fall) or for 2 s; it stands if
// the top sagged less than 2 cm and no log moves faster than 1 mm/s.
TEST(Tower, LogTriangleStandsInEveryCreationOrder) {
    constexpr double kRadius = 0.1;
    constexpr int kOrders = 40;
    std::vector<Vec3> at;  // bottom row first, the top log last
    for (int row = 0; row < 3; ++row) {
        for (int i = 0; i < 3 - row; ++i) {
            at.emplace_back(2 * kRadius * (i - 0.5 * (2 - row)), kRadius + row * std::sqrt(3.0) * kRadius, 0);
        }
    }
    std::vector<int> order(at.size());
    std::uint64_t seed = 19;
    std::vector<int> fallen;
    double worst_sag = 0;
    for (int k = 0; k < kOrders; ++k) {
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
        for (std::size_t i = order.size() - 1; k > 0 && i > 0; --i) {
            std::swap(order[i], order[splitmix64(seed) % (i + 1)]);
        }
        auto space = make_space();
        add_static_box(*space, Vec3(5, 0.5, 5), Vec3(0, -0.5, 0));
        std::vector<BodyHandle> logs(at.size());
        for (int i : order) logs[i] = add_log(*space, at[i], false);
        const double built = at.back().y();
        double sag = 0;
        for (int step = 0; step < 120 && sag < 0.02; ++step) {
            space->update();
            sag = built - space->internal_position(logs.back()).y();
        }
        if (sag >= 0.02 || max_speed(*space, logs) >= 0.001) {
            fallen.push_back(k);
        } else {
            worst_sag = std::max(worst_sag, sag);
        }
    }
    std::printf(
        "[ measure  ] log triangle: stood in %d of %d creation orders; the most a standing top sagged %.1f mm\n",
        kOrders - static_cast<int>(fallen.size()), kOrders, 1000 * worst_sag);
    for (int k : fallen) ADD_FAILURE() << "creation order " << k << ": the triangle fell or still moves";
}

// A 2D pyramid of small cubes built with motion locks (issue 16: "a 2D pyramid of 30 small
// cubes" collapsed or sagged 10 cm or more at the defaults): 8 rows, 36 wooden cubes of
// 5 cm (600 kg/m^3, friction 0.6), each locked to the plane z = 0 (no z motion, turning
// about z only), built exactly touching on a static floor. Small cubes are light, so
// their soft contacts are soft for the load of the rows above; the pyramid must still
// stand: its top less than a fifth of a cube down (a cube knocked out drops it a whole
// one), nothing sliding or moving after the first 2 s, and at rest.
TEST(Tower, SmallCubePyramidLockedToAPlaneStands) {
    auto space = make_space();
    add_static_box(*space, Vec3(1, 0.5, 1), Vec3(0, -0.5, 0));
    constexpr int kRows = 8;
    constexpr double kHalf = 0.025;
    std::vector<BodyHandle> cubes;
    for (int row = 0; row < kRows; ++row) {
        for (int i = 0; i < kRows - row; ++i) {
            BodyDesc d;
            d.shape = Shape::box(Vec3::Constant(kHalf));
            d.position = Vec3(2 * kHalf * (i - 0.5 * (kRows - row - 1)), kHalf + 2 * kHalf * row, 0);
            d.density = 600;
            d.friction = 0.6;
            d.locks = MotionLocks::plane_xy();
            cubes.push_back(space->create_body(d));
        }
    }
    ASSERT_EQ(cubes.size(), 36u);
    const TowerRun run = run_tower(*space, cubes);
    double out_of_plane = 0;
    for (BodyHandle cube : cubes) out_of_plane = std::max(out_of_plane, std::abs(space->internal_position(cube).z()));
    std::printf(
        "[ measure  ] 2D pyramid of %zu cubes of 5 cm: top built at %.4f m sagged %.2f mm and moved %.2f mm aside; "
        "most any cube moved from 2 s to 10 s %.3f mm; fastest at the end %.2g m/s; furthest out of plane %.2g m\n",
        cubes.size(), run.built_top, 1000 * run.sag, 1000 * run.aside, 1000 * run.creep, run.speed, out_of_plane);
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.sag, 0.01);
    EXPECT_LT(run.aside, 0.01);
    EXPECT_LT(run.creep, 0.001);
    EXPECT_LT(run.speed, 0.001);
    EXPECT_LT(out_of_plane, 1e-9);
}

}  // namespace spindle::stability
