// Static friction at the default settings (issue 16): what sticks stays where it stuck.
// Each test names what main measured before.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "scene_util.hpp"

namespace spindle::stability {

namespace {

int awake_count(const Space& space, const std::vector<BodyHandle>& bodies) {
    int n = 0;
    for (BodyHandle b : bodies) n += space.internal_is_awake(b) ? 1 : 0;
    return n;
}

}  // namespace

// A wall one cube deep, cubes on cubes in columns, on a static floor, sleeping off so any
// creep shows. Issue 16 measured 20 wide creeping sideways 15 cm in 10 s (still moving)
// and 30 wide collapsing. Creep is motion that goes on: the wall may settle while its
// soft contacts take the load, then must stand still. Friction solved in every pass
// settled 3.5 mm; in the relax passes only (Box3D's, kept for heavy bodies on light
// ones: below) it settles 26 mm in 5 s, then 0.7 mm more in the next 10 s as it comes
// to rest (4e-6 m/s at the end).
TEST(StaticFriction, AOneCubeDeepWallStands) {
    for (int wide : {20, 30}) {
        constexpr int kHigh = 10;
        auto space = make_space();  // sleep off: any creep shows
        add_static_box(*space, Vec3(40, 0.5, 10), Vec3(0, -0.5, 0));
        std::vector<BodyHandle> bricks;
        for (int row = 0; row < kHigh; ++row) {
            for (int col = 0; col < wide; ++col) {
                bricks.push_back(add_box(*space, Vec3::Constant(0.5), Vec3(col - 0.5 * (wide - 1), 0.5 + row, 0)));
            }
        }
        const std::vector<Vec3> built = positions(*space, bricks);
        for (int step = 0; step < 300; ++step) space->update();  // 5 s to settle
        const std::vector<Vec3> settled = positions(*space, bricks);
        const double settling = max_displacement(*space, bricks, built);
        double creep = 0;
        for (int step = 0; step < 600; ++step) {
            space->update();
            creep = std::max(creep, max_displacement(*space, bricks, settled));
        }
        const double speed = max_speed(*space, bricks);
        std::printf(
            "[ measure  ] wall %d x %d: worst brick settled %.1f mm in 5 s, then moved %.4f mm in 10 s; fastest at "
            "the end %.2g m/s\n",
            wide, kHigh, 1000 * settling, 1000 * creep, speed);
        EXPECT_LT(settling, 0.05) << wide << " wide";
        EXPECT_LT(creep, 0.002) << wide << " wide";
        EXPECT_LT(speed, 0.001) << wide << " wide";
    }
}

// The built-in mass_ratio scene: a 1000 kg slab on four 1 kg cubes, and a 100 kg cube on
// a 1 kg one, on a plane, sleeping on as in a game. Issue 16 measured the light cubes
// wandering 11 cm in 1.7 s and 47 cm in 10 s, never asleep. Main at c096e0f: 28 mm in
// 10 s, and the 100 kg cube rocking on its 1 kg one at 0.15 m/s for ever (friction in
// the biased pass, and the slab's 7 cm of soft compression pushed out as overlap past
// the recovery depth); 2 of 7 bodies never slept.
TEST(StaticFriction, LightCubesUnderHeavyBodiesRestAndSleep) {
    Space space{SpaceSettings{}};
    add_ground_plane(space);
    std::vector<BodyHandle> bodies;
    for (int i = 0; i < 4; ++i) {
        bodies.push_back(add_box(space, Vec3::Constant(0.5), Vec3(i % 2 ? 2 : -2, 0.5, i / 2 ? 2 : -2), 1));
    }
    bodies.push_back(add_box(space, Vec3(3, 0.5, 3), Vec3(0, 1.5, 0), 1000));
    bodies.push_back(add_box(space, Vec3::Constant(0.5), Vec3(8, 0.5, 0), 1));
    bodies.push_back(add_box(space, Vec3::Constant(0.5), Vec3(8, 1.5, 0), 100));
    for (int step = 0; step < 90; ++step) space.update();  // 1.5 s to settle
    const std::vector<Vec3> settled = positions(space, bodies);
    double worst = 0;
    for (int step = 0; step < 540; ++step) {
        space.update();
        worst = std::max(worst, max_displacement(space, bodies, settled));
    }
    const int awake = awake_count(space, bodies);
    std::printf(
        "[ measure  ] heavy on light cubes: most moved after settling %.4f mm in 9 s; %d of %zu awake at the end\n",
        1000 * worst, awake, bodies.size());
    EXPECT_LT(worst, 0.001);
    EXPECT_EQ(awake, 0);
}

}  // namespace spindle::stability
