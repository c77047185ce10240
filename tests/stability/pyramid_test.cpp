// Pyramids: Jolt's 1240-box "Pyramid" standing for 1000 steps, and piles started with
// 25% overlap pushing apart no faster than the push-out speed allows.
#include "scene_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

using namespace spindle;
using namespace spindle::stability;

namespace {

// Jolt's PyramidTest: 15 layers of boxes (half extent 1) with gaps of 0.5 between the
// layers, each layer offset by half a box on odd layers, friction 0.2.
std::vector<BodyHandle> add_jolt_pyramid(Space& space) {
    add_static_box(space, Vec3(50, 1, 50), Vec3(0, -1, 0), Quat::Identity(), 0.2);
    std::vector<BodyHandle> boxes;
    constexpr int kLayers = 15;
    for (int i = 0; i < kLayers; ++i) {
        const double h = (i % 2 == 1) ? 1.0 : 0.0;
        for (int j = i / 2; j < kLayers - (i + 1) / 2; ++j) {
            for (int k = i / 2; k < kLayers - (i + 1) / 2; ++k) {
                const Vec3 p(-kLayers + 2 * j + h, 1 + 2.5 * i, -kLayers + 2 * k + h);
                boxes.push_back(add_box(space, Vec3::Constant(1), p, 0, 0.2));
            }
        }
    }
    return boxes;
}

}  // namespace

// The top layer falls 7 m onto the layer below and lands near step 72, so the settled
// pose is taken at step 120; then 1000 more steps.
TEST(Pyramid, StandsFor1000Steps) {
    auto jobs = two_workers();
    auto space = make_space(SpaceSettings{}, jobs.get());
    const std::vector<BodyHandle> boxes = add_jolt_pyramid(*space);
    ASSERT_EQ(boxes.size(), 1240u);
    constexpr int kSettle = 120;
    for (int step = 0; step < kSettle; ++step) space->update();
    const std::vector<Vec3> settled = positions(*space, boxes);
    double worst = 0, worst_top_error = 0;
    for (int step = 0; step < 1000; ++step) {
        space->update();
        worst = std::max(worst, max_displacement(*space, boxes, settled));
        worst_top_error = std::max(worst_top_error, std::abs(space->internal_position(boxes.back()).y() - 29.0));
    }
    const double top = space->internal_position(boxes.back()).y();
    std::printf("[ measure  ] pyramid: settled top y %.4f, final top y %.4f, worst top |y - 29| %.4f m, worst box "
                "displacement from settled %.4f m\n",
                settled.back().y(), top, worst_top_error, worst);
    EXPECT_TRUE(all_finite(*space, boxes));
    EXPECT_LT(worst, 0.1);
    EXPECT_LT(worst_top_error, 0.02);
}

// A 10-layer pyramid of unit cubes (385 boxes, each on four below) whose layers
// overlap by a quarter of a box: each layer 0.75 above the one below.
TEST(OverlapRecovery, PyramidWithQuarterOverlapSeparatesAtThePushOutSpeed) {
    auto space = make_space();
    const BodyHandle floor = add_static_box(*space, Vec3(20, 1, 20), Vec3(0, -1, 0));
    std::vector<BodyHandle> boxes;
    constexpr int kBase = 10;
    for (int layer = 0; layer < kBase; ++layer) {
        const int n = kBase - layer;
        for (int j = 0; j < n; ++j) {
            for (int k = 0; k < n; ++k) {
                const Vec3 p(-0.5 * n + 0.5 + j, 0.5 + 0.75 * layer, -0.5 * n + 0.5 + k);
                boxes.push_back(add_box(*space, Vec3::Constant(0.5), p));
            }
        }
    }
    const OverlapRun run = run_overlap_recovery("overlapping pyramid", *space, boxes, floor, 240);
    EXPECT_LE(run.worst_speed_excess, 0.0);
    EXPECT_LT(run.final_overlap, 0.01);
}

// A column of 20 cubes, each 0.75 above the one below.
TEST(OverlapRecovery, StackWithQuarterOverlapSeparatesAtThePushOutSpeed) {
    auto space = make_space();
    const BodyHandle floor = add_static_box(*space, Vec3(20, 1, 20), Vec3(0, -1, 0));
    const std::vector<BodyHandle> boxes = add_cube_stack(*space, 20, Vec3::Zero(), 0.75);
    const OverlapRun run = run_overlap_recovery("overlapping stack", *space, boxes, floor, 240);
    EXPECT_LE(run.worst_speed_excess, 0.0);
    EXPECT_LT(run.final_overlap, 0.01);
    // Standing: no cube ends more than half its width from where it started (the
    // column toppled, several metres, before overlap was pushed out by split impulse).
    EXPECT_LT(run.final_sideways, 0.5) << "the column should end standing, not toppled";
}
