// Finite but huge input: impulses, forces, velocities and time steps near the largest
// double are taken, and the state stays finite: velocities are held to the solver's
// speed limits, and update(dt) counts its steps without overflowing.
#include <vector>

#include "invalid_input.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

constexpr Real kLargest = std::numeric_limits<Real>::max();

// Every live body's internal state is finite and within the speed limits.
void expect_finite_and_limited(const Space& space, const std::vector<BodyHandle>& bodies) {
    const SolverSettings& limits = space.settings().solver;
    for (const BodyHandle b : bodies) {
        SCOPED_TRACE(to_string(b));
        const MotionState s = space.internal_motion_state(b);
        EXPECT_TRUE(is_finite(s.position));
        EXPECT_TRUE(is_finite(s.orientation));
        EXPECT_TRUE(is_finite(s.center_of_mass));
        EXPECT_TRUE(is_finite(s.linear_velocity));
        EXPECT_TRUE(is_finite(s.angular_velocity));
        EXPECT_LE(s.linear_velocity.norm(), limits.max_linear_speed * (1 + 1e-12));
        EXPECT_LE(s.angular_velocity.norm(), limits.max_angular_speed * (1 + 1e-12));
    }
}

}  // namespace

TEST(HugeInput, ImpulsesNearTheLargestDoubleLeaveAFiniteState) {
    Scene scene = make_scene();
    Space& space = *scene.space;
    // A light body: its inverse mass times the impulse overflows.
    BodyDesc light;
    light.shape = Shape::sphere(0.1);
    light.mass = 1e-3;
    light.position = Vec3(-3, 1, 0);
    const BodyHandle feather = space.create_body(light);
    for (const BodyHandle b : {scene.box, scene.sphere, feather}) {
        space.apply_impulse(b, Vec3(1e306, -1e306, 1e306));
        space.apply_angular_impulse(b, Vec3(1e306, -1e306, 1e306));
    }
    space.flush();  // the writes alone, published
    for (const BodyHandle b : {scene.box, scene.sphere, feather}) {
        EXPECT_TRUE(is_finite(space.linear_velocity(b)));
        EXPECT_TRUE(is_finite(space.angular_velocity(b)));
    }
    for (int i = 0; i < 30; ++i) space.update();
    expect_finite_and_limited(space, {scene.sphere, scene.box, feather});
}

TEST(HugeInput, ForcesAndTorquesNearTheLargestDoubleLeaveAFiniteState) {
    Scene scene = make_scene();
    Space& space = *scene.space;
    for (int k = 0; k < 3; ++k) {  // accumulated: their sum overflows
        space.add_force(scene.box, Vec3(kLargest, -kLargest, kLargest));
        space.add_torque(scene.box, Vec3(kLargest, -kLargest, kLargest));
    }
    for (int i = 0; i < 30; ++i) space.update();
    expect_finite_and_limited(space, {scene.sphere, scene.box});
}

// Forces and impulses at points far out: their moments overflow, and must not turn into
// NaN (inf - inf) on the way to the torque.
TEST(HugeInput, ForcesAndImpulsesAtFarPointsLeaveAFiniteState) {
    Scene scene = make_scene();
    Space& space = *scene.space;
    const Vec3 far(1e9, 1e9, -1e9);
    for (int k = 0; k < 3; ++k) {
        space.add_force_at(scene.box, Vec3(kLargest, kLargest, -kLargest), far);
        space.apply_impulse_at(scene.box, Vec3(kLargest, kLargest, kLargest), far);
        space.apply_impulse_at(scene.sphere, Vec3(kLargest, -kLargest, kLargest), -far);
    }
    space.flush();
    EXPECT_TRUE(is_finite(space.angular_velocity(scene.box)));
    EXPECT_TRUE(is_finite(space.angular_velocity(scene.sphere)));
    for (int i = 0; i < 30; ++i) space.update();
    expect_finite_and_limited(space, {scene.sphere, scene.box});
}

TEST(HugeInput, HugeVelocitiesAreHeldToTheLimits) {
    Scene scene = make_scene();
    Space& space = *scene.space;
    BodyDesc kinematic;
    kinematic.type = MotionType::Kinematic;
    kinematic.shape = Shape::box(Vec3(1, 0.1, 1));
    kinematic.position = Vec3(0, 20, 0);
    kinematic.linear_velocity = Vec3(1e300, 1e300, 0);
    kinematic.angular_velocity = Vec3(0, kLargest, 0);
    const BodyHandle platform = space.create_body(kinematic);
    space.set_linear_velocity(scene.box, Vec3(kLargest, kLargest, kLargest));
    MotionState state = space.internal_motion_state(scene.sphere);
    state.angular_velocity = Vec3(-kLargest, 0, kLargest);
    space.set_internal_motion_state(scene.sphere, state);
    space.flush();
    EXPECT_NEAR(space.linear_velocity(scene.box).norm(), space.settings().solver.max_linear_speed, 1e-9);
    EXPECT_NEAR(space.linear_velocity(platform).norm(), space.settings().solver.max_linear_speed, 1e-9);
    EXPECT_NEAR(space.angular_velocity(scene.sphere).norm(), space.settings().solver.max_angular_speed, 1e-9);
    for (int i = 0; i < 30; ++i) space.update();
    expect_finite_and_limited(space, {scene.sphere, scene.box, platform});
}

TEST(HugeInput, HugeGravityLeavesAFiniteState) {
    Scene scene = make_scene();
    Space& space = *scene.space;
    space.set_gravity(Vec3(0, -1e300, 0));
    BodyDesc heavy;
    heavy.gravity_scale = 1e300;  // times the gravity: beyond the largest double
    heavy.position = Vec3(5, 2, 0);
    const BodyHandle body = space.create_body(heavy);
    for (int i = 0; i < 30; ++i) space.update();
    expect_finite_and_limited(space, {scene.sphere, scene.box, body});
}

// The limits are settings: a body is cut to them, and one below them is left alone.
TEST(HugeInput, SpeedLimitsAreSettings) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    settings.solver.max_linear_speed = 10;
    settings.solver.max_angular_speed = 5;
    Space space(settings);
    BodyDesc fast;
    fast.position = Vec3(0, 0, 0);
    fast.linear_velocity = Vec3(0, 0, 30);
    fast.angular_velocity = Vec3(20, 0, 0);
    const BodyHandle a = space.create_body(fast);
    BodyDesc slow = fast;
    slow.position = Vec3(100, 0, 0);
    slow.linear_velocity = Vec3(0, 0, 9);
    slow.angular_velocity = Vec3(4, 0, 0);
    const BodyHandle b = space.create_body(slow);
    space.update();
    EXPECT_NEAR(space.internal_linear_velocity(a).z(), 10, 1e-12);
    EXPECT_NEAR(space.internal_angular_velocity(a).x(), 5, 1e-12);
    EXPECT_EQ(space.internal_linear_velocity(b), Vec3(0, 0, 9));
    EXPECT_EQ(space.internal_angular_velocity(b), Vec3(4, 0, 0));
}

// With internal stepping, a huge dt takes the cap's steps, keeps the cap's worth and
// reports the rest as dropped (an int cast of dt / duration used to overflow).
TEST(HugeInput, HugeDtTakesTheCapAndDropsTheRest) {
    for (const Real dt : {2e8, 1e12, 1e300, kLargest}) {
        SCOPED_TRACE(dt);
        SpaceSettings settings;
        settings.time_step.use_internal_time_stepping = true;
        Scene scene = make_scene(settings);
        Space& space = *scene.space;
        const TimeStepSettings& ts = space.settings().time_step;
        space.update(dt);
        EXPECT_EQ(space.last_update().steps, ts.max_steps_per_frame);
        EXPECT_NEAR(space.accumulated_time(), ts.max_steps_per_frame * ts.duration, 1e-9);
        EXPECT_GT(space.last_update().dropped_seconds, 0);
        EXPECT_TRUE(std::isfinite(space.last_update().dropped_seconds));
        space.update(dt);  // again, on top of a full accumulator
        EXPECT_EQ(space.last_update().steps, ts.max_steps_per_frame);
        EXPECT_TRUE(std::isfinite(space.accumulated_time()));
    }
}

// Without internal stepping every update is one step, whatever dt is.
TEST(HugeInput, HugeDtWithoutInternalSteppingTakesOneStep) {
    Scene scene = make_scene();
    scene.space->update(1e12);
    EXPECT_EQ(scene.space->last_update().steps, 1);
}

// Positions are finite and within a billion metres of the origin: a body made, moved or
// set there is rejected naming the field, and the space is left as it was.
TEST(HugeInput, PositionsBeyondTheWorldBoundAreRejected) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    Space& space = *scene.space;
    for (const Real far : {1e10, 1e308, -1e15}) {
        const std::string trial = std::to_string(far);
        BodyDesc d;
        d.shape = Shape::sphere(0.5);
        d.position = Vec3(0, far, 0);
        expect_rejected(
            space, *twin.space, [&] { space.create_body(d); }, "position", trial);
        expect_rejected(
            space, *twin.space, [&] { space.set_position(scene.box, Vec3(far, 0, 0)); }, "position", trial);
        expect_rejected(
            space, *twin.space,
            [&] {
                space.set_motion_state(scene.box,
                                       MotionState{Vec3(0, 0, far), Quat::Identity(), Vec3::Zero(), Vec3::Zero()});
            },
            "position", trial);
    }
    // At the bound itself, accepted.
    BodyDesc edge;
    edge.shape = Shape::sphere(0.5);
    edge.position = Vec3(1e9, -1e9, 1e9);
    expect_accepted([&] { space.create_body(edge); }, "position", "1e9");
}
