// Hard cases of motion: a confined crowd of spheres, a row of dominoes, a body
// tumbling about its intermediate axis, fast spheres against thin walls, and a long
// run of a busy scene.
#include "scene_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

using namespace spindle;
using namespace spindle::stability;

namespace {

// Six static walls 1 m thick around the cube [-half, half]^3.
std::vector<BodyHandle> add_closed_box(Space& space, double half) {
    std::vector<BodyHandle> walls;
    for (int axis = 0; axis < 3; ++axis) {
        for (const double side : {-1.0, 1.0}) {
            Vec3 extents = Vec3::Constant(half + 1);
            extents[axis] = 0.5;
            Vec3 p = Vec3::Zero();
            p[axis] = side * (half + 0.5);
            walls.push_back(add_static_box(space, extents, p));
        }
    }
    return walls;
}

Vec3 random_direction(std::mt19937_64& rng) {
    std::normal_distribution<double> normal;
    return Vec3(normal(rng), normal(rng), normal(rng)).normalized();
}

}  // namespace

// 625 spheres (radius 0.5) in a 9 x 9 x 8 grid, touching, filling a closed 9 m cube
// but for one layer, with random velocities up to 5 m/s and no gravity.
TEST(ConfinedCrowd, SpheresStayInsideAndNeverOutrunPushOut) {
    auto space = make_space();
    space->set_gravity(Vec3::Zero());
    constexpr double kHalf = 4.5;
    add_closed_box(*space, kHalf);
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> speed(0, 5);
    std::vector<BodyHandle> spheres;
    double fastest_start = 0;
    for (int n = 0; n < 625; ++n) {
        BodyDesc d;
        d.shape = Shape::sphere(0.5);
        d.position = Vec3(-4 + n % 9, -4 + (n / 9) % 9, -4 + n / 81);
        d.linear_velocity = speed(rng) * random_direction(rng);
        fastest_start = std::max(fastest_start, d.linear_velocity.norm());
        spheres.push_back(space->create_body(d));
    }
    const double allowed = fastest_start + space->settings().solver.push_out_speed;
    double worst_speed = 0, worst_step_speed = 0, worst_outside = -kHuge;
    std::vector<Vec3> before = positions(*space, spheres);
    for (int step = 0; step < 600; ++step) {
        space->update();
        for (std::size_t i = 0; i < spheres.size(); ++i) {
            const Vec3 p = space->internal_position(spheres[i]);
            worst_speed = std::max(worst_speed, space->internal_linear_velocity(spheres[i]).norm());
            worst_step_speed = std::max(worst_step_speed, (p - before[i]).norm() / kStep);
            worst_outside = std::max(worst_outside, p.cwiseAbs().maxCoeff() + 0.5 - kHalf);
            before[i] = p;
        }
    }
    std::printf("[ measure  ] crowd: fastest start %.3f m/s, worst speed %.3f m/s (from position change %.3f), "
                "allowed %.3f; deepest reach past a wall face %.4f m\n",
                fastest_start, worst_speed, worst_step_speed, allowed, worst_outside);
    EXPECT_TRUE(all_finite(*space, spheres));
    EXPECT_LE(worst_speed, allowed);
    EXPECT_LE(worst_step_speed, allowed);
    EXPECT_LT(worst_outside, 0.5);  // a centre past the wall face means it escaped
}

// 20 dominoes 0.2 x 2 x 1 m, 1 m apart; the first is tipped over by an initial spin
// about its front bottom edge. A domino has fallen when it leans more than 10 degrees.
TEST(Dominoes, AllFallInOrder) {
    auto space = make_space();
    add_static_box(*space, Vec3(30, 1, 5), Vec3(0, -1, 0));
    constexpr int kCount = 20;
    const Vec3 half(0.1, 1, 0.5);
    std::vector<BodyHandle> dominoes;
    for (int i = 0; i < kCount; ++i) {
        BodyDesc d;
        d.shape = Shape::box(half);
        d.position = Vec3(i * 1.0, 1, 0);
        if (i == 0) {
            d.angular_velocity = Vec3(0, 0, -2);
            d.linear_velocity = d.angular_velocity.cross(Vec3(-half.x(), half.y(), 0));  // pivot on the +x bottom edge
        }
        dominoes.push_back(space->create_body(d));
    }
    std::vector<int> fell(kCount, -1);
    const double threshold = 10 * kPi / 180;
    for (int step = 1; step <= 600 && fell.back() < 0; ++step) {
        space->update();
        for (int i = 0; i < kCount; ++i) {
            const Vec3 up = space->internal_orientation(dominoes[i]) * Vec3::UnitY();
            if (fell[i] < 0 && std::acos(std::clamp(up.y(), -1.0, 1.0)) > threshold) fell[i] = step;
        }
    }
    std::printf("[ measure  ] dominoes fall steps:");
    for (int f : fell) std::printf(" %d", f);
    std::printf("\n");
    for (int i = 0; i < kCount; ++i) {
        EXPECT_GE(fell[i], 0) << "domino " << i << " never fell";
        if (i > 0) {
            EXPECT_GT(fell[i], fell[i - 1]) << "domino " << i << " fell before domino " << i - 1;
        }
    }
}

// A 1 x 2 x 3 m box spun about its intermediate (y) axis, slightly perturbed, tumbles
// (Dzhanibekov). A free body keeps its angular momentum: over 20 s it must stay within
// 1 % (as a vector, in the world) and the energy must not grow (it may wobble by a
// thousandth of a percent; an explicit update would gain 500 % here). Main before issue 16
// (an implicit Newton step on the gyroscopic torque) lost 22 % of the momentum and 39 %
// of the energy in 20 s.
TEST(Gyroscopic, IntermediateAxisSpinKeepsAngularMomentumAndGainsNoEnergy) {
    auto space = make_space();
    space->set_gravity(Vec3::Zero());
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.5, 1, 1.5));
    d.gyroscopic = true;
    d.angular_velocity = Vec3(0.01, 5, 0.01);
    const BodyHandle body = space->create_body(d);
    auto momentum = [&] {
        const Mat3 r = space->internal_orientation(body).toRotationMatrix();
        return Vec3(r * mass_of(space->internal_desc(body)).inertia * r.transpose() *
                    space->internal_angular_velocity(body));
    };
    const double initial = rotational_energy(*space, body);
    const Vec3 initial_momentum = momentum();
    double highest = initial, lowest = initial, worst_momentum = 0;
    int flips = 0;
    double last_sign = 1;
    for (int step = 0; step < 1200; ++step) {
        space->update();
        const double e = rotational_energy(*space, body);
        highest = std::max(highest, e);
        lowest = std::min(lowest, e);
        worst_momentum = std::max(worst_momentum, (momentum() - initial_momentum).norm() / initial_momentum.norm());
        const Vec3 body_w = space->internal_orientation(body).conjugate() * space->internal_angular_velocity(body);
        const double sign = body_w.y() >= 0 ? 1 : -1;
        if (sign != last_sign) ++flips;
        last_sign = sign;
    }
    std::printf("[ measure  ] gyroscopic: energy initial %.6g J, highest %+.3g%%, lowest %+.3g%%, final %+.3g%%; "
                "angular momentum off by up to %.3g%%; %d flips of the spin about the body's y axis\n",
                initial, 100 * (highest / initial - 1), 100 * (lowest / initial - 1),
                100 * (rotational_energy(*space, body) / initial - 1), 100 * worst_momentum, flips);
    EXPECT_TRUE(all_finite(*space, {body}));
    EXPECT_LT(highest, initial * (1 + 1e-4));  // a bounded wobble of the midpoint rule, no growth
    EXPECT_GT(lowest, initial * 0.99);
    EXPECT_LT(worst_momentum, 0.01);
    EXPECT_GT(flips, 2);  // it tumbles, as a free body spinning about that axis must
}

// Sixteen 0.1 m spheres at 100 to 300 m/s, at angles from head-on to 80 degrees off
// the normal, at a static wall 0.1 m thick (80 m square); none may come out behind it.
// Their paths cross near the wall, so they also knock each other about there, and one
// knocked sideways may fly past the wall's edge and drift behind it: a centre counts as
// through only where its path crosses the wall's middle plane within the wall's face.
TEST(FastBodies, SpheresAtManyAnglesDoNotTunnelThroughAThinWall) {
    auto space = make_space();
    space->set_gravity(Vec3::Zero());
    constexpr double kWallHalf = 40;
    add_static_box(*space, Vec3(0.05, kWallHalf, kWallHalf), Vec3::Zero());
    std::vector<BodyHandle> spheres;
    std::vector<double> angles;
    for (int n = 0; n < 16; ++n) {
        const double off_normal = (n % 8) * 10 * kPi / 180;
        angles.push_back(off_normal);
        const double around = n * 0.7;
        const double speed = 100 + 200 * (n % 5) / 4.0;
        const Vec3 dir(std::cos(off_normal), std::sin(off_normal) * std::cos(around),
                       std::sin(off_normal) * std::sin(around));
        BodyDesc d;
        d.shape = Shape::sphere(0.1);
        d.fast = true;
        d.friction = (n % 2) ? 0.6 : 0;
        d.restitution = (n % 3 == 0) ? 0.5 : 0;
        // Start so that, unhindered, each would be inside or past the wall after a step
        // at a different phase of its path.
        const double steps_to_wall = 1.3 + 0.37 * n;
        d.position = Vec3(-0.15, 0, 0) - dir * speed * kStep * steps_to_wall +
                     Vec3(0, 2.0 * (n % 4) - 3, 2.0 * (n / 4) - 3);
        d.linear_velocity = dir * speed;
        spheres.push_back(space->create_body(d));
    }
    const auto within_face = [&](const Vec3& q) { return std::abs(q.y()) < kWallHalf && std::abs(q.z()) < kWallHalf; };
    double deepest_x = -kHuge;  // over centres within the wall's face
    std::vector<int> passed(spheres.size(), -1);
    std::vector<Vec3> last(spheres.size());
    for (std::size_t i = 0; i < spheres.size(); ++i) last[i] = space->internal_position(spheres[i]);
    for (int step = 1; step <= 60; ++step) {
        space->update();
        for (std::size_t i = 0; i < spheres.size(); ++i) {
            const Vec3 p = space->internal_position(spheres[i]);
            if (last[i].x() <= 0 && p.x() > 0 && passed[i] < 0) {
                // Where the step's straight path crosses the middle plane.
                const Vec3 at = last[i] + (p - last[i]) * (-last[i].x() / (p.x() - last[i].x()));
                if (within_face(at)) passed[i] = step;
            }
            if (within_face(p)) deepest_x = std::max(deepest_x, p.x());
            last[i] = p;
        }
    }
    std::printf("[ measure  ] fast spheres: largest centre x within the wall's face %.4f m (wall face at -0.05, "
                "radius 0.1); through:",
                deepest_x);
    for (std::size_t i = 0; i < spheres.size(); ++i) {
        if (passed[i] < 0) continue;
        const BodyDesc& d = space->internal_desc(spheres[i]);
        std::printf(" #%zu (%.0f deg, %.0f m/s, friction %.1f, restitution %.1f: step %d)", i, angles[i] * 180 / kPi,
                    d.linear_velocity.norm(), d.friction, d.restitution, passed[i]);
    }
    std::printf("\n");
    EXPECT_TRUE(all_finite(*space, spheres));
    EXPECT_EQ(std::count(passed.begin(), passed.end(), -1), static_cast<std::ptrdiff_t>(spheres.size()))
        << "a centre crossed the wall's middle plane within its face: tunnelled";
}

// 50 mixed bodies (boxes, spheres, capsules, hulls) thrown around a closed 6 m box
// under gravity for 100,000 steps, sleeping off. Kinetic plus potential energy must
// never exceed the initial by more than 3%.
TEST(LongRun, BusySceneStaysFiniteAndGainsNoEnergyOver100kSteps) {
    auto space = make_space();
    constexpr double kHalf = 3;
    add_closed_box(*space, kHalf);
    const Vec3 hull_points[] = {{0.4, 0, 0},     {-0.4, 0, 0}, {0, 0.5, 0},
                                {0, -0.3, 0.25}, {0, 0, -0.4}, {0.15, 0.25, 0.3}};
    const Shape shapes[] = {Shape::box(Vec3(0.4, 0.25, 0.3)), Shape::sphere(0.3), Shape::capsule(0.25, 0.2),
                            Shape::convex_hull(hull_points)};
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> speed(0, 6);
    std::vector<BodyHandle> bodies;
    for (int n = 0; n < 50; ++n) {
        BodyDesc d;
        d.shape = shapes[n % 4];
        d.position = Vec3(-2.2 + 1.1 * (n % 5), -2 + 1.1 * (n / 25), -2.2 + 1.1 * ((n / 5) % 5));
        d.orientation = Quat(Eigen::AngleAxisd(0.7 * n, random_direction(rng)));
        d.linear_velocity = speed(rng) * random_direction(rng);
        d.angular_velocity = 3 * random_direction(rng);
        d.restitution = (n % 3) * 0.3;
        d.friction = 0.2 + 0.2 * (n % 3);
        bodies.push_back(space->create_body(d));
    }
    const EnergyMeter energy(*space, bodies, -kHalf);
    const double initial = energy(*space);
    double highest = initial;
    int worst_step = 0;
    bool finite = true;
    for (int step = 1; step <= 100000; ++step) {
        space->update();
        const double e = energy(*space);
        if (e > highest) {
            highest = e;
            worst_step = step;
        }
        if (step % 1000 == 0 && !all_finite(*space, bodies)) {
            finite = false;
            break;
        }
    }
    std::printf("[ measure  ] long run: energy initial %.6g J, highest %+.3g%% (step %d), final %.6g J\n", initial,
                100 * (highest / initial - 1), worst_step, energy(*space));
    EXPECT_TRUE(finite && all_finite(*space, bodies));
    EXPECT_LE(highest, initial * 1.03);
}
