// Analytic contact cases: Coulomb friction on flat ground and on a ramp, a small
// pyramid started overlapping, and a fast sphere against a thin wall.
#include "scene_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace spindle;
using namespace spindle::stability;

// A unit cube sliding at 10 m/s on flat ground (friction 0.5 on both, so 0.5 mixed)
// slows by mu g t until it stops.
TEST(Friction, BoxSlidingAt10MetresPerSecondDeceleratesAtMuG) {
    auto space = make_space();
    constexpr double kMu = 0.5;
    add_static_box(*space, Vec3(30, 1, 5), Vec3(0, -1, 0), Quat::Identity(), kMu);
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.5));
    d.position = Vec3(-20, 0.5, 0);
    d.linear_velocity = Vec3(10, 0, 0);
    d.friction = kMu;
    const BodyHandle box = space->create_body(d);
    const double stop_time = 10 / (kMu * kGravity);
    double worst = 0;
    for (int step = 1; step <= 150; ++step) {
        space->update();
        const double t = step * kStep;
        const double expected = std::max(0.0, 10 - kMu * kGravity * t);
        worst = std::max(worst, std::abs(space->internal_linear_velocity(box).x() - expected));
    }
    std::printf(
        "[ measure  ] sliding box: worst |v - (10 - mu g t)| %.3g m/s over 2.5 s (stops at %.3f s), final x %.4f "
        "(analytic %.4f)\n",
        worst, stop_time, space->internal_position(box).x(), -20 + 10 * stop_time / 2);
    EXPECT_LT(worst, 2e-2);
}

namespace {

constexpr double kRampAngle = 0.25;  // rad; tan = 0.2553

struct RampRun {
    double speed_down = 0;  // along the slope, after 1 s, m/s
    double moved = 0;       // along the slope, over 1 s, m
};

// A unit cube at rest on a static box tilted by kRampAngle about z (downhill is -x),
// both with friction mu.
RampRun slide_on_ramp(double mu) {
    auto space = make_space();
    const Quat tilt(Eigen::AngleAxisd(kRampAngle, Vec3::UnitZ()));
    add_static_box(*space, Vec3(10, 0.5, 3), Vec3::Zero(), tilt, mu);
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.5));
    d.position = tilt * Vec3(0, 1, 0);
    d.orientation = tilt;
    d.friction = mu;
    const BodyHandle box = space->create_body(d);
    const Vec3 downhill = tilt * -Vec3::UnitX();
    for (int step = 0; step < 60; ++step) space->update();
    RampRun run;
    run.speed_down = space->internal_linear_velocity(box).dot(downhill);
    run.moved = (space->internal_position(box) - d.position).dot(downhill);
    return run;
}

}  // namespace

TEST(Friction, BoxOnA025RadianRampSticksForMuFromPoint3) {
    for (const double mu : {0.3, 0.4, 0.6}) {
        const RampRun run = slide_on_ramp(mu);
        std::printf("[ measure  ] ramp mu %.1f: moved %.3g m, speed %.3g m/s after 1 s\n", mu, run.moved,
                    run.speed_down);
        EXPECT_LT(std::abs(run.moved), 1e-3) << "mu " << mu;
        EXPECT_LT(std::abs(run.speed_down), 1e-3) << "mu " << mu;
    }
}

TEST(Friction, BoxOnA025RadianRampSlidesAtCoulombsAccelerationForMuUpToPoint2) {
    for (const double mu : {0.0, 0.1, 0.2}) {
        const RampRun run = slide_on_ramp(mu);
        const double a = kGravity * (std::sin(kRampAngle) - mu * std::cos(kRampAngle));
        std::printf(
            "[ measure  ] ramp mu %.1f: speed %.4f m/s after 1 s (analytic %.4f), moved %.4f m (analytic %.4f)\n", mu,
            run.speed_down, a, run.moved, a / 2);
        EXPECT_NEAR(run.speed_down, a, 2e-2) << "mu " << mu;
    }
}

// A pyramid of 15 unit cubes (5 at the base, in a plane) whose rows overlap by a
// quarter of a box pushes apart no faster than push-out speed plus free fall.
TEST(OverlapRecovery, SmallPyramidWithQuarterOverlapSeparatesAtThePushOutSpeed) {
    auto space = make_space();
    const BodyHandle floor = add_static_box(*space, Vec3(10, 1, 10), Vec3(0, -1, 0));
    std::vector<BodyHandle> boxes;
    for (int row = 0; row < 5; ++row) {
        for (int i = 0; i < 5 - row; ++i) {
            boxes.push_back(add_box(*space, Vec3::Constant(0.5), Vec3(-2 + 0.5 * row + i, 0.5 + 0.75 * row, 0)));
        }
    }
    const OverlapRun run = run_overlap_recovery("small overlapping pyramid", *space, boxes, floor, 240);
    EXPECT_LE(run.worst_speed_excess, 0.0);
    EXPECT_LT(run.final_overlap, 0.01);
}

// A 0.1 m sphere at 200 m/s head-on at a static wall 0.1 m thick: it stops against
// the wall, never beyond it.
TEST(FastBodies, SphereAt200MetresPerSecondStopsAtAThinWall) {
    auto space = make_space();
    space->set_gravity(Vec3::Zero());
    add_static_box(*space, Vec3(0.05, 2, 2), Vec3::Zero());
    BodyDesc d;
    d.shape = Shape::sphere(0.1);
    d.fast = true;
    d.position = Vec3(-9.2, 0, 0);  // 2.7 steps from the wall: no step ends just touching it
    d.linear_velocity = Vec3(200, 0, 0);
    const BodyHandle ball = space->create_body(d);
    double farthest = -kHuge;
    for (int step = 0; step < 30; ++step) {
        space->update();
        farthest = std::max(farthest, space->internal_position(ball).x());
    }
    std::printf("[ measure  ] 200 m/s sphere: farthest centre x %.4f m (touching at -0.15), final speed %.3g m/s\n",
                farthest, space->internal_linear_velocity(ball).norm());
    EXPECT_LT(farthest, -0.15 + 0.01);
    EXPECT_LT(space->internal_linear_velocity(ball).norm(), 0.01);
}
