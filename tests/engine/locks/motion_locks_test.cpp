// Motion locks (BodyDesc::locks): a locked body never moves along, or turns about, a
// locked world axis, to the last bit, whatever pushes it; contacts and joints see it
// infinitely heavy there and correctly heavy everywhere else.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "static_bodies.hpp"

using namespace spindle;

namespace motion_locks_test {

namespace {

SpaceSettings awake() {
    SpaceSettings s;
    s.sleep.enabled = false;
    return s;
}

void add_ground(Space& space) { test::add_ground_plane(space); }

// The rotation of q0 to q, as a rotation vector (world).
Vec3 turned(const Quat& q0, const Quat& q) {
    const Eigen::AngleAxis<Real> aa(q * q0.conjugate());
    return aa.angle() * aa.axis();
}

}  // namespace

// A 2D pyramid of 15 unit cubes in the plane z = 0.3, locked to it, is kicked out of
// the plane (impulses and angular impulses with every component) and hit side-on by a
// free ball rolling along -z: every cube keeps its z and turns about z only, to 1e-9,
// and the pyramid still stands after 600 steps.
TEST(MotionLocks, Pyramid2D_StaysInItsPlaneAndStands) {
    Space space(awake());
    add_ground(space);
    constexpr Real kZ = 0.3;
    const int rows = 5;
    std::vector<BodyHandle> cubes;
    std::vector<Vec3> start;
    for (int row = 0; row < rows; ++row) {
        for (int k = 0; k < rows - row; ++k) {
            BodyDesc d;
            d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
            d.position = Vec3(k - 0.5 * (rows - row - 1), 0.5 + row, kZ);
            d.locks = MotionLocks::plane_xy();
            d.linear_velocity = Vec3(0, 0, 3);  // lost at creation
            d.angular_velocity = Vec3(1, -2, 0);
            cubes.push_back(space.create_body(d));
            start.push_back(d.position);
        }
    }
    BodyDesc ball;
    ball.shape = Shape::sphere(0.4);
    ball.density = 200;
    ball.position = Vec3(1.3, 0.4, 6);
    ball.linear_velocity = Vec3(0, 0, -4);
    space.create_body(ball);

    Real worst_z = 0, worst_turn = 0, worst_spin = 0;
    for (int step = 0; step < 600; ++step) {
        if (step % 50 == 10) {
            const BodyHandle kicked = cubes[static_cast<std::size_t>(step / 50) % cubes.size()];
            space.apply_impulse(kicked, Vec3(40, 30, 500));
            space.apply_angular_impulse(kicked, Vec3(300, -200, 1));
            space.add_force(kicked, Vec3(0, 0, 1e4));
            space.add_torque(kicked, Vec3(1e4, 1e4, 0));
        }
        space.update();
        for (std::size_t i = 0; i < cubes.size(); ++i) {
            const MotionState s = space.internal_motion_state(cubes[i]);
            worst_z = std::max({worst_z, std::abs(s.center_of_mass.z() - kZ), std::abs(s.linear_velocity.z())});
            worst_turn = std::max({worst_turn, std::abs(s.orientation.x()), std::abs(s.orientation.y())});
            worst_spin = std::max({worst_spin, std::abs(s.angular_velocity.x()), std::abs(s.angular_velocity.y())});
        }
    }
    EXPECT_LE(worst_z, 1e-9);
    EXPECT_LE(worst_turn, 1e-9);
    EXPECT_LE(worst_spin, 1e-9);
    // Standing: every cube near where it was built, upright.
    for (std::size_t i = 0; i < cubes.size(); ++i) {
        const MotionState s = space.internal_motion_state(cubes[i]);
        EXPECT_LT((s.position - start[i]).norm(), 0.1) << "cube " << i;
        EXPECT_LT(turned(Quat::Identity(), s.orientation).norm(), 0.05) << "cube " << i;
    }
}

// A cube balanced on an edge, pushed sideways, with all rotation locked: it slides on
// that edge until friction stops it and never turns (a free one topples).
TEST(MotionLocks, AllRotationLocked_CubeOnItsEdgeDoesNotTurn) {
    for (const bool locked : {false, true}) {
        Space space(awake());
        add_ground(space);
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        d.orientation = Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));
        d.position = Vec3(0, std::sqrt(0.5), 0);
        d.linear_velocity = Vec3(1, 0, 0.2);
        if (locked) d.locks = MotionLocks::all_rotation();
        const BodyHandle cube = space.create_body(d);
        Real worst_turn = 0;
        for (int step = 0; step < 300; ++step) {
            space.update();
            const MotionState s = space.internal_motion_state(cube);
            worst_turn = std::max(worst_turn, turned(d.orientation, s.orientation).norm());
            if (locked) {
                EXPECT_EQ(s.angular_velocity, Vec3::Zero());
            }
        }
        const MotionState s = space.internal_motion_state(cube);
        if (locked) {
            EXPECT_LT(worst_turn, 1e-12);  // normalising the orientation is all that touches it
            EXPECT_NEAR(s.center_of_mass.y(), std::sqrt(0.5), 0.01);  // resting on the edge
            EXPECT_LT(s.linear_velocity.norm(), 1e-3);                // stopped by friction
        } else {
            EXPECT_GT(worst_turn, 0.5);  // the free cube topples onto a face
        }
    }
}

// Two equal balls meet head-on along x with restitution 1; the one at rest has x
// locked. It must act as infinitely heavy along x: it stays put and the other bounces
// back at its own speed (free, they would swap speeds). No gravity, friction or spin
// enters and the effective mass is the moving ball's own, so the bounce is exact but for
// the contact keeping its effective mass in single precision (a relative 6e-8): 1e-6.
// The scalar effective mass of two free balls (half the mass) would stop it dead.
TEST(MotionLocks, TranslationLocked_BallIsAWallAlongItsAxis) {
    for (const bool locked : {false, true}) {
        Space space(awake());
        space.set_gravity(Vec3::Zero());
        BodyDesc d;
        d.shape = Shape::sphere(0.5);
        d.restitution = 1;
        d.friction = 0;
        d.position = Vec3(0, 1, 0);
        if (locked) d.locks.translation_x = true;
        const BodyHandle target = space.create_body(d);
        d.locks = MotionLocks{};
        d.position = Vec3(-3, 1, 0);
        d.linear_velocity = Vec3(2, 0, 0);
        const BodyHandle shooter = space.create_body(d);
        for (int step = 0; step < 120; ++step) space.update();
        const MotionState t = space.internal_motion_state(target);
        const MotionState s = space.internal_motion_state(shooter);
        if (locked) {
            EXPECT_EQ(t.center_of_mass, Vec3(0, 1, 0));
            EXPECT_EQ(t.linear_velocity, Vec3::Zero());
            EXPECT_NEAR(s.linear_velocity.x(), -2, 1e-6);
            EXPECT_LT(s.center_of_mass.x(), -1.5);  // it came back
        } else {
            EXPECT_NEAR(t.linear_velocity.x(), 2, 0.05);  // Newton's cradle
            EXPECT_NEAR(s.linear_velocity.x(), 0, 0.05);
        }
    }
}

// A tilted bar free to turn about z alone answers an angular impulse L with L_z / I_zz
// about z (I the world inertia): the bearing that locks x and y takes the rest. The
// free body's inverse inertia, projected, would give (I^-1)_zz L_z instead.
TEST(MotionLocks, RotationLocked_SpinsWithTheInertiaOfItsFreeAxis) {
    Space space(awake());
    space.set_gravity(Vec3::Zero());
    BodyDesc d;
    const Vec3 half(1, 0.2, 0.1);
    d.shape = Shape::box(half);
    d.mass = 3;
    d.orientation = Quat(Eigen::AngleAxis<Real>(0.5, Vec3(1, 1, 0).normalized()));
    d.locks.rotation_x = d.locks.rotation_y = true;
    const BodyHandle bar = space.create_body(d);
    const Vec3 impulse(0.7, -0.4, 0.3);
    space.apply_angular_impulse(bar, impulse);
    space.update();
    const Mat3 local = (d.mass / 3 *
                        Vec3(half.y() * half.y() + half.z() * half.z(), half.x() * half.x() + half.z() * half.z(),
                             half.x() * half.x() + half.y() * half.y()))
                           .asDiagonal();
    const Mat3 r = d.orientation.toRotationMatrix();
    const Mat3 world = r * local * r.transpose();
    ASSERT_GT(std::abs(1 / world(2, 2) - world.inverse()(2, 2)), 0.01 / world(2, 2));  // the axes do couple
    const Vec3 w = space.internal_angular_velocity(bar);
    EXPECT_EQ(w.x(), 0.0);
    EXPECT_EQ(w.y(), 0.0);
    EXPECT_NEAR(w.z(), impulse.z() / world(2, 2), 1e-12 * std::abs(w.z()));
}

// Velocities given at creation, by a buffered or an internal write, and impulses lose
// their locked components; the free ones are kept as given.
TEST(MotionLocks, WrittenVelocities_LoseTheirLockedComponents) {
    Space space(awake());
    space.set_gravity(Vec3::Zero());
    BodyDesc d;
    d.locks.translation_y = true;
    d.locks.rotation_z = true;
    d.linear_velocity = Vec3(1, 2, 3);
    d.angular_velocity = Vec3(4, 5, 6);
    const BodyHandle body = space.create_body(d);
    EXPECT_EQ(space.internal_linear_velocity(body), Vec3(1, 0, 3));
    EXPECT_EQ(space.internal_angular_velocity(body), Vec3(4, 5, 0));
    space.set_linear_velocity(body, Vec3(-1, -2, -3));
    space.set_angular_velocity(body, Vec3(-4, -5, -6));
    space.update();
    EXPECT_EQ(space.internal_linear_velocity(body), Vec3(-1, 0, -3));
    EXPECT_EQ(space.internal_angular_velocity(body).z(), 0.0);
    MotionState s = space.internal_motion_state(body);
    s.linear_velocity = Vec3(0, 7, 0);
    s.angular_velocity = Vec3(0, 0, 7);
    space.set_internal_motion_state(body, s);
    EXPECT_EQ(space.internal_linear_velocity(body), Vec3::Zero());
    EXPECT_EQ(space.internal_angular_velocity(body), Vec3::Zero());
    space.apply_impulse(body, Vec3(0, 1e3, 0));
    space.update();
    EXPECT_EQ(space.internal_linear_velocity(body), Vec3::Zero());
}

// Gravity along a locked axis does nothing: the body floats, exactly where it was.
TEST(MotionLocks, GravityAlongALockedAxis_DoesNothing) {
    Space space(awake());
    BodyDesc d;
    d.position = Vec3(1, 5, -2);
    d.locks.translation_y = true;
    const BodyHandle body = space.create_body(d);
    for (int step = 0; step < 60; ++step) space.update();
    EXPECT_EQ(space.internal_position(body), d.position);
    EXPECT_EQ(space.internal_linear_velocity(body), Vec3::Zero());
}

// A pendulum on a ball-socket, locked to the x-y plane: the point constraint's mass
// matrix is singular along z (nothing can move there), and the joint still holds in
// the plane, finite, with the bob swinging at the right length.
TEST(MotionLocks, PendulumLockedToAPlane_SwingsInIt) {
    Space space(awake());
    BodyDesc anchor;
    anchor.type = MotionType::Static;
    anchor.shape = Shape::sphere(0.1);
    anchor.position = Vec3(0, 5, 0.2);
    const BodyHandle a = space.create_body(anchor);
    BodyDesc bob;
    bob.shape = Shape::box(Vec3(0.2, 0.2, 0.2));
    bob.position = Vec3(2, 5, 0.2);
    bob.locks = MotionLocks::plane_xy();
    const BodyHandle b = space.create_body(bob);
    space.create_joint(JointDesc::ball_socket_at(a, b, Vec3(0, 5, 0.2)));
    Real lowest = 5;
    for (int step = 0; step < 240; ++step) {
        if (step == 30) space.apply_impulse(b, Vec3(0, 0, 100));  // nothing to do along z
        space.update();
        const MotionState s = space.internal_motion_state(b);
        ASSERT_TRUE(s.center_of_mass.allFinite()) << "step " << step;
        EXPECT_EQ(s.center_of_mass.z(), 0.2);
        EXPECT_EQ(s.orientation.x(), 0.0);
        EXPECT_EQ(s.orientation.y(), 0.0);
        EXPECT_NEAR((s.center_of_mass - anchor.position).norm(), 2, 0.02) << "step " << step;
        lowest = std::min(lowest, s.center_of_mass.y());
    }
    EXPECT_LT(lowest, 3.1);  // it swung down
}

// Locked bodies in contact, as every contact path the solver has for them: a 2D pyramid
// locked to a plane (translation z locked), a column of cubes locked along x with a heavy
// cube carried by a light one (a support scale), a tilted box and a free ball hitting
// them, under a gravity with a part along each locked axis. The stored hash was the one the solver's lane by lane
// preparing gave (6eee171): preparing the lanes together must keep a locked lane's inverse masses, gravity and friction
// rows to the bit. Stored again when the relax pass took over the next substep's warm start (the same motion up to
// rounding: GoldenHash.WarmStartInTheRelaxPassMovesAsItsOwnPass), and when a recycled manifold's friction centre
// turned with its bodies (h42a), and when the passes swept landing manifolds' rows until they settle.
TEST(MotionLocks, LockedContacts_GiveTheStoredStateHash) {
    SpaceSettings settings = awake();
    settings.gravity = Vec3(0.8, -9.81, 0.6);  // along the locked axes too
    Space space(settings);
    add_ground(space);
    for (int row = 0; row < 4; ++row) {
        for (int k = 0; k < 4 - row; ++k) {
            BodyDesc d;
            d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
            d.position = Vec3(k - 0.5 * (4 - row - 1), 0.5 + row, 0.3);
            d.locks = MotionLocks::plane_xy();
            space.create_body(d);
        }
    }
    for (int k = 0; k < 3; ++k) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.4, 0.4, 0.4));
        d.position = Vec3(4, 0.4 + 0.8 * k, -1);
        d.density = k == 2 ? 50 : 1;  // the heavy top cube
        d.locks.translation_x = true;
        space.create_body(d);
    }
    BodyDesc tilted;
    tilted.shape = Shape::box(Vec3(0.3, 0.2, 0.4));
    tilted.position = Vec3(-3, 1.5, 1);
    tilted.orientation = Quat(Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()));
    space.create_body(tilted);
    BodyDesc knob;  // a locked ball bounces on it along a normal with a part along z
    knob.type = MotionType::Static;
    knob.shape = Shape::sphere(0.5);
    knob.position = Vec3(-6, 0.5, 0);
    space.create_body(knob);
    BodyDesc rider;
    rider.shape = Shape::sphere(0.4);
    rider.position = Vec3(-6, 3, 0.3);
    rider.restitution = 0.6;
    rider.locks = MotionLocks::plane_xy();
    space.create_body(rider);
    BodyDesc ball;
    ball.shape = Shape::sphere(0.4);
    ball.position = Vec3(0.2, 0.4, 4);
    ball.linear_velocity = Vec3(0, 0, -6);
    space.create_body(ball);
    for (int step = 0; step < 90; ++step) space.update();
    EXPECT_EQ(space.state_hash(), 0x7489532a307130abull) << std::hex << space.state_hash();
}

}  // namespace motion_locks_test
