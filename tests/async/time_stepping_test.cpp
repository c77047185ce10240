// Internal time stepping (the seed 1.A; design.md section 3).
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace spindle;

namespace {

SpaceSettings internal_stepping(int max_steps = 10, int min_steps = 0) {
    SpaceSettings s;
    s.time_step.use_internal_time_stepping = true;
    s.time_step.duration = 1.0 / 60.0;
    s.time_step.max_steps_per_frame = max_steps;
    s.time_step.min_steps_per_frame = min_steps;
    return s;
}

}  // namespace

TEST(TimeStepping, ThirtiethOfASecondTakesTwoSixtiethSteps) {
    Space space(internal_stepping());
    space.update(1.0 / 30.0);
    EXPECT_EQ(space.last_update().steps, 2);
    EXPECT_NEAR(space.accumulated_time(), 0.0, 1e-12);
}

TEST(TimeStepping, LessThanAStepTakesNoneAndKeepsTheTime) {
    Space space(internal_stepping());
    space.update(0.01);
    EXPECT_EQ(space.last_update().steps, 0);
    EXPECT_NEAR(space.accumulated_time(), 0.01, 1e-15);
    space.update(0.01);
    EXPECT_EQ(space.last_update().steps, 1);
    EXPECT_NEAR(space.accumulated_time(), 0.02 - 1.0 / 60.0, 1e-12);
}

TEST(TimeStepping, CapTakesTenAndCarriesNoMoreThanTheCapsWorth) {
    Space space(internal_stepping(10));
    space.update(1.0);
    EXPECT_EQ(space.last_update().steps, 10);
    EXPECT_NEAR(space.accumulated_time(), 10.0 / 60.0, 1e-12);                   // carried: the cap's worth
    EXPECT_NEAR(space.last_update().dropped_seconds, 1.0 - 20.0 / 60.0, 1e-12);  // reported, not kept
    space.update(0.0);
    EXPECT_EQ(space.last_update().steps, 10);  // "trying again in the next update"
    EXPECT_NEAR(space.accumulated_time(), 0.0, 1e-12);
    space.update(0.0);
    EXPECT_EQ(space.last_update().steps, 0);
}

TEST(TimeStepping, MinStepsPerFrameIsHonoured) {
    Space space(internal_stepping(10, 2));
    space.update(0.0);
    EXPECT_EQ(space.last_update().steps, 2);
    EXPECT_EQ(space.accumulated_time(), 0.0);
}

TEST(TimeStepping, WithoutInternalSteppingEveryUpdateIsOneStep) {
    Space space;
    BodyDesc d;
    d.position = Vec3(0, 10, 0);
    const BodyHandle body = space.create_body(d);
    space.update(0.5);
    EXPECT_EQ(space.last_update().steps, 1);
    space.update(0.0);
    EXPECT_EQ(space.last_update().steps, 1);
    space.update();
    EXPECT_EQ(space.last_update().steps, 1);
    // Three steps of 1/60 s of free fall, not 0.5 s.
    EXPECT_NEAR(space.internal_linear_velocity(body).y(), -9.81 * 3 / 60.0, 1e-9);
}

TEST(TimeStepping, BadDtIsRejectedAndChangesNothing) {
    Space space(internal_stepping());
    space.update(0.01);
    for (double bad : {-0.1, std::nan(""), std::numeric_limits<double>::infinity()}) {
        try {
            space.update(bad);
            FAIL() << "accepted dt " << bad;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("dt must be"), std::string::npos) << e.what();
        }
        EXPECT_NEAR(space.accumulated_time(), 0.01, 1e-15);
    }
}

TEST(TimeStepping, BadSettingsAreRejected) {
    Space space;
    TimeStepSettings s;
    s.duration = 0;
    EXPECT_THROW(space.set_time_step(s), Error);
    s = TimeStepSettings{};
    s.min_steps_per_frame = 11;
    EXPECT_THROW(space.set_time_step(s), Error);
    EXPECT_EQ(space.settings().time_step.duration, 1.0 / 60.0);
}

TEST(TimeStepping, ForcesPersistUntilAStepConsumesThem) {
    Space space(internal_stepping());
    space.set_gravity(Vec3::Zero());
    BodyDesc d;
    d.mass = 2;
    const BodyHandle body = space.create_body(d);
    space.add_force(body, Vec3(120, 0, 0));
    space.update(0.001);  // no step: the force must survive
    EXPECT_EQ(space.last_update().steps, 0);
    EXPECT_EQ(space.internal_linear_velocity(body).x(), 0.0);
    space.update(1.0 / 60.0);  // one step consumes it: dv = F/m * dt = 1
    EXPECT_EQ(space.last_update().steps, 1);
    EXPECT_NEAR(space.internal_linear_velocity(body).x(), 1.0, 1e-12);
    space.update(1.0 / 60.0);  // and only that step
    EXPECT_NEAR(space.internal_linear_velocity(body).x(), 1.0, 1e-12);
}
