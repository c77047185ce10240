// Stacks: tall cube stacks standing for 1000 steps, the same stack 10 km from the
// origin, and heavy boxes resting on light ones.
#include "scene_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace spindle;
using namespace spindle::stability;

namespace {

constexpr int kSteps = 1000;
constexpr int kSettleStep = 60;

struct StackRun {
    double top_drift_from_settled = 0;  // worst over steps 60..1000, m
    double top_drift_from_ideal = 0;    // worst over steps 60..1000, m
    double final_top_from_ideal = 0;    // at step 1000, m
    double worst_box_from_settled = 0;  // any box at step 1000, m
    std::vector<Vec3> final_relative;   // box positions minus the base, at step 1000
    bool finite = true;
};

// A stack of count unit cubes on a static floor box whose top is at base.y().
StackRun run_stack(int count, int substeps, const Vec3& base) {
    auto space = make_space();
    SolverSettings solver;
    solver.substeps = substeps;
    space->set_solver(solver);
    add_static_box(*space, Vec3(10, 1, 10), base - Vec3(0, 1, 0));
    const std::vector<BodyHandle> boxes = add_cube_stack(*space, count, base);
    const BodyHandle top = boxes.back();
    const Vec3 ideal = base + Vec3(0, count - 0.5, 0);
    StackRun run;
    std::vector<Vec3> settled;
    for (int step = 1; step <= kSteps; ++step) {
        space->update();
        if (step == kSettleStep) settled = positions(*space, boxes);
        if (step < kSettleStep) continue;
        const Vec3 p = space->internal_position(top);
        run.top_drift_from_settled = std::max(run.top_drift_from_settled, (p - settled.back()).norm());
        run.top_drift_from_ideal = std::max(run.top_drift_from_ideal, (p - ideal).norm());
    }
    run.finite = all_finite(*space, boxes);
    run.final_top_from_ideal = (space->internal_position(top) - ideal).norm();
    run.worst_box_from_settled = max_displacement(*space, boxes, settled);
    for (BodyHandle b : boxes) run.final_relative.push_back(space->internal_position(b) - base);
    std::printf("[ measure  ] %d cubes, %d substeps: top drift from settled (step 60) max %.4f m; "
                "from ideal max %.4f m, final %.4f m; worst box from settled %.4f m\n",
                count, substeps, run.top_drift_from_settled, run.top_drift_from_ideal, run.final_top_from_ideal,
                run.worst_box_from_settled);
    return run;
}

}  // namespace

// The pass criterion asserted is the top box's drift from its settled pose (step 60):
// soft contacts compress in proportion to load, so the settled stack stands a little
// lower than the ideal one; that offset is reported but is not drift.
TEST(Stack, TwentyCubesAtDefaultSettingsStandFor1000Steps) {
    const StackRun run = run_stack(20, SolverSettings{}.substeps, Vec3::Zero());
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.top_drift_from_settled, 0.05);
    EXPECT_LT(run.worst_box_from_settled, 0.05);
}

// Taller stacks stand at the defaults because resting manifolds are recycled (issue 16):
// each contact's points stay anchored to the boxes, so the support under a box does not
// follow the overlap as it shifts on the one below. Before, with fresh manifolds every
// step, a column of soft contacts buckled exactly as springs do (at the default 60 Hz a
// 30-cube column leant exponentially, e-folding in 1.7 s, and fell: its top ended 198 m
// away); Box3D's columns stand only through the same recycling.
TEST(Stack, ThirtyCubesAtDefaultSettingsStandFor1000Steps) {
    const StackRun run = run_stack(30, SolverSettings{}.substeps, Vec3::Zero());
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.top_drift_from_settled, 0.1);
    EXPECT_LT(run.worst_box_from_settled, 0.1);
}

TEST(Stack, FiftyCubesAtDefaultSettingsStandFor1000Steps) {
    const StackRun run = run_stack(50, SolverSettings{}.substeps, Vec3::Zero());
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.top_drift_from_settled, 0.2);
    EXPECT_LT(run.worst_box_from_settled, 0.2);
}

TEST(Stack, TwentyCubesTenKilometresAwayMatchTheStackAtTheOrigin) {
    const StackRun here = run_stack(20, SolverSettings{}.substeps, Vec3::Zero());
    const StackRun far = run_stack(20, SolverSettings{}.substeps, Vec3(10000, 0, 0));
    double worst = 0;
    for (std::size_t i = 0; i < here.final_relative.size(); ++i) {
        worst = std::max(worst, (far.final_relative[i] - here.final_relative[i]).norm());
    }
    std::printf("[ measure  ] 10 km stack vs origin stack: worst box difference relative to the base %.3g m\n", worst);
    EXPECT_TRUE(far.finite);
    EXPECT_LT(worst, 1e-3);
}

namespace {

struct HeavyRun {
    double worst_overlap = 0;  // m, deepest penetration of any pair over steps 60..1000
    double worst_tilt = 0;     // rad, heavy boxes
    bool finite = true;
};

// Light cubes (1 kg) on the floor carrying boxes ratio times heavier: a heavy cube on
// a single light cube, and a heavy plate on a 2 x 2 block of light cubes.
HeavyRun run_heavy_on_light(double ratio, int substeps) {
    auto space = make_space();
    SolverSettings solver;
    solver.substeps = substeps;
    space->set_solver(solver);
    std::vector<BodyHandle> all{add_static_box(*space, Vec3(10, 1, 10), Vec3(0, -1, 0))};
    all.push_back(add_box(*space, Vec3::Constant(0.5), Vec3(-3, 0.5, 0), 1));
    const BodyHandle cube = add_box(*space, Vec3::Constant(0.5), Vec3(-3, 1.5, 0), ratio);
    for (int i = 0; i < 4; ++i) {
        all.push_back(
            add_box(*space, Vec3::Constant(0.5), Vec3(2 + ((i & 1) ? 0.5 : -0.5), 0.5, (i & 2) ? 0.5 : -0.5), 1));
    }
    const BodyHandle plate = add_box(*space, Vec3(1, 0.5, 1), Vec3(2, 1.5, 0), ratio);
    all.push_back(cube);
    all.push_back(plate);
    HeavyRun run;
    for (int step = 1; step <= kSteps; ++step) {
        space->update();
        if (step < kSettleStep) continue;
        run.worst_overlap = std::max(run.worst_overlap, deepest_penetration(*space, all));
        for (BodyHandle b : {cube, plate}) {
            run.worst_tilt = std::max(run.worst_tilt, Eigen::AngleAxisd(space->internal_orientation(b)).angle());
        }
    }
    run.finite = all_finite(*space, all);
    std::printf("[ measure  ] heavy on light %g:1, %d substeps: deepest overlap %.4f m, worst heavy tilt %.4f rad\n",
                ratio, substeps, run.worst_overlap, run.worst_tilt);
    return run;
}

}  // namespace

TEST(HeavyOnLight, HundredToOneDoesNotPushThrough) {
    const HeavyRun run = run_heavy_on_light(100, SolverSettings{}.substeps);
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.worst_overlap, 0.05);
}

// A mass ratio of 1000 needs stiffer contacts: more substeps.
TEST(HeavyOnLight, ThousandToOneWithSixteenSubstepsDoesNotPushThrough) {
    const HeavyRun run = run_heavy_on_light(1000, 16);
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.worst_overlap, 0.05);
}

namespace {

// Boxes resting on each other on a static floor (top at y = 0), bottom first, each
// given by its half extents, centre and mass; the worst of their motion from step 60
// (settled) to the end.
struct Rested {
    double lowest_bottom = 0;    // m: the lowest any box's underside went (below 0: into the floor)
    double worst_gap_error = 0;  // m: worst |centre height above the box under it - resting height|
    double final_speed = 0;      // m/s: fastest box at the end
    double worst_sideways = 0;   // m: most any box moved sideways (x, z) from where it was built
    bool finite = true;
};

struct Box {
    Vec3 half;
    Vec3 position;
    double mass;
    int below = -1;  // the box it rests on (-1: the floor)
};

Rested run_resting(const char* scene, const std::vector<Box>& layout, int steps) {
    auto space = make_space();
    add_static_box(*space, Vec3(10, 1, 10), Vec3(0, -1, 0));
    std::vector<BodyHandle> bodies;
    for (const Box& box : layout) bodies.push_back(add_box(*space, box.half, box.position, box.mass));
    Rested run;
    run.lowest_bottom = kHuge;
    for (int step = 1; step <= steps; ++step) {
        space->update();
        for (std::size_t i = 0; i < layout.size(); ++i) {
            const Vec3 p = space->internal_position(bodies[i]);
            run.lowest_bottom = std::min(run.lowest_bottom, p.y() - layout[i].half.y());
            const Vec3 sideways = p - layout[i].position;
            run.worst_sideways = std::max(run.worst_sideways, std::hypot(sideways.x(), sideways.z()));
            if (step < kSettleStep || layout[i].below < 0) continue;
            const Box& under = layout[static_cast<std::size_t>(layout[i].below)];
            const double rest = layout[i].half.y() + under.half.y();
            const double gap = p.y() - space->internal_position(bodies[static_cast<std::size_t>(layout[i].below)]).y();
            run.worst_gap_error = std::max(run.worst_gap_error, std::abs(gap - rest));
        }
    }
    run.finite = all_finite(*space, bodies);
    run.final_speed = max_speed(*space, bodies);
    std::printf("[ measure  ] %s: lowest underside %.4f m, worst gap error %.4f m, fastest at the end %.3g m/s, "
                "worst sideways %.4f m\n",
                scene, run.lowest_bottom, run.worst_gap_error, run.final_speed, run.worst_sideways);
    return run;
}

void expect_rested(const Rested& run) {
    EXPECT_TRUE(run.finite);
    EXPECT_GT(run.lowest_bottom, -0.02);   // no box through the floor
    EXPECT_LT(run.worst_gap_error, 0.06);  // order kept, each box on the one below
    EXPECT_LT(run.final_speed, 0.01);      // at rest
    EXPECT_LT(run.worst_sideways, 0.02);   // nothing squeezed out
}

// A column of unit cubes, each ratio times heavier than the one under it.
std::vector<Box> heavy_topped_column(const std::vector<double>& masses) {
    std::vector<Box> layout;
    for (std::size_t i = 0; i < masses.size(); ++i) {
        layout.push_back(
            {Vec3::Constant(0.5), Vec3(0, 0.5 + static_cast<double>(i), 0), masses[i], static_cast<int>(i) - 1});
    }
    return layout;
}

}  // namespace

// Issue 16's heavy-topped stack: 1, 100 and 10,000 kg cubes, heaviest on top, for 3 s at
// the defaults. Before support mass scaling (support_scales.cpp) the 1 kg cube was
// squeezed out, also with 16 substeps: an underside 0.72 m through the floor, a box
// 1.01 m off its resting height on the one below, one 1.05 m sideways, 0.11 m/s at the
// end. With it: 0.3 mm, 1.1 mm, 0.4 mm and 1e-7 m/s.
TEST(HeavyOnLight, HeavyToppedStackOf1_100_10000KgStands) {
    expect_rested(run_resting("1/100/10000 kg stack", heavy_topped_column({1, 100, 10000}), 180));
}

// The same kind at other ratios: a 1/50/2500 kg column, a 1000 kg cube on a 1 kg one,
// and a four-high column of ratio 20. Before: every one squeezed its bottom cube out
// (0.50 to 0.70 m through the floor, 1.0 to 1.3 m sideways); a five-high column of
// ratio 4 already did so, while three-high ones of ratio 2 to 10 stood.
TEST(HeavyOnLight, HeavyToppedStacksOfOtherRatiosStand) {
    expect_rested(run_resting("1/50/2500 kg stack", heavy_topped_column({1, 50, 2500}), 180));
    expect_rested(run_resting("1/1000 kg stack", heavy_topped_column({1, 1000}), 180));
    expect_rested(run_resting("1/20/400/8000 kg stack", heavy_topped_column({1, 20, 400, 8000}), 180));
}

// A 1000 kg plank on three 1 kg cubes (ends and middle), a 100 kg cube on its end.
// Before: the cubes sank 4.1 cm into the floor, the plank rocked 10 cm off its resting
// height, a cube moved 5.9 cm sideways, 0.03 m/s at the end.
TEST(HeavyOnLight, HeavyPlankAcrossLightCubesRests) {
    const std::vector<Box> layout = {
        {Vec3::Constant(0.5), Vec3(-2, 0.5, 0), 1},     {Vec3::Constant(0.5), Vec3(0, 0.5, 0), 1},
        {Vec3::Constant(0.5), Vec3(2, 0.5, 0), 1},      {Vec3(3, 0.25, 0.75), Vec3(0, 1.25, 0), 1000, 1},
        {Vec3::Constant(0.5), Vec3(2.2, 2, 0), 100, 3},
    };
    expect_rested(run_resting("1000 kg plank on 1 kg cubes", layout, 180));
}

// Only a light body resting on the ground, through support contacts, is solved heavier
// under a heavy one: a 100 kg box hitting a 1 kg box in the air exchanges momentum at
// the real masses (solved as equal masses, as on the ground, the pair lost a quarter of
// its momentum: -479 instead of -630 kg m/s after 20 steps).
TEST(HeavyOnLight, HeavyBoxHittingALightOneInTheAirKeepsMomentum) {
    SpaceSettings settings;
    auto space = make_space(settings);
    const BodyHandle light = add_box(*space, Vec3::Constant(0.5), Vec3(0, 10, 0), 1);
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.5));
    d.position = Vec3(0, 11.01, 0);
    d.mass = 100;
    d.linear_velocity = Vec3(0, -3, 0);
    const BodyHandle heavy = space->create_body(d);
    constexpr int kSteps = 20;
    double closest = kHuge;
    for (int step = 0; step < kSteps; ++step) {
        space->update();
        closest = std::min(closest, space->internal_position(heavy).y() - space->internal_position(light).y());
    }
    const double momentum = space->internal_linear_velocity(light).y() +
                            100 * space->internal_linear_velocity(heavy).y();
    const double expected = 100 * -3.0 - 101 * kGravity * kSteps * kStep;
    const double relative_speed = space->internal_linear_velocity(heavy).y() -
                                  space->internal_linear_velocity(light).y();
    std::printf("[ measure  ] heavy on light in the air: momentum %.3f kg m/s, free-flight %.3f; relative speed %.3g "
                "m/s\n",
                momentum, expected, relative_speed);
    EXPECT_LT(closest, 1.005);  // they met
    EXPECT_NEAR(momentum, expected, 0.01 * std::abs(expected));
}

namespace {

// The largest speed a 0.1 kg box on the floor reaches in 3 s as a 100 kg ball, dropped on
// its edge at 5 m/s, comes to rest on it and then rolls off it.
double light_box_speed_under_rolling_ball() {
    auto space = make_space();
    add_static_box(*space, Vec3(5, 0.5, 5), Vec3(0, -0.5, 0));
    BodyDesc light;
    light.shape = Shape::box(Vec3::Constant(0.05));
    light.mass = 0.1;
    light.friction = 0.5;
    light.position = Vec3(0, 0.05, 0);
    const BodyHandle box = space->create_body(light);
    BodyDesc heavy;
    heavy.shape = Shape::sphere(0.25);
    heavy.mass = 100;
    heavy.friction = 0.5;
    heavy.position = Vec3(0, 1.5, 0.05);
    heavy.linear_velocity = Vec3(0, -5, 0);
    space->create_body(heavy);
    double fastest = 0;
    for (int step = 0; step < 180; ++step) {
        space->update();
        fastest = std::max(fastest, space->internal_linear_velocity(box).norm());
    }
    return fastest;
}

}  // namespace

// A light body holding up a heavy one is solved as heavy as what it carries
// (support_scales.cpp); when the heavy one rolls off, the contact is no longer a support
// and the light body is solved at its own mass. Its stored impulses, which held up the
// heavy one, were warm started whole: at 2b1aee5 a 0.1 kg box under a 100 kg ball rolling
// off it was launched at 30.8 m/s (17 m high). Now the warm start keeps only the push the
// light body felt as it was solved (kept_share).
TEST(HeavyOnLight, LightBoxIsNotLaunchedWhenAHeavyBallRollsOffIt) {
    const double fastest = light_box_speed_under_rolling_ball();
    std::printf("[ measure  ] light box under a rolling heavy ball: at most %.2f m/s\n", fastest);
    EXPECT_LT(fastest, 3.0);
}

// Random piles of spheres, boxes, capsules and hulls of 0.1 to 100 kg dropped into a box
// (no bounce): none thrown out. Before kept_share, 3 of 60 seeds threw a body out within 4 s
// (these three; in 10 s, 6 of 40 threw 0.1-0.6 kg bodies over the 6 m walls at up to 60 m/s);
// with it none of the 60 does.
TEST(HeavyOnLight, RandomPilesOfMixedMassesThrowNothingOut) {
    for (const unsigned seed : {3u, 7u, 13u}) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> unit(0, 1);
        auto space = make_space();
        add_static_box(*space, Vec3(3, 0.5, 3), Vec3(0, -0.5, 0));
        for (const double side : {-2.2, 2.2}) {
            add_static_box(*space, Vec3(0.2, 3, 3), Vec3(side, 3, 0));
            add_static_box(*space, Vec3(3, 3, 0.2), Vec3(0, 3, side));
        }
        std::vector<BodyHandle> bodies;
        for (int i = 0; i < 120; ++i) {
            BodyDesc d;
            const double size = 0.05 + 0.4 * unit(rng) * unit(rng);
            switch (static_cast<int>(unit(rng) * 4)) {
                case 0: d.shape = Shape::sphere(size); break;
                case 1: d.shape = Shape::box(Vec3(size, size * (0.1 + unit(rng)), size * (0.2 + unit(rng)))); break;
                case 2: d.shape = Shape::capsule(size * (0.5 + 2 * unit(rng)), size * 0.5); break;
                default: {
                    std::vector<Vec3> points;
                    for (int k = 0; k < 10; ++k)
                        points.push_back(2 * size * Vec3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5));
                    d.shape = Shape::convex_hull(points);
                }
            }
            d.mass = std::pow(10.0, -1 + 3 * unit(rng));
            d.friction = unit(rng);
            d.position = Vec3((unit(rng) - 0.5) * 3.4, 0.5 + 4.5 * unit(rng), (unit(rng) - 0.5) * 3.4);
            const Vec3 axis = Vec3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
            d.orientation = Quat(Eigen::AngleAxisd(unit(rng) * 6, axis));
            d.linear_velocity = 6 * Vec3(unit(rng) - 0.5, -unit(rng), unit(rng) - 0.5);
            d.angular_velocity = 20 * Vec3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
            bodies.push_back(space->create_body(d));
        }
        int thrown = 0;
        for (int step = 0; step < 240; ++step) {
            space->update();
            thrown = 0;
            for (const BodyHandle b : bodies) {
                const Vec3 x = space->internal_position(b);
                thrown += std::abs(x.x()) < 2.1 && std::abs(x.z()) < 2.1 && x.y() > -0.1 && x.y() < 6 ? 0 : 1;
            }
            if (thrown > 0) break;
        }
        EXPECT_EQ(thrown, 0) << "seed " << seed;
    }
}
