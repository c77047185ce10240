// Changes after creation (issue 17): material, gravity scale, damping, user data, forces
// and impulses at points, kinematic moves, shape and motion type, each buffered (applied
// at the next update, the last write winning) and each checked (bad values and stale
// handles rejected with the space unchanged).
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <thread>

#include "space_calls.hpp"
#include "static_bodies.hpp"

using namespace spindle;

namespace setters_test {

namespace {

BodyHandle add_ground(Space& space) { return test::add_static_box(space, Vec3(10, 0.5, 10), Vec3(0, -0.5, 0)); }

BodyDesc ball(const Vec3& p) {
    BodyDesc d;
    d.shape = Shape::sphere(0.5);
    d.position = p;
    return d;
}

BodyDesc box(const Vec3& p, Real half = 0.5) {
    BodyDesc d;
    d.shape = Shape::box(Vec3(half, half, half));
    d.position = p;
    return d;
}

using test::error_of;
using test::run;
using test::weightless;

Quat about_z(Real angle) { return Quat(Eigen::AngleAxis<Real>(angle, Vec3::UnitZ())); }
Quat about_y(Real angle) { return Quat(Eigen::AngleAxis<Real>(angle, Vec3::UnitY())); }

}  // namespace

// ---- material ----

// A 20 degree ramp (tan 20 = 0.36): friction 1 holds the box; friction 0.05 on the box
// mixes to sqrt(0.05 * 1) = 0.22 with the ramp, too little. The contact already exists, so
// this also checks that existing contacts take the new value.
TEST(Setters, FrictionLoweredOnARamp_RestingBoxStartsSliding) {
    Space space;
    const Real slope = 20 * std::numbers::pi / 180;
    test::add_static_box(space, Vec3(10, 0.5, 4), Vec3::Zero(), about_z(slope), 1);
    BodyDesc d = box(Vec3::Zero());
    d.orientation = about_z(slope);
    d.position = about_z(slope) * Vec3(0, 1.0, 0);
    d.friction = 1;
    const BodyHandle b = space.create_body(d);
    run(space, 180);
    const Vec3 held = space.internal_position(b);
    run(space, 60);
    ASSERT_LT((space.internal_position(b) - held).norm(), 0.01) << "friction 1 must hold the box";

    space.set_friction(b, 0.05);
    EXPECT_EQ(space.internal_desc(b).friction, 1) << "buffered: nothing changes before the update";
    run(space, 60);
    EXPECT_EQ(space.internal_desc(b).friction, 0.05);
    EXPECT_GT((space.internal_position(b) - held).norm(), 0.5) << "friction 0.05 must let the box slide";
}

// The ball is in contact (speculatively) before it is made bouncy: the existing contact
// must take the new restitution.
TEST(Setters, RestitutionRaised_BallInContactBounces) {
    Space space;
    add_ground(space);
    const BodyHandle b = space.create_body(ball(Vec3(0, 0.52, 0)));
    run(space, 2);
    space.set_restitution(b, 0.9);
    space.set_linear_velocity(b, Vec3(0, -5, 0));
    Real highest_speed_up = 0;
    for (int i = 0; i < 20; ++i) {
        space.update();
        highest_speed_up = std::max(highest_speed_up, space.internal_linear_velocity(b).y());
    }
    EXPECT_GT(highest_speed_up, 3.5);
    EXPECT_EQ(space.internal_desc(b).restitution, 0.9);
}

TEST(Setters, RestitutionLeftAtZero_BallInContactDoesNotBounce) {
    Space space;
    add_ground(space);
    const BodyHandle b = space.create_body(ball(Vec3(0, 0.52, 0)));
    run(space, 2);
    space.set_linear_velocity(b, Vec3(0, -5, 0));
    Real highest_speed_up = 0;
    for (int i = 0; i < 20; ++i) {
        space.update();
        highest_speed_up = std::max(highest_speed_up, space.internal_linear_velocity(b).y());
    }
    EXPECT_LT(highest_speed_up, 1.0);
}

// ---- gravity scale, damping ----

TEST(Setters, GravityScaleZero_BodyFloats) {
    Space space;
    const BodyHandle floating = space.create_body(ball(Vec3(0, 5, 0)));
    const BodyHandle falling = space.create_body(ball(Vec3(3, 5, 0)));
    space.set_gravity_scale(floating, 0);
    run(space, 60);
    EXPECT_DOUBLE_EQ(space.internal_position(floating).y(), 5);
    EXPECT_LT(space.internal_position(falling).y(), 1);
    EXPECT_EQ(space.internal_desc(floating).gravity_scale, 0);
}

TEST(Setters, Damping_SlowsAMovingBody) {
    Space space(weightless());
    BodyDesc d = ball(Vec3::Zero());
    d.linear_velocity = Vec3(10, 0, 0);
    d.angular_velocity = Vec3(0, 10, 0);
    const BodyHandle damped = space.create_body(d);
    d.position = Vec3(0, 5, 0);
    const BodyHandle free = space.create_body(d);
    space.set_damping(damped, 2, 3);
    run(space, 60);
    EXPECT_LT(space.internal_linear_velocity(damped).x(), 2);   // 10 / (1 + 2/60)^60 = 1.4
    EXPECT_LT(space.internal_angular_velocity(damped).y(), 1);  // 10 / (1 + 3/60)^60 = 0.5
    EXPECT_GT(space.internal_linear_velocity(damped).x(), 0.5);
    EXPECT_DOUBLE_EQ(space.internal_linear_velocity(free).x(), 10);
    EXPECT_EQ(space.internal_desc(damped).linear_damping, 2);
    EXPECT_EQ(space.internal_desc(damped).angular_damping, 3);
}

// ---- user data ----

TEST(Setters, UserData_ReadFromAnotherThreadAfterTheNextUpdate) {
    Space space;
    BodyDesc d = ball(Vec3::Zero());
    d.type = MotionType::Static;  // not awake: published only because the write changed it
    d.user_data = 7;
    const BodyHandle b = space.create_body(d);
    EXPECT_EQ(space.user_data(b), 7u);
    run(space, 2);  // both published buffers hold the body: only the write can republish it
    std::thread writer([&] { space.set_user_data(b, 0xfeedbeefcafeULL); });
    writer.join();
    std::uint64_t before = 0, after = 0;
    std::thread([&] { before = space.user_data(b); }).join();
    space.update();
    std::thread([&] { after = space.user_data(b); }).join();
    EXPECT_EQ(before, 7u) << "visible only after the next update";
    EXPECT_EQ(after, 0xfeedbeefcafeULL);
    EXPECT_EQ(space.internal_desc(b).user_data, 0xfeedbeefcafeULL);
    space.update();  // the other published buffer has it too
    EXPECT_EQ(space.user_data(b), 0xfeedbeefcafeULL);
}

TEST(Setters, UserData_DoesNotWakeASleepingBody) {
    Space space;
    add_ground(space);
    const BodyHandle b = space.create_body(box(Vec3(0, 0.5, 0)));
    run(space, 120);
    ASSERT_FALSE(space.internal_is_awake(b));
    space.set_user_data(b, 3);
    space.update();
    EXPECT_FALSE(space.internal_is_awake(b));
    EXPECT_EQ(space.user_data(b), 3u);
    space.set_gravity_scale(b, 1);  // any other write does wake it
    space.update();
    EXPECT_TRUE(space.internal_is_awake(b));
}

// ---- forces and impulses at points ----

// A unit box (mass 1000, inertia 1000/6 about each axis) away from the origin, so that
// the torque must be taken about its centre of mass, not the world origin.
TEST(Setters, ImpulseAtAPoint_SpinsTheBodyAsRCrossJ) {
    Space space(weightless());
    const Vec3 centre(5, 3, -2);
    const BodyHandle b = space.create_body(box(centre));
    const Vec3 r(0, 0.5, 0), j(0, 0, 10);  // r x j = (5, 0, 0)
    space.apply_impulse_at(b, j, centre + r);
    space.flush();
    const Real mass = 1000, inertia = mass / 6;
    EXPECT_NEAR(space.internal_linear_velocity(b).z(), 10 / mass, 1e-12);
    const Vec3 w = space.internal_angular_velocity(b);
    EXPECT_NEAR(w.x(), 5 / inertia, 1e-12);
    EXPECT_NEAR(w.y(), 0, 1e-12);
    EXPECT_NEAR(w.z(), 0, 1e-12);
}

TEST(Setters, ForceAtAPoint_SpinsTheBodyTheRightWay) {
    Space space(weightless());
    const Vec3 centre(-4, 2, 1);
    const BodyHandle b = space.create_body(box(centre));
    // r = +x, F = +y: r x F = +z, so the body turns counter-clockwise about z.
    space.add_force_at(b, Vec3(0, 600, 0), centre + Vec3(0.5, 0, 0));
    space.add_force_at(b, Vec3(0, 600, 0), centre + Vec3(0.5, 0, 0));  // accumulated: 1200 N, 600 N m
    space.update();
    const Real h = 1.0 / 60, inertia = 1000.0 / 6;
    EXPECT_NEAR(space.internal_linear_velocity(b).y(), 1200 * h / 1000, 1e-9);
    EXPECT_NEAR(space.internal_angular_velocity(b).z(), 600 * h / inertia, 1e-9);
    EXPECT_NEAR(space.internal_angular_velocity(b).x(), 0, 1e-12);
    space.update();  // for one step only
    EXPECT_NEAR(space.internal_angular_velocity(b).z(), 600 * h / inertia, 1e-9);
}

// ---- kinematic moves ----

TEST(Setters, MoveKinematic_ReachesTheTargetExactlyInOneStepThenRests) {
    Space space;
    BodyDesc d = box(Vec3(1, 2, 3));
    d.type = MotionType::Kinematic;
    const BodyHandle k = space.create_body(d);
    const Vec3 target(1.7, 2.2, 2.6);
    const Quat turn = about_y(0.4) * about_z(0.3);
    space.move_kinematic(k, target, turn);
    space.update();
    EXPECT_EQ(space.internal_position(k), target);
    EXPECT_TRUE(space.internal_orientation(k).isApprox(turn, 1e-15));
    EXPECT_EQ(space.internal_linear_velocity(k), Vec3::Zero());
    space.update();
    EXPECT_EQ(space.internal_position(k), target) << "at rest after the move";
}

TEST(Setters, MoveKinematic_KeptUntilAStepTakesIt) {
    SpaceSettings s;
    s.time_step.use_internal_time_stepping = true;
    Space space(s);
    BodyDesc d = box(Vec3::Zero());
    d.type = MotionType::Kinematic;
    const BodyHandle k = space.create_body(d);
    space.move_kinematic(k, Vec3(0, 1, 0), Quat::Identity());
    space.update(0.001);  // no step
    EXPECT_EQ(space.internal_position(k), Vec3::Zero());
    space.update(1.0 / 60);
    EXPECT_EQ(space.internal_position(k), Vec3(0, 1, 0));
}

// Moved 0.1 m a step (6 m/s) into a box: the box is pushed at the kinematic body's
// speed, which a pose set without velocity (push-out only) would not give it.
TEST(Setters, MoveKinematic_PushesADynamicBox) {
    Space space(weightless());
    BodyDesc d = box(Vec3::Zero());
    d.type = MotionType::Kinematic;
    const BodyHandle k = space.create_body(d);
    const BodyHandle pushed = space.create_body(box(Vec3(1.05, 0, 0)));
    Real x = 0;
    for (int i = 0; i < 10; ++i) {
        x += 0.1;
        space.move_kinematic(k, Vec3(x, 0, 0), Quat::Identity());
        space.update();
    }
    EXPECT_DOUBLE_EQ(space.internal_position(k).x(), x);
    EXPECT_GT(space.internal_linear_velocity(pushed).x(), 5);
    EXPECT_GT(space.internal_position(pushed).x(), x + 0.95);
}

TEST(Setters, MoveKinematic_OfADynamicBodyThrows) {
    Space space;
    const BodyHandle b = space.create_body(ball(Vec3::Zero()));
    const std::string e = error_of([&] { space.move_kinematic(b, Vec3(1, 0, 0), Quat::Identity()); });
    EXPECT_NE(e.find("move_kinematic: body 0 (generation 1) is Dynamic, not Kinematic"), std::string::npos) << e;
}

// ---- shape ----

// Mass measured by an impulse: dv = J / m. A sphere of radius 0.5 (523.6 kg) becomes a box
// of half extent 1 (8000 kg); it then rests on the floor at its new half height.
TEST(Setters, SetShape_RebuildsTheMassAndRestsAtTheNewHeight) {
    Space space;
    add_ground(space);
    const BodyHandle b = space.create_body(ball(Vec3(0, 0.5, 0)));
    run(space, 30);
    ASSERT_NEAR(space.internal_position(b).y(), 0.5, 0.02);
    space.set_shape(b, Shape::box(Vec3(1, 1, 1)));
    space.apply_impulse(b, Vec3(800, 0, 0));  // after the shape: the new mass takes it
    space.flush();                            // applied, no step (no friction yet)
    EXPECT_EQ(space.internal_desc(b).shape.type, ShapeType::Box);
    EXPECT_NEAR(space.internal_linear_velocity(b).x(), 0.1, 1e-9);  // 800 / 8000
    run(space, 120);
    EXPECT_NEAR(space.internal_position(b).y(), 1.0, 0.02);
}

TEST(Setters, SetShapeKeepingMass_KeepsTheMass) {
    Space space(weightless());
    const BodyHandle b = space.create_body(ball(Vec3::Zero()));
    space.set_shape(b, Shape::box(Vec3(1, 1, 1)), true);
    space.apply_impulse(b, Vec3(523.598775598, 0, 0));  // the sphere's mass
    space.flush();
    EXPECT_NEAR(space.internal_linear_velocity(b).x(), 1, 1e-6);
}

// A hull whose centre of mass is off its origin: the joint's anchor must stay on the same
// point of the body (joint frames are kept from the centre of mass, which moved).
TEST(Setters, SetShapeMovingTheCentreOfMass_KeepsJointAnchorsInPlace) {
    Space space(weightless());
    BodyDesc anchor_desc = box(Vec3(0, 0, 0));
    anchor_desc.type = MotionType::Static;
    const BodyHandle anchor = space.create_body(anchor_desc);
    const BodyHandle b = space.create_body(ball(Vec3(2, 0, 0)));
    const JointHandle joint = space.create_joint(JointDesc::ball_socket_at(anchor, b, Vec3(1.5, 0, 0)));
    const Vec3 corners[] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                            Vec3(1, 1, 0), Vec3(1, 0, 1), Vec3(0, 1, 1), Vec3(1, 1, 1)};
    space.set_shape(b, Shape::convex_hull(corners));  // centre of mass at (0.5, 0.5, 0.5)
    space.flush();
    EXPECT_NEAR(space.internal_joint_error(joint).linear, 0, 1e-12);
    EXPECT_TRUE(space.internal_motion_state(b).center_of_mass.isApprox(Vec3(2.5, 0.5, 0.5), 1e-12));
    EXPECT_EQ(space.internal_position(b), Vec3(2, 0, 0)) << "the origin stays where it was";
}

// The floor's new shape no longer reaches under a sleeping box: no new contact wakes it,
// so the change itself must, or the box hangs in the air.
TEST(Setters, FloorShrunkFromUnderASleepingBox_TheBoxFalls) {
    Space space;
    const BodyHandle ground = add_ground(space);
    const BodyHandle b = space.create_body(box(Vec3(5, 0.5, 0)));
    run(space, 120);
    ASSERT_FALSE(space.internal_is_awake(b));
    space.set_shape(ground, Shape::box(Vec3(2, 0.5, 2)));
    run(space, 60);
    EXPECT_LT(space.internal_position(b).y(), -1);
}

// ---- motion type ----

TEST(Setters, StaticBoxMadeDynamic_Falls) {
    Space space;
    BodyDesc d = box(Vec3(0, 5, 0));
    d.type = MotionType::Static;
    const BodyHandle b = space.create_body(d);
    run(space, 30);
    EXPECT_EQ(space.internal_position(b).y(), 5);
    space.set_motion_type(b, MotionType::Dynamic);
    space.apply_impulse(b, Vec3(500, 0, 0));  // after the type: its new mass, 1000 kg, takes it
    space.flush();
    EXPECT_NEAR(space.internal_linear_velocity(b).x(), 0.5, 1e-12);
    run(space, 60);
    EXPECT_LT(space.internal_position(b).y(), 1);
    EXPECT_EQ(space.internal_desc(b).type, MotionType::Dynamic);
}

// The space keeps a description without the pose and velocities (BodyTraits, world.hpp):
// every other field comes back as made, and those as the body is now.
TEST(Setters, InternalDescKeepsEveryFieldItWasMadeWith) {
    Space space(weightless());
    BodyDesc d = box(Vec3(1, 2, 3));
    d.shape = Shape::box(Vec3(0.5, 1, 1.5));
    d.orientation = Quat(Eigen::AngleAxis<Real>(0.5, Vec3(0, 1, 0)));
    d.linear_velocity = Vec3(1, 0, 0);
    d.angular_velocity = Vec3(0, 1, 0);
    d.density = 500;
    d.mass = 7;
    d.friction = 0.3;
    d.restitution = 0.2;
    d.rolling_resistance = 0.05;
    d.gravity_scale = 0.5;
    d.linear_damping = 0.1;
    d.angular_damping = 0.2;
    d.gyroscopic = true;
    d.locks.translation_z = true;
    d.allow_interpolation = false;
    d.allow_sleep = false;
    d.fast = true;
    d.layer = 3;
    d.group = 9;
    d.contact_events = true;
    d.sensor = true;
    d.user_data = 42;
    const BodyHandle b = space.create_body(d);
    const BodyDesc kept = space.internal_desc(b);
    EXPECT_EQ(kept.type, d.type);
    EXPECT_EQ(kept.shape.type, ShapeType::Box);
    EXPECT_EQ(kept.shape.half_extents, d.shape.half_extents);
    EXPECT_TRUE(kept.position.isApprox(d.position, 1e-12));
    EXPECT_TRUE(kept.orientation.isApprox(d.orientation, 1e-12));
    EXPECT_EQ(kept.linear_velocity, d.linear_velocity);
    EXPECT_EQ(kept.angular_velocity, d.angular_velocity);
    EXPECT_EQ(kept.density, d.density);
    EXPECT_EQ(kept.mass, d.mass);
    EXPECT_EQ(kept.friction, d.friction);
    EXPECT_EQ(kept.restitution, d.restitution);
    EXPECT_EQ(kept.rolling_resistance, d.rolling_resistance);
    EXPECT_EQ(kept.gravity_scale, d.gravity_scale);
    EXPECT_EQ(kept.linear_damping, d.linear_damping);
    EXPECT_EQ(kept.angular_damping, d.angular_damping);
    EXPECT_EQ(kept.gyroscopic, d.gyroscopic);
    EXPECT_EQ(kept.locks, d.locks);
    EXPECT_EQ(kept.allow_interpolation, d.allow_interpolation);
    EXPECT_EQ(kept.allow_sleep, d.allow_sleep);
    EXPECT_EQ(kept.fast, d.fast);
    EXPECT_EQ(kept.layer, d.layer);
    EXPECT_EQ(kept.group, d.group);
    EXPECT_EQ(kept.contact_events, d.contact_events);
    EXPECT_EQ(kept.sensor, d.sensor);
    EXPECT_EQ(kept.user_data, d.user_data);
    // The pose and velocities as they are now, not as made.
    space.update();
    EXPECT_EQ(space.internal_desc(b).position, space.internal_position(b));
}

// A static body keeps no interpolation history (world.hpp); made dynamic it gets one at
// its pose, not the pose the body that last held its slot left there.
TEST(Setters, StaticBoxMadeDynamicInAReusedSlot_BlendsFromWhereItStands) {
    SpaceSettings settings = weightless();
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    const Real step = settings.time_step.duration;
    const BodyHandle gone = space.create_body(box(Vec3(100, 0, 0)));
    space.update(step);
    space.destroy_body(gone);
    BodyDesc d = box(Vec3(0, 5, 0));
    d.type = MotionType::Static;
    const BodyHandle b = space.create_body(d);
    ASSERT_EQ(b.index, gone.index) << "the slot is reused";
    space.set_motion_type(b, MotionType::Dynamic);
    space.update(1.5 * step);  // one step and half a step banked: reads blend the last two
    ASSERT_GT(space.motion_states().alpha(), 0.4);
    ASSERT_LT(space.motion_states().alpha(), 0.6);
    EXPECT_LT((space.motion_state(b).position - Vec3(0, 5, 0)).norm(), 1e-9);
}

// A sleeping box made static must leave its sleeping island: waking the island later (the
// box on it is pushed) must not put the static body in the awake list.
TEST(Setters, SleepingBoxMadeStatic_NeverJoinsTheAwakeList) {
    Space space;
    add_ground(space);
    const BodyHandle bottom = space.create_body(box(Vec3(0, 0.5, 0)));
    const BodyHandle top = space.create_body(box(Vec3(0, 1.5, 0)));
    run(space, 180);
    ASSERT_FALSE(space.internal_is_awake(bottom));
    space.set_motion_type(bottom, MotionType::Static);
    const Vec3 held = space.internal_position(bottom);
    space.apply_impulse(top, Vec3(0, 2000, 0));
    for (int i = 0; i < 60; ++i) {
        space.update();
        ASSERT_FALSE(space.internal_is_awake(bottom)) << "step " << i;
    }
    EXPECT_EQ(space.internal_position(bottom), held);
    run(space, 120);
    EXPECT_NEAR(space.internal_position(top).y(), held.y() + 1, 0.02);
}

// With interpolation, a body made static reads where it is, not a blend with the step before.
TEST(Setters, BodyMadeStaticWhileFalling_InterpolatedReadIsItsPose) {
    SpaceSettings s;
    s.time_step.use_internal_time_stepping = true;
    Space space(s);
    const BodyHandle b = space.create_body(box(Vec3(0, 5, 0)));
    for (int i = 0; i < 10; ++i) space.update(1.0 / 60);
    space.set_motion_type(b, MotionType::Static);
    space.update(1.5 / 60);  // one step and half a step left over: alpha 0.5
    EXPECT_EQ(space.position(b), space.internal_position(b));
}

TEST(Setters, DynamicBoxMadeStatic_StopsMidairAndHoldsABoxDroppedOnIt) {
    Space space;
    const BodyHandle b = space.create_body(box(Vec3(0, 5, 0)));
    run(space, 10);
    space.set_motion_type(b, MotionType::Static);
    space.update();
    const Vec3 held = space.internal_position(b);
    EXPECT_EQ(space.internal_linear_velocity(b), Vec3::Zero());
    EXPECT_FALSE(space.internal_is_awake(b));
    const BodyHandle dropped = space.create_body(box(held + Vec3(0, 2, 0)));
    run(space, 120);
    EXPECT_EQ(space.internal_position(b), held);
    EXPECT_NEAR(space.internal_position(dropped).y(), held.y() + 1, 0.02);
}

TEST(Setters, SleepingStack_WakesAndFallsWhenItsFloorIsMadeDynamic) {
    Space space;
    const BodyHandle f = test::add_static_box(space, Vec3(3, 0.5, 3), Vec3(0, -0.5, 0));
    BodyHandle stack[3];
    for (int i = 0; i < 3; ++i) stack[i] = space.create_body(box(Vec3(0, 0.5 + i, 0)));
    run(space, 240);
    for (BodyHandle s : stack) ASSERT_FALSE(space.internal_is_awake(s)) << "the stack must sleep first";
    space.set_motion_type(f, MotionType::Dynamic);
    space.update();
    for (BodyHandle s : stack) EXPECT_TRUE(space.internal_is_awake(s));
    run(space, 60);
    EXPECT_LT(space.internal_position(f).y(), -2);
    EXPECT_LT(space.internal_position(stack[2]).y(), 0);
}

TEST(Setters, DynamicBodyMadeKinematic_KeepsItsVelocityAndIgnoresGravity) {
    Space space;
    BodyDesc d = box(Vec3(0, 5, 0));
    d.linear_velocity = Vec3(2, 0, 0);
    const BodyHandle b = space.create_body(d);
    space.set_motion_type(b, MotionType::Kinematic);
    run(space, 60);
    EXPECT_NEAR(space.internal_position(b).x(), 2, 1e-9);
    EXPECT_NEAR(space.internal_position(b).y(), 5, 1e-9);
}

// A box resting on the ground made kinematic: kinematic and static make no contact.
TEST(Setters, RestingBoxMadeKinematic_LosesItsContactWithTheGround) {
    Space space;
    add_ground(space);
    const BodyHandle b = space.create_body(box(Vec3(0, 0.5, 0)));
    run(space, 10);
    ASSERT_EQ(space.last_update().contacts, 1u);
    space.set_motion_type(b, MotionType::Kinematic);
    run(space, 2);
    EXPECT_EQ(space.last_update().contacts, 0u);
    space.set_motion_type(b, MotionType::Dynamic);  // and back: found again
    run(space, 2);
    EXPECT_EQ(space.last_update().contacts, 1u);
}

// A body flagged fast that was static is swept once dynamic (World::fast_bodies counts
// it): a bar spinning at 60 rad/s stops at a 4 cm wall (tests/engine/continuous).
TEST(Setters, FastStaticBarMadeDynamic_IsSweptAndStopsAtAThinWall) {
    Space space(weightless());
    test::add_static_box(space, Vec3(0.02, 5, 5), Vec3(0.5, 0, 0));
    BodyDesc bar = test::static_box(Vec3(2, 0.05, 0.05), Vec3(-1, 0, 0), about_z(2.0));
    bar.fast = true;
    const BodyHandle b = space.create_body(bar);
    space.set_motion_type(b, MotionType::Dynamic);
    space.set_angular_velocity(b, Vec3(0, 0, -60));
    Real max_tip_x = -1e9;
    for (int i = 0; i < 30; ++i) {
        space.update();
        const MotionState s = space.internal_motion_state(b);
        for (Real end : {2.0, -2.0})
            max_tip_x = std::max(max_tip_x, (s.position + s.orientation * Vec3(end, 0, 0)).x());
    }
    EXPECT_LT(max_tip_x, 0.48 + 0.01);
    EXPECT_GT(space.counters().swept_tests, 0u);
}

// ---- the buffer's rules ----

TEST(Setters, LastWriteWins_WhenTwoValuesAreWrittenBeforeAnUpdate) {
    Space space;
    const BodyHandle b = space.create_body(ball(Vec3(0, 5, 0)));
    space.set_friction(b, 0.1);
    space.set_friction(b, 0.3);
    space.set_restitution(b, 0.2);
    space.set_restitution(b, 0.4);
    space.set_gravity_scale(b, 2);
    space.set_gravity_scale(b, 0);
    space.set_damping(b, 1, 1);
    space.set_damping(b, 0.5, 0.25);
    space.set_user_data(b, 1);
    space.set_user_data(b, 2);
    space.set_motion_type(b, MotionType::Static);
    space.set_motion_type(b, MotionType::Kinematic);
    space.update();
    const BodyDesc d = space.internal_desc(b);
    EXPECT_EQ(d.friction, 0.3);
    EXPECT_EQ(d.restitution, 0.4);
    EXPECT_EQ(d.gravity_scale, 0);
    EXPECT_EQ(d.linear_damping, 0.5);
    EXPECT_EQ(d.angular_damping, 0.25);
    EXPECT_EQ(d.type, MotionType::Kinematic);
    EXPECT_EQ(space.user_data(b), 2u);
}

TEST(Setters, BadValuesAndStaleHandles_ThrowNamingThemAndChangeNothing) {
    Space space;
    const BodyHandle b = space.create_body(ball(Vec3(0, 5, 0)));
    const BodyHandle gone = space.create_body(ball(Vec3(3, 5, 0)));
    space.destroy_body(gone);
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    const Real inf = std::numeric_limits<Real>::infinity();
    struct Case {
        std::string expected;
        std::function<void()> call;
    };
    Shape bad_sphere = Shape::sphere(1);  // fields are public: a hand-built shape may hold anything
    bad_sphere.radius = -1;
    const Case cases[] = {
        {"set_friction: friction must be finite and >= 0, got nan", [&] { space.set_friction(b, nan); }},
        {"set_friction: friction must be finite and >= 0, got -1", [&] { space.set_friction(b, -1); }},
        {"set_restitution: restitution must be finite and >= 0, got -0.5", [&] { space.set_restitution(b, -0.5); }},
        {"set_rolling_resistance: rolling_resistance must be finite and >= 0, got -0.05",
         [&] { space.set_rolling_resistance(b, -0.05); }},
        {"set_rolling_resistance: rolling_resistance must be finite and >= 0, got inf",
         [&] { space.set_rolling_resistance(b, inf); }},
        {"set_gravity_scale: gravity_scale must be finite, got inf", [&] { space.set_gravity_scale(b, inf); }},
        {"set_damping: linear_damping must be finite and >= 0, got -1", [&] { space.set_damping(b, -1, 0); }},
        {"set_damping: angular_damping must be finite and >= 0, got nan", [&] { space.set_damping(b, 0, nan); }},
        {"set_motion_type: type must be Static, Kinematic or Dynamic, got 7",
         [&] { space.set_motion_type(b, static_cast<MotionType>(7)); }},
        {"set_shape: shape.radius must be finite and > 0, got -1", [&] { space.set_shape(b, bad_sphere); }},
        {"set_shape: a plane shape can only belong to a static body",
         [&] { space.set_shape(b, Shape::plane(Vec3::UnitY(), 0)); }},
        {"add_force_at: point must be finite", [&] { space.add_force_at(b, Vec3(1, 0, 0), Vec3(nan, 0, 0)); }},
        {"apply_impulse_at: impulse must be finite", [&] { space.apply_impulse_at(b, Vec3(inf, 0, 0), Vec3::Zero()); }},
        {"move_kinematic: body 0 (generation 1) is Dynamic, not Kinematic",
         [&] { space.move_kinematic(b, Vec3(1, 0, 0), Quat::Identity()); }},
        {"set_friction: body 1 (generation 1) is not a live body", [&] { space.set_friction(gone, 0.5); }},
        {"set_restitution: body 1 (generation 1) is not a live body", [&] { space.set_restitution(gone, 0.5); }},
        {"set_rolling_resistance: body 1 (generation 1) is not a live body",
         [&] { space.set_rolling_resistance(gone, 0.5); }},
        {"set_gravity_scale: body 1 (generation 1) is not a live body", [&] { space.set_gravity_scale(gone, 1); }},
        {"set_damping: body 1 (generation 1) is not a live body", [&] { space.set_damping(gone, 1, 1); }},
        {"set_motion_type: body 1 (generation 1) is not a live body",
         [&] { space.set_motion_type(gone, MotionType::Static); }},
        {"set_shape: body 1 (generation 1) is not a live body", [&] { space.set_shape(gone, Shape::sphere(1)); }},
        {"set_user_data: body 1 (generation 1) is not a live body", [&] { space.set_user_data(gone, 1); }},
        {"add_force_at: body 1 (generation 1) is not a live body",
         [&] { space.add_force_at(gone, Vec3::Zero(), Vec3::Zero()); }},
        {"apply_impulse_at: body 1 (generation 1) is not a live body",
         [&] { space.apply_impulse_at(gone, Vec3::Zero(), Vec3::Zero()); }},
        {"move_kinematic: body 1 (generation 1) is not a live body",
         [&] { space.move_kinematic(gone, Vec3::Zero(), Quat::Identity()); }},
        {"body 1 (generation 1)", [&] { (void)space.user_data(gone); }},
    };
    BodyDesc kd = box(Vec3(6, 1, 0));
    kd.type = MotionType::Kinematic;
    const BodyHandle k = space.create_body(kd);
    const std::string target = error_of([&] { space.move_kinematic(k, Vec3(0, nan, 0), Quat::Identity()); });
    EXPECT_NE(target.find("move_kinematic: position must be finite"), std::string::npos) << target;
    const std::string turn = error_of([&] { space.move_kinematic(k, Vec3::Zero(), Quat(0, 0, 0, 0)); });
    EXPECT_NE(turn.find("move_kinematic: orientation must be a finite, non-zero quaternion"), std::string::npos)
        << turn;
    for (const Case& c : cases) {
        const std::string e = error_of(c.call);
        EXPECT_NE(e.find(c.expected), std::string::npos) << "expected \"" << c.expected << "\", got \"" << e << "\"";
    }
    const BodyDesc before = space.internal_desc(b);
    space.update();
    EXPECT_EQ(space.last_update().writes_applied, 0);
    const BodyDesc after = space.internal_desc(b);
    EXPECT_EQ(after.friction, before.friction);
    EXPECT_EQ(after.type, MotionType::Dynamic);
    EXPECT_EQ(after.shape.type, ShapeType::Sphere);
    EXPECT_EQ(space.internal_angular_velocity(b), Vec3::Zero());
    EXPECT_EQ(space.internal_position(k), Vec3(6, 1, 0));
}

TEST(Setters, PlaneBodyMadeDynamic_Throws) {
    Space space;
    const BodyHandle p = test::add_ground_plane(space);
    const std::string e = error_of([&] { space.set_motion_type(p, MotionType::Dynamic); });
    EXPECT_NE(e.find("set_motion_type: body 0 (generation 1) has a plane or triangle mesh shape"), std::string::npos)
        << e;
}

// Every setter from four threads while the update thread steps: nothing lost or torn,
// and the last values written are the ones live after the final flush.
TEST(Setters, WritesFromManyThreadsWhileUpdating_AllApply) {
    Space space;
    add_ground(space);
    BodyHandle bodies[4];
    for (int i = 0; i < 4; ++i) bodies[i] = space.create_body(ball(Vec3(2.0 * i, 1, 0)));
    std::atomic<bool> go{true};
    std::thread writers[4];
    for (int t = 0; t < 4; ++t) {
        writers[t] = std::thread([&, t] {
            const BodyHandle b = bodies[t];
            for (int n = 0; n < 2000; ++n) {
                space.set_friction(b, 0.1 * (n % 7));
                space.set_restitution(b, 0.05 * (n % 5));
                space.set_gravity_scale(b, 1);
                space.set_damping(b, 0.1, 0.1);
                space.set_user_data(b, static_cast<std::uint64_t>(n));
                space.add_force_at(b, Vec3(0, 1, 0), Vec3(2.0 * t + 0.5, 1, 0));
                (void)space.user_data(b);
            }
            space.set_friction(b, 0.25 * (t + 1));
            space.set_user_data(b, 100u + static_cast<std::uint64_t>(t));
        });
    }
    for (int i = 0; i < 200; ++i) space.update();
    for (std::thread& w : writers) w.join();
    space.flush();
    for (int t = 0; t < 4; ++t) {
        EXPECT_EQ(space.internal_desc(bodies[t]).friction, 0.25 * (t + 1));
        EXPECT_EQ(space.user_data(bodies[t]), 100u + static_cast<std::uint64_t>(t));
    }
}

}  // namespace setters_test
