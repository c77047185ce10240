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
    space.update(kStep);  // step 1: x = kStep
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
