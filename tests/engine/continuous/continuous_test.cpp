// Continuous collision: a fast-spinning bar flagged `fast` does not sweep through a
// thin static wall (speculative contacts see only the linear closing speed, so
// without the swept test it does), and bodies not flagged pay nothing for it.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>

using namespace spindle;

namespace {

struct BarRun {
    double max_tip_x = -1e9;
    std::uint64_t swept_tests = 0;
};

// A 4 m bar spinning at 60 rad/s about its centre 1 m from a 4 cm wall: within one
// step its tip turns from x = 0.07 to x = 1.0, through the wall at x = 0.48..0.52.
BarRun spin_bar_at_wall(bool fast) {
    Space space;
    space.set_gravity(Vec3::Zero());
    BodyDesc wall;
    wall.type = MotionType::Static;
    wall.shape = Shape::box(Vec3(0.02, 5, 5));
    wall.position = Vec3(0.5, 0, 0);
    space.create_body(wall);
    BodyDesc bar;
    bar.shape = Shape::box(Vec3(2, 0.05, 0.05));
    bar.position = Vec3(-1, 0, 0);
    bar.orientation = Quat(Eigen::AngleAxisd(2.0, Vec3::UnitZ()));
    bar.angular_velocity = Vec3(0, 0, -60);
    bar.fast = fast;
    const BodyHandle h = space.create_body(bar);
    BarRun run;
    for (int i = 0; i < 30; ++i) {
        space.update();
        const MotionState s = space.internal_motion_state(h);
        for (double end : {2.0, -2.0})
            run.max_tip_x = std::max(run.max_tip_x, (s.position + s.orientation * Vec3(end, 0, 0)).x());
    }
    run.swept_tests = space.counters().swept_tests;
    return run;
}

}  // namespace

TEST(Continuous, FastSpinningBarStopsAtAThinWall) {
    const BarRun run = spin_bar_at_wall(true);
    EXPECT_LT(run.max_tip_x, 0.48 + 0.01);  // the wall's near face, plus a little soft penetration
    EXPECT_GT(run.swept_tests, 0u);
}

TEST(Continuous, WithoutTheFlagTheBarSweepsThroughAndNoSweepIsPaidFor) {
    const BarRun run = spin_bar_at_wall(false);
    EXPECT_GT(run.max_tip_x, 0.52);  // the case the swept test exists for
    EXPECT_EQ(run.swept_tests, 0u);
}
