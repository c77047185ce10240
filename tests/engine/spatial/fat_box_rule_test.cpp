// The broadphase's fat box rule (Box3D's; stages/broadphase_state.hpp FatBoxRule): a moving
// body's fat box is its bounds grown by the speculative distance and its shape's own margin
// (an eighth of its radius, at most 5 cm), a static body's is its bounds; a bad rule is
// refused naming the field; a slow body's box is not stretched along its motion, a fast
// one's is while in free flight, and not while its contacts move it; and a fast body closing
// on another still gets its contact before they meet.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "api/space_internals.hpp"
#include "stages/broadphase_state.hpp"
#include "static_bodies.hpp"
#include "world.hpp"

namespace spindle {
namespace {

bool same_box(const Aabb& a, const Aabb& b, Real tolerance = 1e-12) {
    return (a.min - b.min).cwiseAbs().maxCoeff() <= tolerance && (a.max - b.max).cwiseAbs().maxCoeff() <= tolerance;
}

TEST(FatBoxRule, MovingFatBox_IsBoundsPlusSpeculativePlusTheShapesMargin_StaticIsItsBounds) {
    Space space;
    space.set_gravity(Vec3::Zero());
    struct Case {
        Shape shape;
        bool is_static;
        Real margin;  // Box3D's: min(0.05, 0.125 x the shape's radius)
    };
    const Vec3 tetra[] = {Vec3(0, 0, 0), Vec3(0.4, 0, 0), Vec3(0, 0.4, 0), Vec3(0, 0, 0.4)};
    const Case cases[] = {
        {Shape::box(Vec3::Constant(0.1)), false, 0.125 * std::sqrt(0.03)},  // 0.0217: small cube
        {Shape::box(Vec3::Constant(1)), false, 0.05},                       // capped
        {Shape::sphere(0.2), false, 0.025},
        {Shape::capsule(0.1, 0.1), false, 0.025},  // half length + radius
        {Shape::convex_hull(tetra), false, -1},    // checked against the hull's own reach below
        {Shape::box(Vec3(20, 0.5, 20)), true, 0},  // static: its bounds
    };
    const auto n = static_cast<int>(std::size(cases));
    for (int k = 0; k < n; ++k) {
        BodyDesc d;
        d.shape = cases[k].shape;
        d.type = cases[k].is_static ? MotionType::Static : MotionType::Dynamic;
        d.position = Vec3(3.0 * k, 2, 0);
        space.create_body(d);
    }
    const World& world = SpaceInternals::world(space);
    const BroadphaseState& bp = *world.broadphase;
    const auto check = [&](const char* when) {
        for (int k = 0; k < n; ++k) {
            const auto slot = static_cast<std::size_t>(k);
            Real margin = cases[k].margin;
            if (margin < 0) {  // the tetrahedron: its farthest vertex from its centroid
                const Vec3 centroid = Vec3::Constant(0.1);
                margin = 0.125 * (Vec3(0.4, 0, 0) - centroid).norm();
            }
            const Real grow = cases[k].is_static ? 0 : 0.02 + margin;
            const Aabb expected = world.bodies.bounds[slot].fattened(grow);
            EXPECT_TRUE(same_box(bp.tree.fat_aabb(bp.proxy[slot]), expected))
                << when << ", body " << k << ": fat box min " << bp.tree.fat_aabb(bp.proxy[slot]).min.transpose()
                << ", expected " << expected.min.transpose();
        }
    };
    check("created");
    space.update();  // at rest: the boxes stay
    check("after a step");
}

// Bodies at rest move no proxy, so for steps on end the broadphase sets no fat box (it
// skips set_fat_boxes when none moved); the first step a body moves again its box must
// follow: after every step each awake body's fat box holds its bounds.
TEST(FatBoxRule, BodiesAtRestForStepsThenPushed_TheirBoxesFollowFromTheFirstStep) {
    Space space;
    space.set_gravity(Vec3::Zero());
    std::vector<BodyHandle> bodies;
    for (int k = 0; k < 3; ++k) {
        BodyDesc d;
        d.shape = Shape::box(Vec3::Constant(0.5));
        d.position = Vec3(0, 0, 3.0 * k);
        d.allow_sleep = false;
        bodies.push_back(space.create_body(d));
    }
    const World& world = SpaceInternals::world(space);
    const BroadphaseState& bp = *world.broadphase;
    const auto boxes_hold_bounds = [&](const char* when, int step) {
        for (const std::uint32_t i : world.awake) {
            EXPECT_TRUE(bp.tree.fat_aabb(bp.proxy[i]).contains(world.bodies.bounds[i]))
                << when << ", step " << step << ": body " << i << "'s bounds left its fat box";
        }
    };
    const std::uint32_t pushed = bodies[1].index;
    const Aabb resting = bp.tree.fat_aabb(bp.proxy[pushed]);
    for (int step = 0; step < 10; ++step) {
        space.update();
        boxes_hold_bounds("at rest", step);
    }
    EXPECT_TRUE(same_box(bp.tree.fat_aabb(bp.proxy[pushed]), resting, 0)) << "a body at rest got another box";
    space.set_linear_velocity(bodies[1], Vec3(3, 0, 0));  // 5 cm a step: out of its box within steps
    for (int step = 0; step < 20; ++step) {
        space.update();
        boxes_hold_bounds("pushed", step);
    }
    EXPECT_FALSE(same_box(bp.tree.fat_aabb(bp.proxy[pushed]), resting, 0)) << "the pushed body's box never moved";
}

TEST(FatBoxRule, BadRule_IsRefusedNamingTheField) {
    const auto refused = [](const FatBoxRule& rule, const std::string& field) {
        try {
            BroadphaseState state(rule);
            ADD_FAILURE() << field << ": accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
        }
    };
    refused(FatBoxRule{.speculative = -0.01}, "speculative");
    refused(FatBoxRule{.speculative = std::numeric_limits<Real>::quiet_NaN()}, "speculative");
    refused(FatBoxRule{.max_margin = -1}, "max_margin");
    refused(FatBoxRule{.max_margin = std::numeric_limits<Real>::infinity()}, "max_margin");
    refused(FatBoxRule{.margin_fraction = -0.125}, "margin_fraction");
    refused(FatBoxRule{.stretch = -2}, "stretch");
    refused(FatBoxRule{.stretch = std::numeric_limits<Real>::infinity()}, "stretch");
    refused(FatBoxRule{.free_tolerance = -0.25}, "free_tolerance");
    refused(FatBoxRule{.free_tolerance = std::numeric_limits<Real>::quiet_NaN()}, "free_tolerance");
    EXPECT_NO_THROW(BroadphaseState(
        FatBoxRule{.speculative = 0, .max_margin = 0, .margin_fraction = 0, .stretch = 0, .free_tolerance = 0}));
}

// Two 1 m cubes (margin 5 cm) gliding along x without gravity: one at 1 m/s (1.7 cm a step,
// under its margin), one at 12 m/s (20 cm a step). Each time a box is made again it is the
// bounds swept over the step and grown by the speculative distance and the margin; the slow
// cube's is not stretched (a tight box), the fast cube's reaches two displacements further
// ahead, so it is made again every few steps, not every step.
TEST(FatBoxRule, SlowBodysBoxIsTight_FastBodysIsStretchedAndLastsSteps) {
    Space space;
    space.set_gravity(Vec3::Zero());
    const Real speeds[] = {1, 12};
    for (int k = 0; k < 2; ++k) {
        BodyDesc d;
        d.shape = Shape::box(Vec3::Constant(0.5));
        d.position = Vec3(0, 0, 4.0 * k);
        d.linear_velocity = Vec3(speeds[k], 0, 0);
        space.create_body(d);
    }
    const World& world = SpaceInternals::world(space);
    const BroadphaseState& bp = *world.broadphase;
    const Real dt = TimeStepSettings{}.duration;
    const int steps = 60;
    for (int k = 0; k < 2; ++k) {
        const auto slot = static_cast<std::size_t>(k);
        const Real ahead = k == 0 ? 0 : 2 * speeds[k] * dt;  // the stretch along the motion
        int made = 0;
        Aabb fat = bp.tree.fat_aabb(bp.proxy[slot]);
        for (int step = 0; step < steps; ++step) {
            space.update();
            if (same_box(bp.tree.fat_aabb(bp.proxy[slot]), fat, 0)) continue;
            fat = bp.tree.fat_aabb(bp.proxy[slot]);
            ++made;
            Aabb expected = world.bodies.bounds[slot];  // this step's, before it moved
            expected.max.x() += speeds[k] * dt;         // swept over the step
            expected = expected.fattened(0.02 + 0.05);
            expected.max.x() += ahead;
            EXPECT_TRUE(same_box(fat, expected, 1e-9))
                << "speed " << speeds[k] << ", step " << step << ": fat box x " << fat.min.x() << ".." << fat.max.x()
                << ", expected " << expected.min.x() << ".." << expected.max.x();
        }
        EXPECT_GE(made, 3) << "speed " << speeds[k] << ": the box was never made again";
        if (k == 1) {
            EXPECT_LE(made, steps / 2) << "the fast cube's box was made again " << made << " times in " << steps;
        }
    }
}

// Gravity on, two 1 m cubes (margin 5 cm) each 6 m/s fast (10 cm a step, past the margin):
// one slides along a frictionless floor, its contact cancelling gravity every step; the
// other falls freely. Each time a box is made again it is grown by the speculative distance
// and the margin; the falling cube's holds its bounds swept over the step and reaches two
// displacements further down (free flight), the sliding cube's holds its bounds only
// (Box3D's box: a body carried by its contacts is neither swept nor stretched, which in a
// tumbling pile reached past its neighbours and made and lost contacts with the bodies
// beyond, moving with it, at every new box).
TEST(FatBoxRule, FastBodyInFreeFlightIsStretched_OneItsContactsMoveIsNot) {
    Space space;  // gravity (0, -9.81, 0)
    test::add_static_box(space, Vec3(200, 0.5, 5), Vec3(0, -0.5, 0), Quat::Identity(), 0);
    BodyDesc slider;
    slider.shape = Shape::box(Vec3::Constant(0.5));
    slider.position = Vec3(-100, 0.5, 0);  // resting on the floor
    slider.linear_velocity = Vec3(6, 0, 0);
    slider.friction = 0;
    const BodyHandle sliding = space.create_body(slider);
    BodyDesc faller;
    faller.shape = Shape::box(Vec3::Constant(0.5));
    faller.position = Vec3(0, 200, 20);  // far from the floor for the whole test
    faller.linear_velocity = Vec3(0, -6, 0);
    const BodyHandle falling = space.create_body(faller);
    const World& world = SpaceInternals::world(space);
    const BroadphaseState& bp = *world.broadphase;
    const Real dt = TimeStepSettings{}.duration;
    const int steps = 40;
    int made[2] = {0, 0};
    Aabb fat[2] = {bp.tree.fat_aabb(bp.proxy[sliding.index]), bp.tree.fat_aabb(bp.proxy[falling.index])};
    for (int step = 0; step < steps; ++step) {
        // The velocities the step's broadphase reads (its bounds are read after the step).
        const Vec3 v[2] = {world.bodies.v[sliding.index], world.bodies.v[falling.index]};
        space.update();
        for (int k = 0; k < 2; ++k) {
            const std::uint32_t slot = k == 0 ? sliding.index : falling.index;
            const Aabb now = bp.tree.fat_aabb(bp.proxy[slot]);
            if (same_box(now, fat[k], 0)) continue;
            fat[k] = now;
            if (step == 0) continue;  // the first step's bounds are the creation's, not a step's
            ++made[k];
            const Vec3 d = k == 0 ? Vec3::Zero() : Vec3(v[k] * dt);  // the sweep, the faller's only
            Aabb expected = world.bodies.bounds[slot];               // this step's, before it moved
            expected.min += d.cwiseMin(Vec3::Zero());
            expected.max += d.cwiseMax(Vec3::Zero());
            expected = expected.fattened(0.02 + 0.05);
            if (k == 1) expected.min.y() += 2 * d.y();  // the stretch, down along the fall
            EXPECT_TRUE(same_box(now, expected, 1e-9))
                << (k == 0 ? "sliding" : "falling") << " cube, step " << step << ": fat box x " << now.min.x() << ".."
                << now.max.x() << ", y " << now.min.y() << ".." << now.max.y() << ", expected x " << expected.min.x()
                << ".." << expected.max.x() << ", y " << expected.min.y() << ".." << expected.max.y();
        }
    }
    EXPECT_NEAR(space.internal_motion_state(sliding).linear_velocity.x(), 6, 1e-3) << "the slider slowed down";
    EXPECT_GE(made[0], steps / 2) << "the sliding cube's box, made again " << made[0] << " times in " << steps;
    EXPECT_GE(made[1], 3) << "the falling cube's box was never made again";
    EXPECT_LE(made[1], steps / 2) << "the falling cube's box was made again " << made[1] << " times in " << steps;
}

// A 20 cm cube at 30 m/s (half a metre a step) head on into a resting 50 cm cube, no
// gravity. Its first fat box reaches 4 cm ahead of it; the bounds swept over the step
// and the fast body's stretch must find the pair in the step before they meet; a pair
// found later leaves the cube a step deep in the other. Continuous does not help: it
// sweeps against static geometry only.
TEST(FatBoxRule, FastCubeClosingOnAnother_GetsItsContactBeforeTheyMeet) {
    for (const Real start : {-3.0, -3.013, -3.031, -3.047}) {  // each meets at another point of a step
        Space space;
        space.set_gravity(Vec3::Zero());
        BodyDesc target;
        target.shape = Shape::box(Vec3::Constant(0.25));
        const BodyHandle b = space.create_body(target);
        BodyDesc bullet;
        bullet.shape = Shape::box(Vec3::Constant(0.1));
        bullet.position = Vec3(start, 0, 0);
        bullet.linear_velocity = Vec3(30, 0, 0);
        const BodyHandle a = space.create_body(bullet);
        Real deepest = -1;
        for (int step = 0; step < 20; ++step) {
            space.update();
            const Real a_front = space.internal_motion_state(a).position.x() + 0.1;
            const Real b_back = space.internal_motion_state(b).position.x() - 0.25;
            deepest = std::max(deepest, a_front - b_back);
        }
        EXPECT_LT(deepest, 0.01) << "start " << start << ": the cube went " << deepest << " m into the other";
        EXPECT_GT(space.internal_motion_state(b).linear_velocity.x(), 1) << "start " << start << ": no hit";
    }
}

// A 20 cm cube resting on the floor beside a 50 cm one, 30 cm apart, is given 30 m/s
// toward it (half a metre a step): its contact with the floor held it, so it is not in free
// flight, but its velocity changed by far more than its margin a step, so its box holds its
// bounds swept over the step and the pair is found before they meet. A body carried by its
// contacts is not swept; a thrown one must be.
TEST(FatBoxRule, CubeThrownFromRest_GetsItsContactBeforeItMeetsAnother) {
    for (const Real gap : {0.3, 0.25, 0.35}) {
        Space space;
        test::add_static_box(space, Vec3(20, 0.5, 20), Vec3(0, -0.5, 0));
        BodyDesc target;
        target.shape = Shape::box(Vec3::Constant(0.25));
        target.position = Vec3(0, 0.25, 0);
        const BodyHandle b = space.create_body(target);
        BodyDesc thrown;
        thrown.shape = Shape::box(Vec3::Constant(0.1));
        thrown.position = Vec3(-0.25 - gap - 0.1, 0.1, 0);
        const BodyHandle a = space.create_body(thrown);
        for (int step = 0; step < 30; ++step) space.update();  // both at rest on the floor
        space.set_linear_velocity(a, Vec3(30, 0, 0));
        Real deepest = -1;
        Real hit_speed = 0;  // the target's fastest (the floor's friction slows it after)
        for (int step = 0; step < 10; ++step) {
            space.update();
            const Real a_front = space.internal_motion_state(a).position.x() + 0.1;
            const Real b_back = space.internal_motion_state(b).position.x() - 0.25;
            deepest = std::max(deepest, a_front - b_back);
            hit_speed = std::max(hit_speed, space.internal_motion_state(b).linear_velocity.x());
        }
        EXPECT_LT(deepest, 0.01) << "gap " << gap << ": the cube went " << deepest << " m into the other";
        EXPECT_GT(hit_speed, 1) << "gap " << gap << ": no hit";
    }
}

}  // namespace
}  // namespace spindle
