// Each effect is paid for only where a scene uses it (design.md section 7): the work
// counters stay at zero for an effect no body asks for, and count exactly the bodies
// or contact points that do.
#include <cmath>

#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include "static_bodies.hpp"

using namespace spindle;

namespace effects_test {

namespace {

BodyDesc ball(const Vec3& p) {
    BodyDesc d;
    d.shape = Shape::sphere(0.5);
    d.position = p;
    return d;
}

void add_ground(Space& space, Real friction = 0.6, Real restitution = 0) {
    BodyDesc g = test::ground_plane();
    g.friction = friction;
    g.restitution = restitution;
    space.create_body(g);
}

// Solve and relax passes over the constraints per step.
std::uint64_t solver_passes(const Space& space) {
    const SolverSettings& s = space.settings().solver;
    return static_cast<std::uint64_t>(s.substeps * (s.iterations + s.relax_iterations));
}

// Rolling resistance is solved in the relax passes only (contact_solver.cpp).
std::uint64_t relax_passes(const Space& space) {
    const SolverSettings& s = space.settings().solver;
    return static_cast<std::uint64_t>(s.substeps * s.relax_iterations);
}

SpaceSettings awake() {
    SpaceSettings s;
    s.sleep.enabled = false;
    return s;
}

}  // namespace

TEST(Effects, GyroscopicTorqueOnlyForBodiesThatAskOrAreElongated) {
    Space space(awake());
    space.set_gravity(Vec3::Zero());
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.5, 0.2, 0.1));  // principal inertias 0.05 : 0.26 : 0.29
    d.angular_velocity = Vec3(0.1, 5, 0.1);
    space.create_body(d);
    // Elongated (inertias 0.005 : 1.0025 : 1.0025), but not free to turn, or not dynamic.
    BodyDesc pole = d;
    pole.shape = Shape::box(Vec3(1, 0.05, 0.05));
    pole.position = Vec3(0, 5, 0);
    pole.locks.rotation_x = true;
    space.create_body(pole);
    pole.locks = MotionLocks{};
    pole.position = Vec3(0, -5, 0);
    pole.type = MotionType::Kinematic;
    space.create_body(pole);
    for (int i = 0; i < 10; ++i) space.update();
    EXPECT_EQ(space.counters().gyroscopic_applied, 0u);
    d.position = Vec3(5, 0, 0);
    d.gyroscopic = true;
    space.create_body(d);
    for (int i = 0; i < 10; ++i) space.update();
    EXPECT_EQ(space.counters().gyroscopic_applied, 10u * 4u);  // one body, 4 substeps
    // A dynamic elongated body turns keeping its momentum without asking.
    pole.type = MotionType::Dynamic;
    pole.position = Vec3(-5, 0, 0);
    space.create_body(pole);
    for (int i = 0; i < 10; ++i) space.update();
    EXPECT_EQ(space.counters().gyroscopic_applied, 10u * 4u + 10u * 4u * 2u);  // and now two bodies
}

TEST(Effects, GravityScaleZeroSkipsGravity) {
    Space space(awake());
    BodyDesc d = ball(Vec3(0, 10, 0));
    d.gravity_scale = 0;
    const BodyHandle floating = space.create_body(d);
    for (int i = 0; i < 10; ++i) space.update();
    EXPECT_EQ(space.counters().gravity_applied, 0u);
    EXPECT_EQ(space.internal_position(floating).y(), 10.0);
    space.create_body(ball(Vec3(5, 10, 0)));
    space.update();
    EXPECT_EQ(space.counters().gravity_applied, 4u);
}

TEST(Effects, FrictionAndRestitutionOnlyWhereContactsHaveThem) {
    Space space(awake());
    add_ground(space, /*friction=*/0, /*restitution=*/0);
    BodyDesc d = ball(Vec3(0, 0.5, 0));
    d.friction = 0;
    space.create_body(d);
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_GT(space.counters().contact_points_solved, 0u);
    EXPECT_EQ(space.counters().friction_applied, 0u);
    EXPECT_EQ(space.counters().restitution_applied, 0u);
}

// A resting ball has one contact point, through every solve and relax pass of each step;
// friction is solved once per manifold (central friction) in every pass, so a box resting
// on its face (four points, one manifold) counts one friction row per pass against four
// point rows per pass.
TEST(Effects, FrictionCountsExactlyTheFrictionalManifolds) {
    Space space(awake());
    add_ground(space);
    space.create_body(ball(Vec3(0, 0.5, 0)));
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_EQ(space.counters().contact_points_solved, 30u * solver_passes(space));
    EXPECT_EQ(space.counters().friction_applied, 30u * solver_passes(space));
    EXPECT_EQ(space.counters().restitution_applied, 0u);

    Space boxes(awake());
    add_ground(boxes);
    BodyDesc box;
    box.shape = Shape::box(Vec3::Constant(0.5));
    box.position = Vec3(0, 0.5, 0);
    boxes.create_body(box);
    for (int i = 0; i < 30; ++i) boxes.update();
    EXPECT_EQ(boxes.counters().contact_points_solved, 4u * 30u * solver_passes(boxes));
    EXPECT_EQ(boxes.counters().friction_applied, 30u * solver_passes(boxes));
}

// Rolling resistance is one row per manifold in the relax passes, and only where a contact
// has it: a ball and a box resting without it solve none; a ball with it on a plane without
// it (the pair mixes the larger) solves one a relax pass.
TEST(Effects, RollingResistanceOnlyWhereContactsHaveIt) {
    Space space(awake());
    add_ground(space);
    space.create_body(ball(Vec3(0, 0.5, 0)));
    BodyDesc box;
    box.shape = Shape::box(Vec3::Constant(0.5));
    box.position = Vec3(3, 0.5, 0);
    space.create_body(box);
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_EQ(space.counters().rolling_applied, 0u);

    Space rolling(awake());
    add_ground(rolling);
    BodyDesc d = ball(Vec3(0, 0.5, 0));
    d.rolling_resistance = 0.05;
    rolling.create_body(d);
    for (int i = 0; i < 30; ++i) rolling.update();
    EXPECT_EQ(rolling.counters().rolling_applied, 30u * relax_passes(rolling));
    EXPECT_EQ(rolling.counters().friction_applied, 30u * solver_passes(rolling));
}

// Restitution is one pass after the substeps: each point of a bouncy contact is
// checked once per step.
TEST(Effects, RestitutionChecksEachBouncyPointOncePerStep) {
    Space space(awake());
    add_ground(space, /*friction=*/0.6, /*restitution=*/0.5);
    space.create_body(ball(Vec3(0, 0.5, 0)));
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_EQ(space.counters().contact_points_solved, 30u * solver_passes(space));
    EXPECT_EQ(space.counters().restitution_applied, 30u);
}

TEST(Effects, NoContactsNoSolverWork) {
    Space space(awake());
    for (int i = 0; i < 5; ++i) space.create_body(ball(Vec3(3.0 * i, 10, 0)));
    for (int i = 0; i < 20; ++i) space.update();
    EXPECT_EQ(space.counters().contact_points_solved, 0u);
    EXPECT_EQ(space.counters().contacts_updated, 0u);
    EXPECT_EQ(space.counters().bodies_integrated, 5u * 20u);
}

// Collision tests only for pairs that moved: a resting box keeps its manifold (moved
// with the bodies), a sliding one has it recomputed every step.
TEST(Effects, RestingContactsKeepTheirManifolds) {
    Space space(awake());
    add_ground(space);
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.5));
    d.position = Vec3(0, 0.5, 0);
    const BodyHandle box = space.create_body(d);
    for (int i = 0; i < 60; ++i) space.update();
    const WorkCounters before = space.counters();
    for (int i = 0; i < 60; ++i) space.update();
    const WorkCounters after = space.counters();
    EXPECT_EQ(after.contacts_updated - before.contacts_updated, 60u);
    EXPECT_GE(after.manifolds_reused - before.manifolds_reused, 55u);
    EXPECT_NEAR(space.internal_position(box).y(), 0.5, 0.01);
}

// Colouring only when the constraints changed: a resting stack reuses the last step's
// colours; a new body (the body count) or a joint colours again, once: the joint list
// is compared as the manifold list is.
TEST(Effects, RestingStacksAreColouredOnlyWhenTheirConstraintsChange) {
    Space space(awake());
    add_ground(space);
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.5));
    std::vector<BodyHandle> boxes;
    for (int i = 0; i < 5; ++i) {
        d.position = Vec3(0, 0.5 + i, 0);
        boxes.push_back(space.create_body(d));
    }
    for (int i = 0; i < 60; ++i) space.update();
    const std::uint64_t settled = space.counters().constraint_colorings;
    for (int i = 0; i < 60; ++i) space.update();
    EXPECT_LE(space.counters().constraint_colorings - settled, 2u);
    EXPECT_NEAR(space.internal_position(boxes.back()).y(), 4.5, 0.05);

    space.create_joint(JointDesc::ball_socket_at(boxes[0], boxes[1], Vec3(0, 1, 0)));
    const std::uint64_t before_joint = space.counters().constraint_colorings;
    for (int i = 0; i < 3; ++i) space.update();
    EXPECT_EQ(space.counters().constraint_colorings, before_joint + 1);  // the new joint, then reused
    EXPECT_NEAR(space.internal_position(boxes.back()).y(), 4.5, 0.05);
}

// The same manifolds but one more body: the packing's immovable body (the last solver
// body) moved, so the colours are made again. No ground here, so the manifold list
// itself does not change.
TEST(Effects, ANewBodyMeansNewColours) {
    SpaceSettings settings = awake();
    settings.gravity = Vec3::Zero();
    Space space(settings);
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.5));
    d.position = Vec3(0, 0, 0);
    space.create_body(d);
    d.position = Vec3(1, 0, 0);  // face to face with the first
    space.create_body(d);
    for (int i = 0; i < 10; ++i) space.update();
    const std::uint64_t settled = space.counters().constraint_colorings;
    space.update();
    ASSERT_EQ(space.counters().constraint_colorings, settled);
    ASSERT_GT(space.last_update().contacts, 0u);
    d.position = Vec3(20, 0, 0);  // far away: no new contact
    space.create_body(d);
    space.update();
    EXPECT_EQ(space.counters().constraint_colorings, settled + 1);
}

// A sliding contact recycles its manifold until it has slid the recycle distance (10
// linear slops, 5 cm, while it touches) from where it was collided, then collides again:
// at 1.8 m/s (3 cm a step) and 2.7 m/s (4.5 cm) every other step, at 3.6 m/s (6 cm) every
// step.
TEST(Effects, SlidingContactsAreRecomputed) {
    for (const double speed : {1.8, 2.7, 3.6}) {
        Space space(awake());
        add_ground(space, 0);
        BodyDesc d;
        d.shape = Shape::box(Vec3::Constant(0.5));
        d.position = Vec3(0, 0.5, 0);
        d.friction = 0;
        d.linear_velocity = Vec3(speed, 0, 0);
        const BodyHandle box = space.create_body(d);
        for (int i = 0; i < 30; ++i) space.update();
        EXPECT_EQ(space.counters().contacts_updated, 30u);
        EXPECT_EQ(space.counters().manifolds_reused, speed < 3 ? 15u : 0u) << speed << " m/s";
        EXPECT_NEAR(space.internal_position(box).y(), 0.5, 0.01);
        EXPECT_NEAR(space.internal_linear_velocity(box).x(), speed, 1e-6);
    }
}

// Recycling measures how far the body's points have swung by its extent along each axis
// (Box3D's modified cross): a 10.5 m capsule lying on a frictionless ground and spinning
// about its long axis at 0.6 rad/s swings its points by its girth, 0.35 cm a step, and
// keeps its manifold for about ten steps of eleven; spun as fast about the vertical, its
// ends swing 5 cm a step, past the recycle distance, and it collides every step.
TEST(Effects, ALongBodySpinningAboutItsLengthKeepsItsManifold) {
    for (const bool about_length : {true, false}) {
        Space space(awake());
        add_ground(space, 0);
        BodyDesc d;
        d.shape = Shape::capsule(5, 0.25);
        d.orientation = Quat(Eigen::AngleAxis<Real>(-kPi / 2, Vec3::UnitZ()));  // lying along x
        d.position = Vec3(0, 0.25, 0);
        d.friction = 0;
        d.angular_velocity = about_length ? Vec3(0.6, 0, 0) : Vec3(0, 0.6, 0);
        const BodyHandle capsule = space.create_body(d);
        for (int i = 0; i < 30; ++i) space.update();
        EXPECT_EQ(space.counters().contacts_updated, 30u);
        if (about_length) {
            EXPECT_GE(space.counters().manifolds_reused, 24u);
        } else {
            EXPECT_EQ(space.counters().manifolds_reused, 0u);
        }
        EXPECT_NEAR(space.internal_position(capsule).y(), 0.25, 0.01);
        EXPECT_NEAR(space.internal_angular_velocity(capsule).norm(), 0.6, 1e-3);
    }
}
// A body's reach in the recycling test is its extent along its own axes (Box3D's
// maxExtent), not its world bounds' corner: two cubes tilted with a diagonal upright, face
// to face in no gravity, one spinning about their common normal at 1.2 rad/s (0.02 rad a
// step). Their corners reach 0.87 m, so a contact recycles until the turn reaches 0.058 rad
// (two steps of three); by the bounds' corner (1.3 m) it lasted 0.038 rad (one of two).
TEST(Effects, ATiltedCubeSpinningAgainstAnotherRecyclesByItsOwnReach) {
    SpaceSettings settings = awake();
    settings.gravity = Vec3::Zero();
    Space space(settings);
    const Quat tilt = Quat(Eigen::AngleAxis<Real>(std::atan(1 / std::sqrt(2.0)), Vec3::UnitX())) *
                      Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));  // a diagonal along y
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.5));
    d.orientation = tilt;
    d.friction = 0;
    d.type = MotionType::Kinematic;
    space.create_body(d);
    const Vec3 normal = tilt * Vec3::UnitX();
    d.type = MotionType::Dynamic;
    d.position = normal;  // face to face
    d.angular_velocity = 1.2 * normal;
    const BodyHandle spinning = space.create_body(d);
    for (int i = 0; i < 60; ++i) space.update();
    EXPECT_EQ(space.counters().contacts_updated, 60u);
    EXPECT_GE(space.counters().manifolds_reused, 38u);
    EXPECT_NEAR((space.internal_position(spinning) - normal).norm(), 0, 1e-3);
    EXPECT_NEAR(space.internal_angular_velocity(spinning).dot(normal), 1.2, 1e-3);
}
}  // namespace effects_test
