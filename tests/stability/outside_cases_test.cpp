// Hard cases written from outside the team (session 41): variants of the kinds issue 16
// named (friction at the friction angle, thin shapes, rolling, free spin, stacks on moving
// platforms, bounces, pendulums, fast bodies, sleeping), through the public API only,
// each against its analytic answer with a tolerance a game-physics user would accept.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <span>
#include <vector>

#include "../engine/grid_mesh.hpp"
#include "scene_util.hpp"

namespace spindle::stability::outside {

namespace {

enum class Floor { Plane, Box, Mesh };

const char* floor_name(Floor f) {
    switch (f) {
        case Floor::Plane: return "plane";
        case Floor::Box: return "box";
        case Floor::Mesh: return "mesh";
    }
    return "?";
}

// A static floor whose top face passes through the origin, turned by `tilt`, with
// friction mu. The mesh is a grid of 1 m cells (its inner edges are where a sliding or
// rolling body would catch).
BodyHandle add_floor(Space& space, Floor kind, const Quat& tilt, double mu, double restitution = 0) {
    BodyDesc d;
    d.type = MotionType::Static;
    d.friction = mu;
    d.restitution = restitution;
    d.orientation = tilt;
    switch (kind) {
        case Floor::Plane: d.shape = Shape::plane(Vec3::UnitY(), 0); break;
        case Floor::Box:
            d.shape = Shape::box(Vec3(25, 0.5, 6));
            d.position = tilt * Vec3(0, -0.5, 0);
            break;
        case Floor::Mesh: d.shape = test::flat_grid_mesh(50, 1.0); break;
    }
    return space.create_body(d);
}

Quat about_z(double angle) { return Quat(Eigen::AngleAxisd(angle, Vec3::UnitZ())); }
Quat about_x(double angle) { return Quat(Eigen::AngleAxisd(angle, Vec3::UnitX())); }

void step(Space& space, int steps) {
    for (int i = 0; i < steps; ++i) space.update();
}

// A body resting on a slope of angle theta about z (downhill is -x along the slope),
// released at rest at local (x0, lift, 0) in the slope's frame.
enum class Slider { Box, Capsule };

BodyHandle add_slider(Space& space, Slider kind, const Quat& tilt, double mu) {
    BodyDesc d;
    d.friction = mu;
    if (kind == Slider::Box) {
        // Flat enough not to tip over before it slides (tan theta < 0.25 / 0.1).
        d.shape = Shape::box(Vec3(0.25, 0.1, 0.25));
        d.position = tilt * Vec3(2, 0.1, 0);
        d.orientation = tilt;
    } else {
        // Lying with its axis downhill: it cannot roll down, only slide.
        d.shape = Shape::capsule(0.3, 0.1);
        d.position = tilt * Vec3(2, 0.1, 0);
        d.orientation = tilt * about_z(kPi / 2);
    }
    return space.create_body(d);
}

const char* slider_name(Slider s) { return s == Slider::Box ? "box" : "capsule"; }

}  // namespace

// ---- Friction at the friction angle ----------------------------------------------------
// Coulomb: a body on a slope sticks while tan(theta) < mu and slides at g (sin - mu cos)
// above. Just under (tan = 0.85 mu) it must stay put: under 3 mm in 5 s, the few mm a
// player never sees. Just over (tan = 1.15 mu) it must accelerate at Coulomb's rate within
// 5 % (measured between 0.5 s and 1.5 s, after the soft contact has taken the load).
TEST(OutsideFriction, JustUnderTheFrictionAngleBoxesAndCapsulesStayPut) {
    for (Floor floor : {Floor::Plane, Floor::Box, Floor::Mesh}) {
        for (Slider kind : {Slider::Box, Slider::Capsule}) {
            for (double mu : {0.2, 0.5, 1.0}) {
                const double theta = std::atan(0.85 * mu);
                auto space = make_space();
                const Quat tilt = about_z(theta);
                add_floor(*space, floor, tilt, mu);
                const BodyHandle body = add_slider(*space, kind, tilt, mu);
                const Vec3 start = space->internal_position(body);
                step(*space, 300);
                const double drift = (space->internal_position(body) - start).norm();
                std::printf("[ measure  ] %s on %s, mu %.1f at 0.85 mu: drift %.3f mm in 5 s\n", slider_name(kind),
                            floor_name(floor), mu, 1000 * drift);
                EXPECT_LT(drift, 3e-3) << slider_name(kind) << " on " << floor_name(floor) << " mu " << mu;
            }
        }
    }
}

TEST(OutsideFriction, JustOverTheFrictionAngleBoxesAndCapsulesSlideAtCoulombsRate) {
    for (Floor floor : {Floor::Plane, Floor::Box, Floor::Mesh}) {
        for (Slider kind : {Slider::Box, Slider::Capsule}) {
            for (double mu : {0.2, 0.5, 1.0}) {
                const double theta = std::atan(1.15 * mu);
                auto space = make_space();
                const Quat tilt = about_z(theta);
                add_floor(*space, floor, tilt, mu);
                const BodyHandle body = add_slider(*space, kind, tilt, mu);
                const Vec3 downhill = tilt * -Vec3::UnitX();
                step(*space, 30);
                const double v0 = space->internal_linear_velocity(body).dot(downhill);
                step(*space, 60);
                const double v1 = space->internal_linear_velocity(body).dot(downhill);
                const double a = v1 - v0;  // over 1 s
                const double expected = kGravity * (std::sin(theta) - mu * std::cos(theta));
                std::printf("[ measure  ] %s on %s, mu %.1f at 1.15 mu: a %.4f m/s^2 (Coulomb %.4f, %.1f %%)\n",
                            slider_name(kind), floor_name(floor), mu, a, expected, 100 * (a / expected - 1));
                EXPECT_NEAR(a, expected, 0.05 * expected)
                    << slider_name(kind) << " on " << floor_name(floor) << " mu " << mu;
            }
        }
    }
}

// A ball on a slope rolls without slipping while mu >= 2/7 tan(theta), at a = 5/7 g sin;
// with less friction it slides at g (sin - mu cos) and spins up at 5 mu g cos / (2 r).
// Within 3 %: a user sees a ball roll too fast or too slow well before that.
TEST(OutsideFriction, BallOnASlopeRollsAtFiveSeventhsOrSlipsAtCoulombsRate) {
    constexpr double kTheta = 0.3, kR = 0.25;
    for (Floor floor : {Floor::Plane, Floor::Box, Floor::Mesh}) {
        for (double mu : {0.05, 0.5}) {
            auto space = make_space();
            const Quat tilt = about_z(kTheta);
            add_floor(*space, floor, tilt, mu);
            BodyDesc d;
            d.shape = Shape::sphere(kR);
            d.position = tilt * Vec3(5, kR, 0);
            d.friction = mu;
            const BodyHandle ball = space->create_body(d);
            const Vec3 downhill = tilt * -Vec3::UnitX();
            step(*space, 15);
            const double v0 = space->internal_linear_velocity(ball).dot(downhill);
            const double w0 = space->internal_angular_velocity(ball).z();
            step(*space, 60);
            const double v1 = space->internal_linear_velocity(ball).dot(downhill);
            const double w1 = space->internal_angular_velocity(ball).z();
            const bool rolls = mu >= 2.0 / 7.0 * std::tan(kTheta);
            const double expected = rolls ? 5.0 / 7.0 * kGravity * std::sin(kTheta)
                                          : kGravity * (std::sin(kTheta) - mu * std::cos(kTheta));
            const double expected_alpha = rolls ? expected / kR : 2.5 * mu * kGravity * std::cos(kTheta) / kR;
            // Rolling down -x about +z: the spin is positive about z.
            const double alpha = w1 - w0;
            const double height = (space->internal_position(ball)).dot(tilt * Vec3::UnitY());
            std::printf(
                "[ measure  ] ball on %s, mu %.2f: a %.4f (%.4f), alpha %.3f (%.3f), centre %.2f mm above its rest\n",
                floor_name(floor), mu, v1 - v0, expected, alpha, expected_alpha, 1000 * (height - kR));
            EXPECT_NEAR(v1 - v0, expected, 0.03 * expected) << floor_name(floor) << " mu " << mu;
            EXPECT_NEAR(alpha, expected_alpha, 0.03 * expected_alpha) << floor_name(floor) << " mu " << mu;
            EXPECT_GT(height - kR, -0.005) << floor_name(floor) << " mu " << mu;
        }
    }
}

// A cube sliding across a mesh floor's inner edges slows at mu g as on a plane, and does
// not hop on them (a classic of triangle-mesh ground: ghost collisions on inner edges).
TEST(OutsideFriction, CubeSlidingAcrossMeshEdgesDeceleratesAtMuGWithoutHopping) {
    constexpr double kMu = 0.3, kV = 6;
    for (Floor floor : {Floor::Plane, Floor::Mesh}) {
        for (double yaw : {0.0, 0.7}) {
            auto space = make_space();
            add_floor(*space, floor, Quat::Identity(), kMu);
            BodyDesc d;
            d.shape = Shape::box(Vec3::Constant(0.2));
            d.position = Vec3(-10, 0.2, 0.3);
            d.orientation = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitY()));
            d.linear_velocity = Vec3(kV, 0, 0.5 * kV);
            d.friction = kMu;
            const BodyHandle box = space->create_body(d);
            double worst_up = 0, worst_w = 0, worst_dv = 0;
            const double speed0 = d.linear_velocity.norm();
            for (int i = 1; i <= 90; ++i) {
                space->update();
                const Vec3 v = space->internal_linear_velocity(box);
                worst_up = std::max(worst_up, std::abs(v.y()));
                worst_w = std::max(worst_w, space->internal_angular_velocity(box).norm());
                const double expected = std::max(0.0, speed0 - kMu * kGravity * i * kStep);
                worst_dv = std::max(worst_dv, std::abs(Vec3(v.x(), 0, v.z()).norm() - expected));
            }
            std::printf("[ measure  ] cube sliding on %s, yaw %.1f: worst |v - (v0 - mu g t)| %.3f m/s, vertical "
                        "%.3f m/s, spin %.3f rad/s\n",
                        floor_name(floor), yaw, worst_dv, worst_up, worst_w);
            // 0.1 m/s of the 6.7 m/s: a few % of the speed; a hop of 0.1 m/s rises 0.5 mm.
            EXPECT_LT(worst_dv, 0.1) << floor_name(floor) << " yaw " << yaw;
            EXPECT_LT(worst_up, 0.1) << floor_name(floor) << " yaw " << yaw;
            EXPECT_LT(worst_w, 0.5) << floor_name(floor) << " yaw " << yaw;
        }
    }
}

// ---- Thin shapes dropped flat and on an edge ---------------------------------------------
namespace {

Shape coin(double radius, double half_thickness) {
    std::vector<Vec3> points;
    for (int i = 0; i < 24; ++i) {
        const double a = 2 * kPi * i / 24;
        for (double y : {-half_thickness, half_thickness})
            points.emplace_back(radius * std::cos(a), y, radius * std::sin(a));
    }
    return Shape::convex_hull(points);
}

struct Settled {
    double spin = 0;    // largest angular speed over the last second, rad/s
    double drift = 0;   // largest distance from where it was a second before the end, m
    double lowest = 0;  // lowest point reached below the floor, m (from the shape's own bounds)
};

Settled drop_and_settle(Floor floor, const Shape& shape, const Quat& orientation, double lift) {
    auto space = make_space();
    add_floor(*space, floor, Quat::Identity(), 0.6);
    BodyDesc d;
    d.shape = shape;
    d.orientation = orientation;
    d.position = Vec3(0.3, 0, 0.2);
    d.position.y() = lift - shape.bounds(Transform{d.position, orientation}).min.y();
    const BodyHandle body = space->create_body(d);
    Settled s;
    for (int i = 0; i < 150; ++i) {
        space->update();
        const Transform pose{space->internal_position(body), space->internal_orientation(body)};
        s.lowest = std::max(s.lowest, -shape.bounds(pose).min.y());
    }
    const Vec3 before = space->internal_position(body);
    for (int i = 0; i < 60; ++i) {
        space->update();
        s.spin = std::max(s.spin, space->internal_angular_velocity(body).norm());
        s.drift = std::max(s.drift, (space->internal_position(body) - before).norm());
    }
    return s;
}

}  // namespace

// Plates 1 cm thick, a coin (a 24-sided hull 6 mm thick), a thin rod: dropped flat from
// 10 cm, and tilted so that they land on an edge or a corner first. After 2.5 s they must
// lie still: under 0.02 rad/s and 1 mm over the last second (a plate that walks or spins
// on the floor is the complaint), never deeper than 1 cm in the floor on landing.
TEST(OutsideThin, PlatesCoinsAndRodsDroppedFlatOrOnAnEdgeSettle) {
    struct Case {
        const char* name;
        Shape shape;
    };
    const Case cases[] = {
        {"plate 1 x 0.01 x 1", Shape::box(Vec3(0.5, 0.005, 0.5))},
        {"plate 0.4 x 0.01 x 0.1", Shape::box(Vec3(0.2, 0.005, 0.05))},
        {"coin r 0.1 x 0.006", coin(0.1, 0.003)},
        {"rod 2 x 0.02 x 0.02", Shape::box(Vec3(1, 0.01, 0.01))},
        {"capsule rod 2 x r 0.01", Shape::capsule(1, 0.01)},
    };
    const Quat flat = Quat::Identity();
    const Quat edge = Quat(Eigen::AngleAxisd(0.6, Vec3(1, 0, 0.3).normalized()));
    const Quat capsule_flat = about_z(kPi / 2);
    for (const Case& c : cases) {
        for (Floor floor : {Floor::Plane, Floor::Box, Floor::Mesh}) {
            for (bool on_edge : {false, true}) {
                Quat q = on_edge ? edge : flat;
                if (c.shape.type == ShapeType::Capsule) q = q * capsule_flat;
                const Settled s = drop_and_settle(floor, c.shape, q, 0.1);
                std::printf("[ measure  ] %s on %s dropped %s: spin %.4f rad/s, drift %.3f mm, deepest %.2f mm\n",
                            c.name, floor_name(floor), on_edge ? "on an edge" : "flat", s.spin, 1000 * s.drift,
                            1000 * s.lowest);
                EXPECT_LT(s.spin, 0.02) << c.name << " on " << floor_name(floor) << (on_edge ? " edge" : " flat");
                EXPECT_LT(s.drift, 1e-3) << c.name << " on " << floor_name(floor) << (on_edge ? " edge" : " flat");
                EXPECT_LT(s.lowest, 0.01) << c.name << " on " << floor_name(floor) << (on_edge ? " edge" : " flat");
            }
        }
    }
}

// Five thin plates 2 cm thick stacked flat, each turned a little from the one below: a
// pile of books or tiles. They must stay stacked and still (no walking, no spin).
TEST(OutsideThin, StackOfFiveThinPlatesStaysStill) {
    for (Floor floor : {Floor::Plane, Floor::Mesh}) {
        auto space = make_space();
        add_floor(*space, floor, Quat::Identity(), 0.6);
        std::vector<BodyHandle> plates;
        for (int i = 0; i < 5; ++i) {
            BodyDesc d;
            d.shape = Shape::box(Vec3(0.3, 0.01, 0.2));
            d.position = Vec3(0.05 * i, 0.01 + 0.02 * i, 0.3);
            d.orientation = Quat(Eigen::AngleAxisd(0.2 * i, Vec3::UnitY()));
            plates.push_back(space->create_body(d));
        }
        step(*space, 120);
        const std::vector<Vec3> settled = positions(*space, plates);
        double spin = 0;
        for (int i = 0; i < 60; ++i) {
            space->update();
            for (BodyHandle p : plates) spin = std::max(spin, space->internal_angular_velocity(p).norm());
        }
        const double drift = max_displacement(*space, plates, settled);
        // Each contact may press in up to the linear slop (the engine's allowed penetration;
        // soft contacts under more load press in more: 3.4 mm under four plates, 1.3 mm
        // under one were measured).
        double deepest = 0, below = 0;  // below: the top of what the plate lies on
        for (BodyHandle p : plates) {
            const double y = space->internal_position(p).y();
            deepest = std::max(deepest, below - (y - 0.01));
            below = y + 0.01;
        }
        std::printf("[ measure  ] five plates on %s: drift %.3f mm, spin %.4f rad/s, top at %.4f m, deepest contact "
                    "%.2f mm\n",
                    floor_name(floor), 1000 * drift, spin, space->internal_position(plates.back()).y(), 1000 * deepest);
        EXPECT_LT(drift, 1e-3) << floor_name(floor);
        EXPECT_LT(spin, 0.02) << floor_name(floor);
        EXPECT_LT(deepest, SolverSettings{}.linear_slop) << floor_name(floor);
    }
}

// Twenty poker chips (4 x 4 cm, 3.3 mm thick, 10 g) stacked flat: the stack must keep its
// height within 5 % (each contact a sixth of a millimetre) and stay put.
// Disabled: found in session 43: the top sits at 30 % of the built height (5 chips: 53 %,
// 10: 41 %). A soft contact holds its load at a depth of load / (m_eff w^2) (SolverSettings::
// contact_hertz; ContactSolveParams::held_per_impulse), about 0.28 mm per chip carried
// between two equal bodies at 30 Hz whatever their size: the twenty chips' contacts press in
// 2.3 mm on average, two thirds of a chip. Box3D's soft contacts share the model. The
// plates above (2 cm) show the same depths (3.4 mm under four), within their slop. Tried in
// session 43, both unstable: the soft row without its leak of the warm-started impulse (the
// five plates spin at 0.8 rad/s, the chips scatter 11 cm), and its rest depth offset by the
// depth the warm-started load holds (an eight-cube stack jitters at 0.47 m/s). A fix holds a
// resting contact at no depth whatever its load (support scaling by the whole load carried,
// a position pass as Jolt's), without letting an impact's impulse push bodies apart.
TEST(OutsideThin, DISABLED_StackOfTwentyPokerChipsKeepsItsHeight) {
    auto space = make_space();
    add_floor(*space, Floor::Plane, Quat::Identity(), 0.5);
    constexpr int kChips = 20;
    constexpr double kThick = 0.0033;
    std::vector<BodyHandle> chips;
    for (int i = 0; i < kChips; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.02, kThick / 2, 0.02));
        d.mass = 0.01;
        d.friction = 0.5;
        d.position = Vec3(0, kThick * (i + 0.5), 0);
        chips.push_back(space->create_body(d));
    }
    step(*space, 300);
    const double top = space->internal_position(chips.back()).y() + kThick / 2;
    double sideways = 0;
    for (BodyHandle c : chips) {
        const Vec3 x = space->internal_position(c);
        sideways = std::max(sideways, std::hypot(x.x(), x.z()));
    }
    std::printf("[ measure  ] twenty chips: top at %.2f %% of the built height, %.2f mm sideways\n",
                100 * top / (kChips * kThick), 1000 * sideways);
    EXPECT_GT(top, 0.95 * kChips * kThick);
    EXPECT_LT(sideways, 1e-3);
}

// ---- Rolling -------------------------------------------------------------------------------
// A ball and a capsule rolling at 8 m/s (spin matched, v = w r) on a plane, a box and a
// mesh: no sinking below the linear slop, speed kept within 1 % over 1.5 s (nothing
// brakes a rolling body without rolling resistance), and v = w r held within 1 %.
TEST(OutsideRolling, BallAndCapsuleRollOnPlaneBoxAndMeshWithoutSinkingOrSlowing) {
    constexpr double kR = 0.2, kV = 8;
    for (Floor floor : {Floor::Plane, Floor::Box, Floor::Mesh}) {
        for (bool capsule : {false, true}) {
            auto space = make_space();
            add_floor(*space, floor, Quat::Identity(), 0.6);
            BodyDesc d;
            d.shape = capsule ? Shape::capsule(0.3, kR) : Shape::sphere(kR);
            // The capsule lies along z and rolls along x.
            d.orientation = capsule ? about_x(kPi / 2) : Quat::Identity();
            d.position = Vec3(-12, kR, 0.4);
            d.linear_velocity = Vec3(kV, 0, 0);
            d.angular_velocity = Vec3(0, 0, -kV / kR);
            const BodyHandle body = space->create_body(d);
            double deepest = 0, worst_slip = 0, worst_speed = 0;
            for (int i = 0; i < 90; ++i) {
                space->update();
                const double v = space->internal_linear_velocity(body).x();
                const double w = -space->internal_angular_velocity(body).z();
                deepest = std::max(deepest, kR - space->internal_position(body).y());
                worst_slip = std::max(worst_slip, std::abs(v - w * kR) / kV);
                worst_speed = std::max(worst_speed, std::abs(v - kV) / kV);
            }
            std::printf("[ measure  ] %s rolling on %s at 8 m/s: sank %.3f mm, worst slip %.3f %%, speed off %.3f %%\n",
                        capsule ? "capsule" : "ball", floor_name(floor), 1000 * deepest, 100 * worst_slip,
                        100 * worst_speed);
            EXPECT_LT(deepest, 0.005) << floor_name(floor) << (capsule ? " capsule" : " ball");
            EXPECT_LT(worst_slip, 0.01) << floor_name(floor) << (capsule ? " capsule" : " ball");
            EXPECT_LT(worst_speed, 0.01) << floor_name(floor) << (capsule ? " capsule" : " ball");
        }
    }
}

// ---- Free spin without gravity ---------------------------------------------------------------
namespace {

Vec3 angular_momentum(const Space& space, BodyHandle body, const MassProperties& mp) {
    const Mat3 r = space.internal_orientation(body).toRotationMatrix();
    return r * mp.inertia * r.transpose() * space.internal_angular_velocity(body);
}

// The same at the middle of the last substep's turn, where the engine's gyroscopic spin
// is taken (integrator.cpp, keep_momentum): the orientation turned back half a substep.
Vec3 midstep_angular_momentum(const Space& space, BodyHandle body, const MassProperties& mp) {
    const Real substep = space.settings().time_step.duration / space.settings().solver.substeps;
    const Vec3 w = space.internal_angular_velocity(body);
    const Mat3 r = integrate_rotation(space.internal_orientation(body), w, -substep / 2).toRotationMatrix();
    return r * mp.inertia * r.transpose() * w;
}

double spin_energy(const Space& space, BodyHandle body, const MassProperties& mp) {
    const Vec3 w = space.internal_angular_velocity(body);
    return 0.5 * w.dot(angular_momentum(space, body, mp));
}

}  // namespace

namespace {

// A box (0.2 x 0.5 x 1 half extents), turned arbitrarily, spinning at 50 rad/s about its
// principal axis `axis`: the largest relative change of its angular momentum over 2 s.
struct MomentumChange {
    double at_step_end = 0;  // L from the step's orientation and spin, as a user reads them
    double mid_substep = 0;  // L where the engine keeps it (midstep_angular_momentum)
};

MomentumChange fast_spin_momentum_change(int axis, bool gyroscopic) {
    const Quat pose = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    auto space = make_space(settings);
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.2, 0.5, 1.0));
    d.orientation = pose;
    d.angular_velocity = pose * (50 * Vec3::Unit(axis));
    d.gyroscopic = gyroscopic;
    const BodyHandle body = space->create_body(d);
    const MassProperties mp = mass_of(d);
    const Vec3 l0 = angular_momentum(*space, body, mp);
    const Vec3 m0 = midstep_angular_momentum(*space, body, mp);
    double worst = 0, worst_mid = 0;
    for (int i = 0; i < 120; ++i) {
        space->update();
        worst = std::max(worst, (angular_momentum(*space, body, mp) - l0).norm() / l0.norm());
        worst_mid = std::max(worst_mid, (midstep_angular_momentum(*space, body, mp) - m0).norm() / m0.norm());
    }
    std::printf("[ measure  ] spin 50 rad/s about axis %d, gyroscopic %d: worst |dL|/L %.4f %% (mid-substep %.4f %%)\n",
                axis, gyroscopic, 100 * worst, 100 * worst_mid);
    return {worst, worst_mid};
}

}  // namespace

// Spinning at 50 rad/s about each principal axis, with and without gyroscopic motion:
// nothing acts on the box, so its spin must not change, within 0.5 % over 2 s (a spin
// that decays by a few rad/s is plain to see). About the intermediate axis with gyroscopic
// motion the spin is unstable (it flips): FastSpinAboutTheIntermediateAxisKeepsItsMomentum.
TEST(OutsideSpin, FastSpinAboutEachPrincipalAxisDoesNotDecay) {
    for (bool gyroscopic : {false, true}) {
        for (int axis = 0; axis < 3; ++axis) {
            if (gyroscopic && axis == 1) continue;
            EXPECT_LT(fast_spin_momentum_change(axis, gyroscopic).at_step_end, 0.005)
                << "axis " << axis << " gyroscopic " << gyroscopic;
        }
    }
}

// The same about the intermediate axis, with gyroscopic motion: it flips over and over
// (rounding starts it), and its angular momentum must not drift while it does: within 1 %
// where the engine keeps it (the middle of the last substep's turn). The box turns 0.2 rad
// a substep. Failed before keep_momentum (integrator.cpp) took both middles as the exact
// halves of the turns the body makes and solved the new spin by Newton passes: 5.2 % in
// 2 s (its two middles, integrate_rotation by -h/2 and +h/2, disagreed at 0.2 rad a
// substep, and two fixed-point passes had not converged); 0.03 % since. What is left
// from the step's end orientation (6.8 %) is bounded, not drift: the published spin is
// the one the body turned by over the last substep, half a substep behind the published
// orientation.
TEST(OutsideSpin, FastSpinAboutTheIntermediateAxisKeepsItsMomentum) {
    EXPECT_LT(fast_spin_momentum_change(1, true).mid_substep, 0.01);
}

namespace {

struct Tumbler {
    const char* name;
    Shape shape;
    Vec3 w;
    bool gyroscopic;
};

// at_step_end: L as a user reads it from the step's orientation and spin, within 2 %;
// else L where the engine keeps it (midstep_angular_momentum), within 1 %.
void expect_tumbling_keeps_momentum(std::span<const Tumbler> cases, bool at_step_end) {
    for (const Tumbler& c : cases) {
        SpaceSettings settings;
        settings.gravity = Vec3::Zero();
        auto space = make_space(settings);
        BodyDesc d;
        d.shape = c.shape;
        d.angular_velocity = c.w;
        d.gyroscopic = c.gyroscopic;
        const BodyHandle body = space->create_body(d);
        const MassProperties mp = mass_of(d);
        const Vec3 l0 = angular_momentum(*space, body, mp);
        const double e0 = spin_energy(*space, body, mp);
        const Vec3 com0 = space->internal_motion_state(body).center_of_mass;
        const Vec3 m0 = midstep_angular_momentum(*space, body, mp);
        double worst_l = 0, worst_e = 0, worst_com = 0, worst_mid = 0;
        for (int i = 0; i < 240; ++i) {
            space->update();
            worst_l = std::max(worst_l, (angular_momentum(*space, body, mp) - l0).norm() / l0.norm());
            worst_mid = std::max(worst_mid, (midstep_angular_momentum(*space, body, mp) - m0).norm() / m0.norm());
            worst_e = std::max(worst_e, std::abs(spin_energy(*space, body, mp) / e0 - 1));
            worst_com = std::max(worst_com, (space->internal_motion_state(body).center_of_mass - com0).norm());
        }
        std::printf(
            "[ measure  ] %s: worst |dL|/L %.3f %% (at mid-substep %.3f %%), |dE|/E %.3f %%, centre moved %.3g m\n",
            c.name, 100 * worst_l, 100 * worst_mid, 100 * worst_e, worst_com);
        if (at_step_end) {
            EXPECT_LT(worst_l, 0.02) << c.name;
        } else {
            EXPECT_LT(worst_mid, 0.01) << c.name;
        }
        EXPECT_LT(worst_e, 0.02) << c.name;
        EXPECT_LT(worst_com, 1e-6) << c.name;
    }
}

}  // namespace

// Dzhanibekov's wing nut: a body spun about its intermediate axis with a small
// perturbation flips over and over; its angular momentum (a world vector, as a user
// measures it from the step's orientation and spin) and energy stay within 2 % over 4 s.
// Also about the minor axis (stable), and a compound whose centre of mass is off its
// origin (the centre must stay put).
TEST(OutsideSpin, TumblingBodiesKeepAngularMomentumAndEnergy) {
    const CompoundPart parts[] = {{Shape::sphere(0.3), Vec3(0, 0, 0)},
                                  {Shape::box(Vec3(0.6, 0.1, 0.2)), Vec3(0.8, 0.2, 0)}};
    const Tumbler cases[] = {
        {"box intermediate axis", Shape::box(Vec3(0.1, 0.3, 0.6)), Vec3(0.05, 12, 0.05), true},
        {"box minor axis", Shape::box(Vec3(0.1, 0.3, 0.6)), Vec3(12, 0.3, 0.3), true},
        {"compound off centre", Shape::compound(parts), Vec3(3, 8, 1), true},
    };
    expect_tumbling_keeps_momentum(cases, true);
}

// A thin rod and a thin capsule (elongated: always gyroscopic) spun fast about their long
// axis and a little across it: they cone about their angular momentum, which must not
// drift (within 1 % where the engine keeps it). Failed before the fix of
// FastSpinAboutTheIntermediateAxisKeepsItsMomentum: the rod's L drifted 2.7 % and the
// capsule's 3.9 % within 4 s; 0.004 % since (energy 1.9 % and 0.5 %, now 0.002 %).
TEST(OutsideSpin, FastConingThinBodiesKeepAngularMomentum) {
    const Tumbler cases[] = {
        {"rod tilted spin", Shape::box(Vec3(1, 0.05, 0.05)), Vec3(20, 3, 1), false},
        {"capsule tilted spin", Shape::capsule(0.8, 0.05), Vec3(2, 20, 1), false},
    };
    expect_tumbling_keeps_momentum(cases, false);
}

// A top (a hull: a sharp tip 13 cm below its centre of mass, a 10 cm rim) spun at 150 rad/s,
// tilted 0.2 rad, on a floor with mu 0.3: fast enough to precess about its pinned tip (as it
// does on a ball-socket pivot: tilt 0.22-0.27 rad for 5 s). It must stay up: its tilt under
// 0.45 rad (its rim touches the floor at 1 rad) and its spin kept. At d60bc49 it fell within
// 4 s on 60 Hz steps (at 120 Hz it stood): each substep's turn of 0.6 rad carries the tip a
// little off the point friction held (the chord, w x (w x r) h^2 / 2, 0.4 mm a substep), so
// the tip slid, the tilt grew and the rim came down. prepare_friction's turning pull is that
// correction, but it was cut to a radian a step of the whole spin, which on a top is mostly
// spin about the tip's own arm and moves nothing; it is now cut where the arm itself turns
// more than a radian a step (turning_pull). The tip still slides (about 0.1 m/s).
TEST(OutsideSpin, FastTopOnARoughFloorStaysUp) {
    std::vector<Vec3> points{Vec3(0, -0.1, 0)};
    for (int i = 0; i < 16; ++i) {
        const double a = 2 * kPi * i / 16;
        points.push_back(Vec3(0.1 * std::cos(a), 0.05, 0.1 * std::sin(a)));
        points.push_back(Vec3(0.08 * std::cos(a), 0.08, 0.08 * std::sin(a)));
    }
    for (bool gyroscopic : {false, true}) {
        auto space = make_space();
        add_floor(*space, Floor::Plane, Quat::Identity(), 0.3);
        BodyDesc d;
        d.shape = Shape::convex_hull(points);
        d.friction = 0.3;
        d.gyroscopic = gyroscopic;
        d.orientation = Quat(Eigen::AngleAxisd(0.2, Vec3::UnitZ()));
        d.position = Vec3(0, 0.101, 0);
        d.angular_velocity = d.orientation * Vec3(0, 150, 0);
        const BodyHandle top = space->create_body(d);
        double tilt = 0;
        for (int i = 0; i < 300; ++i) {
            space->update();
            const Vec3 up = space->internal_orientation(top) * Vec3::UnitY();
            tilt = std::max(tilt, std::acos(std::clamp(up.y(), -1.0, 1.0)));
        }
        const double spin = space->internal_angular_velocity(top).norm();
        std::printf("[ measure  ] top (gyroscopic %d): tilt at most %.3f rad, spin %.1f rad/s after 5 s\n", gyroscopic,
                    tilt, spin);
        EXPECT_LT(tilt, 0.45) << "gyroscopic " << gyroscopic;
        EXPECT_GT(spin, 140) << "gyroscopic " << gyroscopic;
    }
}

// ---- Spinning and tumbling on joints -------------------------------------------------------------
namespace {

// Kinetic and potential energy of a body (gravity g down y).
double body_energy(const Space& space, BodyHandle body, const MassProperties& mp, double g) {
    const Vec3 v = space.internal_linear_velocity(body);
    return 0.5 * mp.mass * v.squaredNorm() + spin_energy(space, body, mp) +
           mp.mass * g * space.internal_position(body).y();
}

// The disc spinning at 100 rad/s about its axle, which lies level and is held 0.3 m from
// the disc's centre by a ball socket.
struct Gyroscope {
    double spin_change = 0;  // the largest relative change of the spin about the axle
    double precession = 0;   // the axle's mean turn about the vertical, rad/s, over the run
};

// The gyroscope's disc: a 32-sided hull, 0.2 m radius, 4 cm thick, its axle along x.
Shape gyroscope_disc() {
    std::vector<Vec3> points;
    for (int i = 0; i < 32; ++i) {
        const double a = 2 * kPi * i / 32;
        points.emplace_back(-0.02, 0.2 * std::cos(a), 0.2 * std::sin(a));
        points.emplace_back(0.02, 0.2 * std::cos(a), 0.2 * std::sin(a));
    }
    return Shape::convex_hull(points);
}

Gyroscope spin_gyroscope(int steps) {
    auto space = make_space();
    BodyDesc pivot;
    pivot.type = MotionType::Static;
    pivot.shape = Shape::sphere(0.01);
    pivot.position = Vec3(0, 1, 0);
    const BodyHandle anchor = space->create_body(pivot);
    BodyDesc d;
    d.shape = gyroscope_disc();
    d.position = Vec3(0.3, 1, 0);
    d.gyroscopic = true;
    d.angular_velocity = Vec3(100, 0, 0);
    const BodyHandle disc = space->create_body(d);
    space->create_joint(JointDesc::ball_socket_at(anchor, disc, Vec3(0, 1, 0)));
    Gyroscope out;
    double turned = 0, last = 0;
    for (int i = 0; i < steps; ++i) {
        space->update();
        const Vec3 axle = space->internal_orientation(disc) * Vec3::UnitX();
        const double spin = space->internal_angular_velocity(disc).dot(axle);
        out.spin_change = std::max(out.spin_change, std::abs(spin / 100 - 1));
        const Vec3 c = space->internal_position(disc);
        const double angle = std::atan2(-c.z(), c.x());
        turned += std::remainder(angle - last, 2 * kPi);
        last = angle;
    }
    out.precession = turned / (steps * kStep);
    return out;
}

}  // namespace

// A gyroscope: nothing turns the disc about its axle (the pivot's pull passes through it),
// so its spin must stay what it was (within 0.1 % over 2 s), and the axle must precess
// about the vertical at m g r / (I w) (within 2 %). Failed before the joints turned the
// bodies' inverse inertias with them through the step: an impulse at the turned anchor went
// through the step's start's inertia, and the precessing disc gained spin, 100 -> 103.3 rad/s
// in 2 s (28 J), 107 in 6 s.
TEST(OutsideSpin, GyroscopeOnAPivotKeepsItsSpinAndPrecessesAtItsRate) {
    const Gyroscope g = spin_gyroscope(120);
    BodyDesc d;
    d.shape = gyroscope_disc();
    const MassProperties mp = mass_of(d);
    const double expected = mp.mass * 9.81 * 0.3 / (mp.inertia(0, 0) * 100);
    std::printf("[ measure  ] gyroscope: spin changed at most %.4f %%, precession %.4f rad/s (m g r / I w: %.4f)\n",
                100 * g.spin_change, g.precession, expected);
    EXPECT_LT(g.spin_change, 1e-3);
    EXPECT_NEAR(g.precession, expected, 0.02 * expected);
}

// A box (1 x 0.2 x 0.5 m) held at a corner by a ball socket, a hinge (its axis askew to the
// box) or a distance rod (solved one by one, not in lanes), tumbling without gravity at 5
// and 20 rad/s: nothing drives it, so its energy must never rise, by 0.1 % of it at most on
// the ball socket and the hinge, 0.5 % on the rod (its length's soft correction); without
// gyroscopic motion (the spin kept as the step's velocity) the ball socket and the hinge must
// also keep it within 1 %. Failed before the joints turned the bodies' inverse inertias with
// them through the step: on the ball socket at 20 rad/s the energy rose from 1.4 kJ to 70 kJ
// with gyroscopic motion (at 5 rad/s by 24 %) and by 4.8 % without; on the rod by 1-2 %, and
// 70-fold at 20 rad/s with gyroscopic motion. Not asserted, the same before and after: with
// gyroscopic motion a tumbling body on a ball socket loses energy (7 % at 5 rad/s, 47 % at 20
// over 5 s: the free spin keeps its momentum, the joint's pull on it each substep does not),
// and on the rod it loses 10-57 % either way.
TEST(OutsideSpin, BodiesTumblingOnJointsGainNoEnergy) {
    for (int joint = 0; joint < 3; ++joint) {
        for (bool gyroscopic : {false, true}) {
            for (double rate : {5.0, 20.0}) {
                SpaceSettings settings;
                settings.gravity = Vec3::Zero();
                auto space = make_space(settings);
                BodyDesc pivot;
                pivot.type = MotionType::Static;
                pivot.shape = Shape::sphere(0.01);
                const BodyHandle anchor = space->create_body(pivot);
                BodyDesc d;
                d.shape = Shape::box(Vec3(0.5, 0.1, 0.25));
                d.position = Vec3(0.6, 0.15, 0.3);
                d.angular_velocity = rate * Vec3(0.3, 1, 0.5);
                d.gyroscopic = gyroscopic;
                const BodyHandle box = space->create_body(d);
                const char* name = "ball socket";
                if (joint == 0) space->create_joint(JointDesc::ball_socket_at(anchor, box, Vec3::Zero()));
                if (joint == 1) {
                    name = "hinge";
                    space->create_joint(JointDesc::hinge_at(anchor, box, Vec3::Zero(), Vec3(0.2, 1, 0.1).normalized()));
                }
                if (joint == 2) {
                    name = "distance rod";
                    space->create_joint(JointDesc::distance_between(anchor, box, Vec3::Zero(), Vec3(0.1, 0.05, 0.05)));
                }
                const MassProperties mp = mass_of(d);
                for (int i = 0; i < 3; ++i) space->update();  // the joint's first pull taken
                const double start = body_energy(*space, box, mp, 0);
                double rose = 0, fell = 0;
                for (int i = 0; i < 300; ++i) {
                    space->update();
                    const double change = body_energy(*space, box, mp, 0) / start - 1;
                    rose = std::max(rose, change);
                    fell = std::min(fell, change);
                }
                std::printf("[ measure  ] %s, gyroscopic %d, %.0f rad/s: energy %.1f J, rose at most %.4f %%, fell at "
                            "most %.4f %%\n",
                            name, gyroscopic, rate, start, 100 * rose, 100 * fell);
                EXPECT_LT(rose, joint == 2 ? 5e-3 : 1e-3)
                    << name << ", gyroscopic " << gyroscopic << ", " << rate << " rad/s";
                if (!gyroscopic && joint != 2) {
                    EXPECT_GT(fell, -0.01) << name << ", " << rate << " rad/s";
                }
            }
        }
    }
}

// Two boxes joined by a weld, a prismatic, a swing-twist or a hinge joint, tumbling together
// without gravity at 5 and 20 rad/s (both dynamic: both turn within the step): their energy must
// never rise by more than 0.2 %. Failed before the joints turned the bodies' inverse inertias
// with them through the step: the weld rose 1,444 % at 20 rad/s, the hinge 10 % at 5 and 1,702 %
// at 20, the prismatic 0.4-1.3 %, the swing-twist 0.4-0.6 %. Not asserted: they lose 0.1-43 % (the boxes are elongated,
// so gyroscopic; the swing-twist's default limits catch the tumble).
TEST(OutsideSpin, JointedPairsTumblingTogetherGainNoEnergy) {
    for (int joint = 0; joint < 4; ++joint) {
        for (double rate : {5.0, 20.0}) {
            SpaceSettings settings;
            settings.gravity = Vec3::Zero();
            auto space = make_space(settings);
            BodyDesc a, b;
            a.shape = Shape::box(Vec3(0.5, 0.05, 0.1));
            b.shape = Shape::box(Vec3(0.05, 0.4, 0.15));
            b.position = Vec3(0.55, 0.35, 0);
            a.angular_velocity = b.angular_velocity = rate * Vec3(0.3, 1, 0.5);
            b.linear_velocity = b.angular_velocity.cross(b.position);  // one rigid tumble
            const BodyHandle first = space->create_body(a), second = space->create_body(b);
            const Vec3 at(0.55, 0, 0);
            const char* names[] = {"weld", "prismatic", "swing-twist", "hinge"};
            const JointDesc joints[] = {JointDesc::fixed_at(first, second, at),
                                        JointDesc::prismatic_at(first, second, at, Vec3::UnitY()),
                                        JointDesc::swing_twist_at(first, second, at, Vec3::UnitX()),
                                        JointDesc::hinge_at(first, second, at, Vec3::UnitZ())};
            space->create_joint(joints[joint]);
            const MassProperties ma = mass_of(a), mb = mass_of(b);
            auto energy = [&] { return body_energy(*space, first, ma, 0) + body_energy(*space, second, mb, 0); };
            for (int i = 0; i < 3; ++i) space->update();  // the joint's first pull taken
            const double start = energy();
            double rose = 0;
            for (int i = 0; i < 300; ++i) {
                space->update();
                rose = std::max(rose, energy() / start - 1);
            }
            std::printf("[ measure  ] %s pair, %.0f rad/s: energy %.1f J, rose at most %.4f %%\n", names[joint], rate,
                        start, 100 * rose);
            EXPECT_LT(rose, 2e-3) << names[joint] << ", " << rate << " rad/s";
        }
    }
}

// ---- Moving platforms --------------------------------------------------------------------------
// A cube on a kinematic platform is carried by friction. mu 0.8 holds it under the
// platform's accelerations here (at most 3 m/s^2 < mu g = 7.8): it must stay where it
// was put on the platform, within 5 mm over 3 s.
namespace {

enum Motion { Constant, Accelerating, Turntable, Elevator };

// A kinematic platform moving as `motion` says and a cube on it, moving with it from the
// start (as if put there long ago), mu 0.8.
struct CarriedCube {
    std::unique_ptr<Space> space;
    BodyDesc platform_desc;
    BodyHandle platform, cube;
};

// A turntable's rate (rad/s) and the cube's distance from its axis (m).
struct Turn {
    double rate = 1.2, radius = 2;  // 1.2^2 x 2 = 2.9 m/s^2
};

CarriedCube cube_on_platform(Motion motion, Turn turn = {}) {
    CarriedCube made{make_space(), {}, {}, {}};
    BodyDesc& p = made.platform_desc;
    p.type = MotionType::Kinematic;
    p.shape = Shape::box(Vec3(3, 0.1, 3));
    p.position = Vec3(0, -0.1, 0);
    p.friction = 0.8;
    if (motion == Constant) p.linear_velocity = Vec3(2, 0, 1);
    if (motion == Turntable) p.angular_velocity = Vec3(0, turn.rate, 0);
    if (motion == Elevator) p.linear_velocity = Vec3(0, 1.5, 0);
    made.platform = made.space->create_body(p);
    BodyDesc c;
    c.shape = Shape::box(Vec3::Constant(0.25));
    c.position = Vec3(motion == Turntable ? turn.radius : 2, 0.25, 0);
    c.friction = 0.8;
    c.linear_velocity = p.linear_velocity + p.angular_velocity.cross(c.position - p.position);
    c.angular_velocity = p.angular_velocity;
    made.cube = made.space->create_body(c);
    return made;
}

// How far the cube moved on the platform (in the platform's frame) over 3 s.
double carried_cube_slip(Motion motion, Turn turn = {}) {
    {
        CarriedCube made = cube_on_platform(motion, turn);
        Space* space = made.space.get();
        const BodyHandle platform = made.platform, cube = made.cube;
        step(*space, 30);  // let the contact take the load
        auto in_platform = [&] {
            const Quat q = space->internal_orientation(platform);
            return Vec3(q.conjugate() * (space->internal_position(cube) - space->internal_position(platform)));
        };
        const Vec3 start = in_platform();
        double worst = 0;
        for (int i = 1; i <= 180; ++i) {
            if (motion == Accelerating) {
                const double t = i * kStep;
                space->move_kinematic(platform, Vec3(1.5 * t * t, -0.1, 0), Quat::Identity());  // a = 3 m/s^2
            }
            space->update();
            worst = std::max(worst, (in_platform() - start).norm());
        }
        std::printf("[ measure  ] cube on platform motion %d: moved %.3f mm on it in 3 s\n", motion, 1000 * worst);
        return worst;
    }
}

}  // namespace

TEST(OutsidePlatform, CubeOnAMovingKinematicPlatformIsCarried) {
    for (Motion motion : {Constant, Accelerating, Elevator}) EXPECT_LT(carried_cube_slip(motion), 5e-3) << motion;
}

// A cube carried on a turntable moves with the platform's surface under it: its velocity
// within 2 degrees of that surface's, also when its manifold was collided steps before (the
// friction centre turns with the bodies, prepare_friction) and not only when just collided.
TEST(OutsidePlatform, CubeOnATurntableMovesWithTheSurfaceUnderIt) {
    CarriedCube made = cube_on_platform(Turntable);
    Space* space = made.space.get();
    const BodyDesc& p = made.platform_desc;
    const BodyHandle platform = made.platform, cube = made.cube;
    step(*space, 30);
    double worst = 0;
    for (int i = 0; i < 60; ++i) {
        space->update();
        const Vec3 surface =
            p.angular_velocity.cross(space->internal_position(cube) - space->internal_position(platform));
        const Vec3 v = space->internal_linear_velocity(cube);
        worst = std::max(worst, std::acos(std::clamp(v.dot(surface) / (v.norm() * surface.norm()), -1.0, 1.0)));
    }
    std::printf("[ measure  ] cube on a turntable: velocity at most %.2f degrees from the surface's\n",
                worst * 180 / kPi);
    EXPECT_LT(worst, 2 * kPi / 180);
}

// The cube slid 1.36 m off the turntable in 3 s at ff39273 (a recycled manifold's friction
// centre not turned with the bodies since its collide; session 42 turned it), then 74 mm at
// c0f2223: the friction centre's anchors stay fixed offsets through a step while the surfaces
// under them turn, so the cube was matched to the platform's velocity of the step's start
// and moved on the tangent, 0.4 mm a step outward, never taken back while it stuck. Friction
// now reads the surfaces turned to the pass's time in the step (prepare_friction).
TEST(OutsidePlatform, CubeOnATurntableIsCarried) { EXPECT_LT(carried_cube_slip(Turntable), 5e-3); }

// Slow and wide, fast and near the axis, and near the friction's limit (5.0 of 7.8 m/s^2).
TEST(OutsidePlatform, CubesOnTurntablesOfOtherRatesAndRadiiAreCarried) {
    for (const Turn turn : {Turn{0.4, 2.8}, Turn{3, 0.5}, Turn{2.5, 0.8}})
        EXPECT_LT(carried_cube_slip(Turntable, turn), 5e-3) << turn.rate << " rad/s at " << turn.radius << " m";
}

// ---- Bounces ---------------------------------------------------------------------------------------
// A ball and a cube dropped flat from 2 m onto the floor rise again to e^2 of the drop
// (restitution mixes as the larger: the floor has 0). Within 5 % of the drop height for
// e = 0.5 and 1; e = 0 must not bounce (under 1 cm).
TEST(OutsideBounce, BallsAndCubesBounceToESquaredOfTheirDrop) {
    constexpr double kDrop = 2;
    for (Floor floor : {Floor::Plane, Floor::Mesh}) {
        for (bool cube : {false, true}) {
            for (double e : {0.0, 0.5, 1.0}) {
                auto space = make_space();
                add_floor(*space, floor, Quat::Identity(), 0.6);
                BodyDesc d;
                d.shape = cube ? Shape::box(Vec3::Constant(0.2)) : Shape::sphere(0.2);
                d.position = Vec3(0.3, 0.2 + kDrop, 0.3);
                d.restitution = e;
                const BodyHandle body = space->create_body(d);
                bool landed = false;
                double apex = 0;
                for (int i = 0; i < 150; ++i) {
                    space->update();
                    const double h = space->internal_position(body).y() - 0.2;
                    if (!landed && space->internal_linear_velocity(body).y() > 0) landed = true;
                    if (landed) apex = std::max(apex, h);
                }
                std::printf("[ measure  ] %s on %s, e %.1f: rose to %.3f m (e^2 h = %.3f)\n", cube ? "cube" : "ball",
                            floor_name(floor), e, apex, e * e * kDrop);
                EXPECT_NEAR(apex, e * e * kDrop, std::max(0.01, 0.05 * kDrop * e * e))
                    << (cube ? "cube" : "ball") << " on " << floor_name(floor) << " e " << e;
            }
        }
    }
}

// A cube dropped flat from 2 m lands flat: it must not come out of the landing turning
// (under 0.1 rad/s, where a player sees no wobble) or sliding off sideways (under 2 cm).
// It failed at 6118a81 on a plane and on a mesh alike: 1.6 rad/s on the plane and 3.2 on
// the mesh, 19 mm sideways. The four speculative points of the landing face were solved
// one after another once a pass: the first took the whole approach and the later ones
// less, so the impulses turned the cube. The passes now sweep a manifold's normal rows
// until they settle where its bodies close fast before touching (solve_wide): 0.006 rad/s.
TEST(OutsideBounce, CubeDroppedFlatLandsFlat) {
    for (Floor floor : {Floor::Plane, Floor::Mesh}) {
        auto space = make_space();
        add_floor(*space, floor, Quat::Identity(), 0.6);
        const BodyHandle cube = add_box(*space, Vec3::Constant(0.2), Vec3(0.3, 2.2, 0.3));
        double spin = 0, sideways = 0;
        for (int i = 0; i < 90; ++i) {
            space->update();
            spin = std::max(spin, space->internal_angular_velocity(cube).norm());
            const Vec3 x = space->internal_position(cube);
            sideways = std::max(sideways, std::hypot(x.x() - 0.3, x.z() - 0.3));
        }
        std::printf("[ measure  ] cube dropped flat on %s: spin %.3f rad/s, moved sideways %.1f mm\n",
                    floor_name(floor), spin, 1000 * sideways);
        EXPECT_LT(spin, 0.1) << floor_name(floor);
        EXPECT_LT(sideways, 0.02) << floor_name(floor);
    }
}

// A ball struck into a row of touching balls (e = 1, no friction, no gravity): momentum is
// kept and kinetic energy never rises; with three balls the last one leaves at the striker's
// speed and the others stay (a Newton's cradle's). At 2b1aee5 the three ended at -0.5,
// -0.5 and 3.0 m/s (2.4 times the energy; five balls 3.7 times at the worst step): restitution took the
// approach speed the iteration had reached when a point first pushed, which held the warm
// start of the contact behind it, about to let go.
struct Row {
    std::vector<double> v;
    double worst_energy = 0;  // the most kinetic energy of any step, over the start's
};

Row struck_row(int balls) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    auto space = make_space(settings);
    std::vector<BodyHandle> row;
    for (int i = 0; i < balls; ++i) {
        BodyDesc d;
        d.shape = Shape::sphere(0.1);
        d.mass = 1;
        d.friction = 0;
        d.restitution = 1;
        d.position = Vec3(i == 0 ? -1.0 : 0.2 * (i - 1), 0, 0);
        if (i == 0) d.linear_velocity = Vec3(2, 0, 0);
        row.push_back(space->create_body(d));
    }
    Row out;
    for (int step = 0; step < 90; ++step) {
        space->update();
        double energy = 0;
        for (BodyHandle b : row) energy += 0.5 * space->internal_linear_velocity(b).squaredNorm();
        out.worst_energy = std::max(out.worst_energy, energy / 2.0);
    }
    for (BodyHandle b : row) out.v.push_back(space->internal_linear_velocity(b).x());
    return out;
}

TEST(OutsideBounce, BallStruckIntoTouchingBallsGainsNoEnergy) {
    const Row three = struck_row(3);
    std::printf("[ measure  ] three balls: %.3f %.3f %.3f m/s\n", three.v[0], three.v[1], three.v[2]);
    EXPECT_NEAR(three.v[0], 0, 0.02);
    EXPECT_NEAR(three.v[1], 0, 0.02);
    EXPECT_NEAR(three.v[2], 2, 0.02);
    for (int balls = 2; balls <= 6; ++balls) {
        const Row row = struck_row(balls);
        double momentum = 0;
        for (double v : row.v) momentum += v;
        std::printf("[ measure  ] %d balls: energy at most %.4f of the start's\n", balls, row.worst_energy);
        EXPECT_NEAR(momentum, 2, 1e-6) << balls << " balls";
        EXPECT_LT(row.worst_energy, 1.001) << balls << " balls";
    }
}

// The contact points a box coming down fast over a mesh makes lie under the box (within
// its footprint and a slop), whatever triangles are near. At ff39273, at 12 cm above the
// grid (a speculative manifold, closing at 6 m/s), two of the four points were at (0, -1)
// and (1, -1), mesh vertices over a metre from the box (x, z in 0.1..0.5): the SAT picked
// the box's bottom face against a neighbouring triangle, its clip left nothing, and
// face_manifold's fallback took that triangle's deepest vertex wherever it lay; the merge of
// same-normal manifolds then kept those far points for the area they span. Now against a
// mesh's triangle only a vertex over the box's face stands in (between hulls any still must:
// overlapping hulls were left without a manifold, ConvexConsistency and SatAxes).
TEST(OutsideMesh, ContactPointsOfABoxComingDownFastLieUnderIt) {
    auto space = make_space();
    add_floor(*space, Floor::Mesh, Quat::Identity(), 0.6);
    EventSettings events;
    events.publish_contact_points = true;
    space->set_events(events);
    const BodyHandle cube = add_box(*space, Vec3::Constant(0.2), Vec3(0.3, 2.2, 0.3));
    double worst = 0;
    std::vector<ContactPointInfo> points;
    for (int i = 0; i < 60; ++i) {
        space->update();
        space->read_contact_points(points);
        const Vec3 x = space->internal_position(cube);
        for (const ContactPointInfo& p : points) {
            worst = std::max(worst, std::max(std::abs(p.point.x() - x.x()), std::abs(p.point.z() - x.z())) - 0.2);
        }
    }
    std::printf("[ measure  ] box over a mesh: farthest contact point %.3f m outside its footprint\n", worst);
    EXPECT_LT(worst, 0.01);
}

// ---- Pendulums --------------------------------------------------------------------------------------
// A 1 kg ball of radius 0.1 on a 1.5 m arm, hung from a static body by a hinge and by a
// rigid distance joint, swung 0.1 rad: a physical pendulum,
// T = 2 pi sqrt((2/5 r^2 + L^2) / (g L)) (within 1 %: a clock a user would notice).
TEST(OutsidePendulum, HingeAndDistancePendulumsSwingAtTheirPeriod) {
    constexpr double kL = 1.5, kR = 0.1, kAmp = 0.1;
    const double period = 2 * kPi * std::sqrt((0.4 * kR * kR + kL * kL) / (kGravity * kL));
    for (bool hinge : {true, false}) {
        auto space = make_space();
        const BodyHandle pivot = add_static_box(*space, Vec3::Constant(0.05), Vec3(0, 3, 0));
        BodyDesc d;
        d.shape = Shape::sphere(kR);
        d.mass = 1;
        d.position = Vec3(0, 3, 0) + kL * Vec3(std::sin(kAmp), -std::cos(kAmp), 0);
        const BodyHandle bob = space->create_body(d);
        if (hinge) {
            space->create_joint(JointDesc::hinge_at(pivot, bob, Vec3(0, 3, 0), Vec3::UnitZ()));
        } else {
            space->create_joint(JointDesc::distance_between(pivot, bob, Vec3(0, 3, 0), d.position));
        }
        // Times the bob crosses x = 0 going the same way, interpolated within the step.
        std::vector<double> crossings;
        double x_prev = space->internal_position(bob).x();
        for (int i = 1; i <= 300; ++i) {
            space->update();
            const double x = space->internal_position(bob).x();
            if (x_prev > 0 && x <= 0) crossings.push_back((i - 1 + x_prev / (x_prev - x)) * kStep);
            x_prev = x;
        }
        ASSERT_GE(crossings.size(), 2u);
        const double measured = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
        std::printf("[ measure  ] %s pendulum: period %.4f s (analytic %.4f, %.2f %%)\n", hinge ? "hinge" : "distance",
                    measured, period, 100 * (measured / period - 1));
        EXPECT_NEAR(measured, period, 0.01 * period) << (hinge ? "hinge" : "distance");
    }
}

// Ten 1 kg capsule links on ball-socket joints hung from a static box at (0, 10, 0), `tilt`
// from straight down (about z), and a 100 kg ball of radius 0.2 on the last: the links,
// then the ball.
std::vector<BodyHandle> hang_heavy_chain(Space& space, double tilt) {
    constexpr int kLinks = 10;
    constexpr double kLink = 0.4;
    const Vec3 top(0, 10, 0);
    const Vec3 down(std::sin(tilt), -std::cos(tilt), 0);
    BodyHandle prev = add_static_box(space, Vec3::Constant(0.1), top);
    std::vector<BodyHandle> bodies;
    for (int i = 0; i < kLinks; ++i) {
        BodyDesc d;
        d.shape = Shape::capsule(0.15, 0.04);
        d.mass = 1;
        d.orientation = about_z(tilt);
        d.position = top + kLink * (i + 0.5) * down;
        const BodyHandle link = space.create_body(d);
        space.create_joint(JointDesc::ball_socket_at(prev, link, top + kLink * i * down));
        bodies.push_back(link);
        prev = link;
    }
    BodyDesc heavy;
    heavy.shape = Shape::sphere(0.2);
    heavy.mass = 100;
    heavy.position = top + (kLink * kLinks + 0.2) * down;
    const BodyHandle ball = space.create_body(heavy);
    space.create_joint(JointDesc::ball_socket_at(prev, ball, top + kLink * kLinks * down));
    bodies.push_back(ball);
    return bodies;
}

// A chain of ten 1 kg links holding a 100 kg ball at the default settings: it must hang
// still, no longer than 3 % over its length (soft joints stretch under load), and not
// jitter (under 1 cm/s at the end).
// Disabled: fails at 6118a81, a4df795 and c0f2223: after 4 s it is 3.76 % long and the ball
// still bounces up and down at 0.17 m/s (period 0.76 s). Two causes, found by trying (h42b):
// - The stretch is the soft joints' own, not the bounce: settled or mid-bounce, the chain
//   is 3.6 % long at 4, 8 or 16 substeps, 1 or 4 iterations, 1 to 4 relax iterations,
//   damping ratio 2 to 20. The model of SolverSettings::joint_hertz (a joint stretches
//   F / (m_eff (2 pi 60 Hz)^2), m_eff = 0.5 kg between two links) says 3.67 %, and
//   JointAccuracy.ThousandToOneChainStretchesAsItsSoftnessPredicts asserts that model, so
//   3 % at the default settings needs a stiffer joint model, not a tuning. The knob
//   works: 8 substeps with joint_hertz 0 (120 Hz) hold it to 0.92 %, ringing 0.008 m/s.
//   Dropping the soft rows' leak of the warm-started impulse (a rigid joint under the
//   soft bias: no stretch at rest) blows the chain up (44 m/s), as joint_softness says.
// - The bounce: the ball on eleven soft joints in series is a mass on a spring whose
//   damping ratio is the joints' (2) times sqrt(m_eff / (11 x 100 kg)), about 0.04, and
//   one rigid relax pass barely moves a 100 kg ball through 1 kg links. More relax
//   iterations damp it (2: 0.013 m/s, 3: 0.0009 m/s at 4 s; all contacts pay for them),
//   as does joint_damping_ratio 10 (0.0055 m/s), which makes every joint correct its error
//   more slowly: JointAccuracy.ChainHoldsAThousandToOneMassWithEightSubsteps fails (0.11 m
//   against 0.08; 0.082 m at ratio 4) and Distance.RigidRodKeepsItsLength at 10. A damping
//   scaled to the pair's mass ratio (not tried) would reach only the ball's own joint,
//   which carries 1/11 of the bounce.
// Support mass scaling for joints, as contacts have it (support_scales.cpp), tried in
// session 43 (h43b, not landed): in the joints' rows a body is made as heavy as the heaviest body it carries
// (farther from a static body by joint hops). It holds this chain to 0.209 % and still
// (0.0000 m/s), but it is no fix: scaling both bodies of a joint alike changes nothing,
// so in a chain only the ball's own joint changes, which solves the last link as if it
// weighed 100 kg; that link, and so the chain, then feels a hundredth of the ball's pull,
// and the chain, free of its load, moves the ball instead of the ball the chain.
// OutsidePendulum.DISABLED_HeavyBallSwungOnALightChainStaysShort shows it: swung from 40
// degrees the ball reaches 7.0 m/s at the bottom (4.4 m/s is all its drop gives), rises
// 0.40 m over its release and swings in 3.57 s (4.33 s unscaled). Scaling only the
// joint's lighter body gives the same numbers; with the relax pass at the real masses, it
// rises 0.38 m. Any scaling that keeps a light body from feeling the load it carries
// makes energy wherever that body moves along the load; a contact's support scaling
// stays on supported stacks, which barely move, and a swinging chain does not. What
// remains is solving a joint tree's rows together, exactly (a chain's block-tridiagonal
// system, as PhysX's articulations and Baraff's linear-time method do), not tried in the
// engine. In a one-dimensional model of this chain (h43b: the bodies on a vertical line,
// the engine's soft step, which with one Gauss-Seidel pass gives the engine's 3.764 % and
// 0.1741 m/s), solving each pass's rows exactly holds it to 2.47 % and still at the
// default softness, and to 0.02 % with each joint a spring for the mass below it.
TEST(OutsidePendulum, DISABLED_LightChainHoldsAHundredTimesHeavierEndMass) {
    auto space = make_space();
    const std::vector<BodyHandle> bodies = hang_heavy_chain(*space, 0);
    const double rest_y = space->internal_position(bodies.back()).y();
    step(*space, 240);
    const double stretch = (rest_y - space->internal_position(bodies.back()).y()) / 4.0;
    const double speed = max_speed(*space, bodies);
    std::printf("[ measure  ] chain of 10 x 1 kg holding 100 kg: stretched %.3f %%, fastest %.4f m/s\n", 100 * stretch,
                speed);
    EXPECT_TRUE(all_finite(*space, bodies));
    EXPECT_LT(std::abs(stretch), 0.03);
    EXPECT_LT(speed, 0.01);
}

// The same chain released 40 degrees out, a wrecking ball's swing: the chain must not
// stretch 3 % at the bottom of a swing (the ball's weight and its swing's pull), and the
// ball must never swing higher than it was released (no energy from the solver). Also
// prints its period (4.2 s for a rigid pendulum of the ball and the links at 40 degrees).
// Disabled: fails at c0f2223: 6.88 % long at the bottom of a swing (highest -0.07 m, 4.33 s
// a swing). The cause is the hanging chain's (above), with the swing's pull added. Support
// mass scaling for joints (above) holds it to 0.3 % but swings the ball up 0.40 m over its
// release, in 3.57 s.
TEST(OutsidePendulum, DISABLED_HeavyBallSwungOnALightChainStaysShort) {
    auto space = make_space();
    const std::vector<BodyHandle> bodies = hang_heavy_chain(*space, 40 * kPi / 180);
    const BodyHandle ball = bodies.back();
    const double release_y = space->internal_position(ball).y();
    double highest = -kHuge, longest = 0;
    bool past_bottom = false;
    std::vector<double> crossings;  // times the ball crosses x = 0, within the step
    double x_prev = space->internal_position(ball).x();
    for (int i = 0; i < 300; ++i) {
        space->update();
        const Vec3 x = space->internal_position(ball);
        if ((x_prev > 0) != (x.x() > 0)) crossings.push_back((i + x_prev / (x_prev - x.x())) * kStep);
        x_prev = x.x();
        past_bottom = past_bottom || x.x() < 0;
        if (past_bottom) highest = std::max(highest, x.y());
        longest = std::max(longest, ((x - Vec3(0, 10, 0)).norm() - 4.2) / 4.0);
    }
    const double period = crossings.size() < 2
                              ? 0
                              : 2 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
    std::printf("[ measure  ] 100 kg ball swung on 10 x 1 kg links: highest %.4f m over its release, longest %.3f %%, "
                "period %.3f s\n",
                highest - release_y, 100 * longest, period);
    EXPECT_TRUE(all_finite(*space, bodies));
    EXPECT_LT(highest, release_y);
    EXPECT_LT(longest, 0.03);
}

// A cantilever: ten 20 kg boxes (0.5 x 0.2 x 0.2 m) welded end to end by fixed joints, the
// first welded to a static wall, held out level. A welded beam must hold its shape: its tip
// within 10 cm of level (2 % of its 5 m) and still after 4 s.
// Disabled: found in session 43 by probing: the beam swings down 2.8 m and back with a 2 s
// period, decaying slowly (0.56-2.5 m at 2-6 s; five boxes 0.10 m; twenty fall 5.8 m). The
// soft joints' angular rows hold a moment at an angle of M / (I_eff w^2), with I_eff the two
// boxes' and w 2 pi 60 Hz at most: the wall's joint carries 4,900 N m at 0.14 rad. The same
// cause as the light chain's stretch above (a joint's stiffness from the two bodies it joins,
// not from the load it carries); 8 substeps or 3 relax iterations only damp the swing.
TEST(OutsidePendulum, DISABLED_WeldedCantileverHoldsItsShape) {
    auto space = make_space();
    BodyHandle prev = add_static_box(*space, Vec3(0.1, 1, 1), Vec3(-0.1, 5, 0));
    BodyHandle tip;
    for (int i = 0; i < 10; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.25, 0.1, 0.1));
        d.position = Vec3(0.25 + 0.5 * i, 5, 0);
        tip = space->create_body(d);
        space->create_joint(JointDesc::fixed_at(prev, tip, Vec3(0.5 * i, 5, 0)));
        prev = tip;
    }
    double sag = 0;
    for (int i = 0; i < 240; ++i) {
        space->update();
        sag = std::max(sag, 5 - space->internal_position(tip).y());
    }
    const double speed = space->internal_linear_velocity(tip).norm();
    std::printf("[ measure  ] welded cantilever: tip sagged at most %.3f m, %.3f m/s after 4 s\n", sag, speed);
    EXPECT_LT(sag, 0.1);
    EXPECT_LT(speed, 0.01);
}

// ---- Fast bodies -----------------------------------------------------------------------------------
// A small fast projectile (a 2 cm ball or a 1 cm x 4 cm capsule, `fast`) at 300 m/s
// against a static wall 2 cm thick and against a one-sided mesh wall (no thickness at
// all): it must end on the near side, never through.
TEST(OutsideFast, SmallProjectileAt300MetresPerSecondStopsAtAThinWall) {
    for (bool mesh : {false, true}) {
        for (bool capsule : {false, true}) {
            SpaceSettings settings;
            settings.gravity = Vec3::Zero();
            auto space = make_space(settings);
            BodyDesc wall;
            wall.type = MotionType::Static;
            if (mesh) {
                // The grid on y = 0 turned to face -x, at x = 5.
                wall.shape = test::flat_grid_mesh(4, 1.0);
                wall.orientation = about_z(kPi / 2);
                wall.position = Vec3(5, 0, 0);
            } else {
                wall.shape = Shape::box(Vec3(0.01, 2, 2));
                wall.position = Vec3(5, 0, 0);
            }
            space->create_body(wall);
            BodyDesc d;
            d.shape = capsule ? Shape::capsule(0.02, 0.005) : Shape::sphere(0.01);
            d.orientation = about_z(kPi / 2 + 0.3);
            d.position = Vec3(-3, 0.13, -0.21);
            d.linear_velocity = Vec3(300, 0, 0);
            d.fast = true;
            const BodyHandle bullet = space->create_body(d);
            double furthest = -kHuge;
            for (int i = 0; i < 10; ++i) {
                space->update();
                furthest = std::max(furthest, space->internal_position(bullet).x());
            }
            std::printf("[ measure  ] %s at 300 m/s into a %s wall at x = 5: furthest x %.4f\n",
                        capsule ? "capsule" : "ball", mesh ? "mesh" : "2 cm box", furthest);
            EXPECT_LT(furthest, mesh ? 5.0 : 4.99) << (capsule ? "capsule" : "ball") << (mesh ? " mesh" : " box");
        }
    }
}

// ---- Sleeping -----------------------------------------------------------------------------------------
// Bodies asleep on a floor that goes away must fall: destroyed, made dynamic, or a
// kinematic floor moved away. And a sleeping cube hit by a ball wakes and moves.
TEST(OutsideSleep, SleepersFallWhenTheirFloorGoes) {
    enum How { Destroyed, MadeDynamic, KinematicMovedAway, MiddleOfAStackDestroyed };
    for (How how : {Destroyed, MadeDynamic, KinematicMovedAway, MiddleOfAStackDestroyed}) {
        Space space{SpaceSettings{}};                                 // sleeping on
        add_static_box(space, Vec3(20, 0.5, 20), Vec3(0, -10.5, 0));  // something far below
        BodyDesc f;
        f.type = how == KinematicMovedAway ? MotionType::Kinematic : MotionType::Static;
        f.shape = Shape::box(Vec3(3, 0.25, 3));
        f.position = Vec3(0, -0.25, 0);
        const BodyHandle floor = space.create_body(f);
        const std::vector<BodyHandle> cubes = add_cube_stack(space, 3, Vec3(0.2, 0, 0));
        step(space, 120);
        bool asleep = true;
        for (BodyHandle c : cubes) asleep = asleep && !space.internal_is_awake(c);
        ASSERT_TRUE(asleep) << "how " << how;
        BodyHandle top = cubes.back();
        switch (how) {
            case Destroyed: space.destroy_body(floor); break;
            case MadeDynamic: space.set_motion_type(floor, MotionType::Dynamic); break;
            case KinematicMovedAway: space.move_kinematic(floor, Vec3(0, -3, 0), Quat::Identity()); break;
            case MiddleOfAStackDestroyed: space.destroy_body(cubes[1]); break;
        }
        const double y0 = space.internal_position(top).y();
        step(space, 30);
        const double fell = y0 - space.internal_position(top).y();
        // Half a second of free fall is 1.2 m (a floor made dynamic falls with them); the
        // stack with its middle gone falls 1 m onto the cube below.
        std::printf("[ measure  ] sleepers, floor gone (how %d): top fell %.3f m in 0.5 s\n", how, fell);
        EXPECT_GT(fell, how == MiddleOfAStackDestroyed ? 0.9 : 1.0) << "how " << how;
    }
}

TEST(OutsideSleep, ASleepingCubeHitByABallWakesAndMoves) {
    Space space{SpaceSettings{}};
    test::add_ground_plane(space);
    const BodyHandle cube = add_box(space, Vec3::Constant(0.5), Vec3(0, 0.5, 0));
    step(space, 90);
    ASSERT_FALSE(space.internal_is_awake(cube));
    BodyDesc d;
    d.shape = Shape::sphere(0.3);
    d.density = 5000;
    d.position = Vec3(-5, 0.3, 0);
    d.linear_velocity = Vec3(8, 0, 0);
    space.create_body(d);
    step(space, 90);
    const double moved = space.internal_position(cube).x();
    std::printf("[ measure  ] sleeping cube hit by a ball: moved %.3f m\n", moved);
    EXPECT_GT(moved, 0.2);
}

}  // namespace spindle::stability::outside
