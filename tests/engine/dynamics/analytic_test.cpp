// Analytic cases for integration and the contact solver, at tolerances close to
// those mature engines test with.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <cmath>

#include "static_bodies.hpp"

using namespace spindle;

namespace analytic_test {

namespace {

constexpr double kG = 9.81;

BodyDesc sphere_at(const Vec3& p, double radius = 0.5) {
    BodyDesc d;
    d.shape = Shape::sphere(radius);
    d.position = p;
    return d;
}

BodyHandle add_ground(Space& space) { return test::add_ground_plane(space); }

}  // namespace

TEST(Integration, FreeFallMatchesSymplecticEulerExactly) {
    Space space;
    const BodyHandle body = space.create_body(sphere_at(Vec3(0, 100, 0)));
    const int substeps = space.settings().solver.substeps;
    const int steps = 120;  // 2 s at 60 Hz
    for (int i = 0; i < steps; ++i) space.update();
    const double t = steps / 60.0;
    const double h = 1.0 / 60.0 / substeps;
    const int n = steps * substeps;
    EXPECT_NEAR(space.internal_linear_velocity(body).y(), -kG * t, 1e-4);
    // Semi-implicit Euler: y_n = y_0 - g h^2 n (n + 1) / 2.
    EXPECT_NEAR(space.internal_position(body).y(), 100 - kG * h * h * n * (n + 1) / 2.0, 1e-5);
}

TEST(Integration, ConstantForceAddsToGravity) {
    Space space;
    BodyDesc d = sphere_at(Vec3(0, 100, 0));
    d.mass = 2;
    const BodyHandle body = space.create_body(d);
    const Vec3 force(3, 4, -5);
    for (int i = 0; i < 120; ++i) {
        space.add_force(body, force);
        space.update();
    }
    const Vec3 expected = 2.0 * (Vec3(0, -kG, 0) + force / 2.0);
    EXPECT_NEAR((space.internal_linear_velocity(body) - expected).norm(), 0.0, 1e-4);
}

TEST(Integration, TorqueSpinsUpAsTauOverI) {
    Space space;
    space.set_gravity(Vec3::Zero());
    BodyDesc d = sphere_at(Vec3::Zero(), 0.5);
    d.mass = 3;
    const BodyHandle body = space.create_body(d);
    const double inertia = 0.4 * 3 * 0.25;
    for (int i = 0; i < 60; ++i) {
        space.add_torque(body, Vec3(0, 0, 0.2));
        space.update();
    }
    EXPECT_NEAR(space.internal_angular_velocity(body).z(), 1.0 * 0.2 / inertia, 1e-4);
}

TEST(Integration, DampingOnlyWhereAsked) {
    Space space;
    space.set_gravity(Vec3::Zero());
    BodyDesc d = sphere_at(Vec3::Zero());
    d.linear_velocity = Vec3(1, 0, 0);
    const BodyHandle plain = space.create_body(d);
    d.position = Vec3(10, 0, 0);
    d.linear_damping = 0.5;
    const BodyHandle damped = space.create_body(d);
    for (int i = 0; i < 60; ++i) space.update();
    EXPECT_EQ(space.internal_linear_velocity(plain).x(), 1.0);
    EXPECT_LT(space.internal_linear_velocity(damped).x(), 0.7);
    EXPECT_EQ(space.counters().damping_applied, 60u * 4u);  // one body, 4 substeps, 60 steps
}

TEST(Contact, RestingUnitBoxSitsAtOne) {
    Space space;
    add_ground(space);
    BodyDesc d;
    d.shape = Shape::box(Vec3(1, 1, 1));
    d.position = Vec3(0, 1.2, 0);
    const BodyHandle box = space.create_body(d);
    for (int i = 0; i < 90; ++i) space.update();
    EXPECT_NEAR(space.internal_position(box).y(), 1.0, 0.01);
    EXPECT_LT(space.internal_linear_velocity(box).norm(), 0.05);
}

TEST(Contact, ElasticSphereBouncesBackToItsStartHeight) {
    Space space;
    add_ground(space);
    space.set_sleep(SleepSettings{.enabled = false});
    BodyDesc d = sphere_at(Vec3(0, 5, 0), 0.5);
    d.restitution = 1;
    d.friction = 0;
    const BodyHandle ball = space.create_body(d);
    // Track apexes: local maxima of height.
    std::vector<double> apexes;
    double prev_v = 0;
    for (int i = 0; i < 60 * 12 && apexes.size() < 5; ++i) {
        space.update();
        const double v = space.internal_linear_velocity(ball).y();
        if (prev_v > 0 && v <= 0) apexes.push_back(space.internal_position(ball).y());
        prev_v = v;
    }
    ASSERT_EQ(apexes.size(), 5u);
    for (double apex : apexes) EXPECT_NEAR(apex, 5.0, 0.05) << "apex " << apex;
}

TEST(Contact, InelasticSphereComesToRest) {
    Space space;
    add_ground(space);
    const BodyHandle ball = space.create_body(sphere_at(Vec3(0, 3, 0), 0.5));
    for (int i = 0; i < 180; ++i) space.update();
    EXPECT_NEAR(space.internal_position(ball).y(), 0.5, 0.01);
    EXPECT_LT(std::abs(space.internal_linear_velocity(ball).y()), 0.05);
}

TEST(Contact, EqualSpheresSwapVelocitiesInAnElasticHeadOnCollision) {
    Space space;
    space.set_gravity(Vec3::Zero());
    BodyDesc d = sphere_at(Vec3(-2, 0, 0), 0.5);
    d.restitution = 1;
    d.friction = 0;
    d.linear_velocity = Vec3(3, 0, 0);
    const BodyHandle a = space.create_body(d);
    d.position = Vec3(2, 0, 0);
    d.linear_velocity = Vec3(-1, 0, 0);
    const BodyHandle b = space.create_body(d);
    for (int i = 0; i < 90; ++i) space.update();
    EXPECT_NEAR(space.internal_linear_velocity(a).x(), -1.0, 1e-4);
    EXPECT_NEAR(space.internal_linear_velocity(b).x(), 3.0, 1e-4);
}

TEST(Validation, BadBodiesAreRejectedNamingTheFieldAndChangeNothing) {
    Space space;
    auto message = [&](BodyDesc d) -> std::string {
        try {
            space.create_body(d);
        } catch (const Error& e) {
            return e.what();
        }
        return {};
    };
    BodyDesc d = sphere_at(Vec3::Zero());
    d.mass = -1;
    EXPECT_NE(message(d).find("mass must be finite and >= 0, got -1"), std::string::npos);
    d = sphere_at(Vec3(std::nan(""), 0, 0));
    EXPECT_NE(message(d).find("position"), std::string::npos);
    d = sphere_at(Vec3::Zero());
    d.orientation = Quat(0, 0, 0, 0);
    EXPECT_NE(message(d).find("orientation"), std::string::npos);
    d = sphere_at(Vec3::Zero());
    d.shape = Shape::plane(Vec3::UnitY(), 0);
    EXPECT_NE(message(d).find("static body"), std::string::npos);
    d = sphere_at(Vec3::Zero());
    d.friction = -0.5;
    EXPECT_NE(message(d).find("friction"), std::string::npos);
    EXPECT_EQ(space.body_count(), 0u);
    EXPECT_THROW(Shape::sphere(-1), Error);
    EXPECT_THROW(Shape::box(Vec3(1, 0, 1)), Error);
}

}  // namespace analytic_test
