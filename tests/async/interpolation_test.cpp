// Interpolation (the seed, section 2.B).
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

using namespace spindle;

namespace {

constexpr double kStep = 0.016667;

Space make_space() {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    s.time_step.use_internal_time_stepping = true;
    s.time_step.duration = kStep;
    return Space(s);
}

BodyDesc moving(bool interpolate) {
    BodyDesc d;
    d.type = MotionType::Kinematic;
    d.shape = Shape::sphere(0.1);
    d.linear_velocity = Vec3(1, 0, 0);
    d.angular_velocity = Vec3(0, 0, 3);
    d.allow_interpolation = interpolate;
    return d;
}

}  // namespace

TEST(Interpolation, SeedExampleBlendsPointFourOfNewestAndPointSixOfPrevious) {
    Space space = make_space();
    const BodyHandle body = space.create_body(moving(true));
    space.update(kStep);             // step 1: x = kStep
    space.update(kStep + 0.006667);  // step 2: x = 2 kStep, 0.006667 left over
    ASSERT_EQ(space.last_update().steps, 1);
    EXPECT_NEAR(space.motion_states().alpha(), 0.4, 1e-4);
    const double alpha = 0.006667 / kStep;
    const double previous = kStep, newest = 2 * kStep;
    EXPECT_NEAR(space.position(body).x(), (1 - alpha) * previous + alpha * newest, 1e-12);
    EXPECT_NEAR(space.center_of_mass(body).x(), (1 - alpha) * previous + alpha * newest, 1e-12);
    // Orientation: slerp between the two steps' rotations about z.
    const double angle = 3 * ((1 - alpha) * previous + alpha * newest);
    EXPECT_NEAR(2 * std::atan2(space.orientation(body).z(), space.orientation(body).w()), angle, 1e-6);
}

TEST(Interpolation, WithTheFlagOffTheNewestStateIsReturned) {
    Space space = make_space();
    const BodyHandle body = space.create_body(moving(false));
    space.update(kStep);
    space.update(kStep + 0.006667);
    EXPECT_NEAR(space.position(body).x(), 2 * kStep, 1e-12);
}

TEST(Interpolation, BodiesWithoutTheFlagPayNothing) {
    Space space = make_space();
    for (int i = 0; i < 10; ++i) space.create_body(moving(false));
    for (int i = 0; i < 10; ++i) space.update(kStep);
    EXPECT_EQ(space.counters().interpolated_publishes, 0u);
    space.create_body(moving(true));
    space.update(kStep);
    EXPECT_EQ(space.counters().interpolated_publishes, 1u);
}

TEST(Interpolation, SlerpTakesTheShortestArc) {
    const Quat a(Eigen::AngleAxisd(0.1, Vec3::UnitZ()));
    Quat b(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
    b.coeffs() = -b.coeffs();  // the same rotation, on the far side of the 4D sphere
    const Quat mid = slerp_shortest(a, b, 0.5);
    EXPECT_NEAR(mid.angularDistance(Quat(Eigen::AngleAxisd(0.2, Vec3::UnitZ()))), 0.0, 1e-12);
}

TEST(Interpolation, ATeleportJumpsInsteadOfSliding) {
    Space space = make_space();
    const BodyHandle body = space.create_body(moving(true));
    space.update(kStep);
    space.update(kStep);
    space.set_position(body, Vec3(100, 0, 0));
    space.update(0.5 * kStep);  // no step: the teleport alone is published
    EXPECT_EQ(space.last_update().steps, 0);
    EXPECT_EQ(space.position(body), Vec3(100, 0, 0));
    space.update(kStep);  // one step on: blends between 100 and 100 + kStep only
    EXPECT_GE(space.position(body).x(), 100.0);
}

// An update that takes no step and applies no write leaves the awake bodies as they
// were: once both published buffers hold the newest step, flips refill nothing. What
// changes without a step (a buffered write, a direct internal change) still shows in
// every later read, whichever buffer is in front.
TEST(Interpolation, UpdatesWithoutAStepRepublishOnlyWhatChanged) {
    Space space = make_space();
    std::vector<BodyHandle> bodies;
    for (int i = 0; i < 10; ++i) bodies.push_back(space.create_body(moving(i != 4)));  // 4: read unblended
    space.update(kStep);
    const double tiny = kStep / 100;
    space.update(tiny);  // the other buffer catches up with the step
    const std::uint64_t caught_up = space.counters().awake_publishes;
    for (int i = 0; i < 20; ++i) space.update(tiny);
    EXPECT_EQ(space.counters().awake_publishes, caught_up);
    EXPECT_EQ(space.last_update().steps, 0);

    // An impulse changes the velocity at once, without marking the body changed.
    BodyDesc ball = moving(false);
    ball.type = MotionType::Dynamic;
    ball.position = Vec3(0, 10, 0);
    ball.mass = 2;
    const BodyHandle dynamic = space.create_body(ball);
    space.update(kStep);
    for (int i = 0; i < 3; ++i) space.update(tiny);
    const Vec3 pushed = space.linear_velocity(dynamic) + Vec3(0, 5, 0) / 2;  // mass 2 kg
    space.apply_impulse(dynamic, Vec3(0, 5, 0));
    for (int i = 0; i < 3; ++i) {
        space.update(tiny);
        EXPECT_TRUE(space.linear_velocity(dynamic).isApprox(pushed, 1e-12)) << "flip " << i;
    }
    MotionState moved = space.internal_motion_state(bodies[4]);
    moved.position = Vec3(7, 8, 9);
    space.set_internal_motion_state(bodies[4], moved);
    for (int i = 0; i < 3; ++i) {
        space.update(tiny);
        EXPECT_TRUE(space.position(bodies[4]).isApprox(Vec3(7, 8, 9), 1e-12)) << "flip " << i;
    }
    const std::uint64_t before = space.counters().awake_publishes;
    for (int i = 0; i < 5; ++i) space.update(tiny);
    EXPECT_EQ(space.counters().awake_publishes, before);
}
