// The accuracy cases: stacks and a column, mass ratios, free flight, spinning boxes, a bounce,
// joints, a rolling ball and a thin box at rest, each with its ideal answer written next to
// it. Sleeping is off everywhere, so every setting pays for (and is judged on) every step it
// simulates.
#include "accuracy/cases.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>
#include <vector>

#include <spindle/engine/joint.hpp>
#include <spindle/engine/space.hpp>

namespace spindle::bench {

std::string Setting::label() const {
    char text[48];
    if (contact_hertz > 0) {
        std::snprintf(text, sizeof text, "%dx%d @1/%d %g Hz", substeps, iterations, step_hz, contact_hertz);
    } else {
        std::snprintf(text, sizeof text, "%dx%d @1/%d", substeps, iterations, step_hz);
    }
    return text;
}

namespace {

constexpr Real kGravity = 9.81;
// The error a case reports when the simulation blew up (NaN): off the chart, but plottable.
constexpr double kDiverged = 1e3;

// A single-threaded Space under one setting that times its own steps.
class TimedSpace {
public:
    TimedSpace(const Setting& setting, const Vec3& gravity)
        : m_space(make_settings(setting, gravity)), m_dt(setting.dt()) {}

    Space& space() { return m_space; }
    void step() {
        const auto start = std::chrono::steady_clock::now();
        m_space.update();
        m_step_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ++m_steps;
    }
    Real time() const { return m_steps * m_dt; }
    // Steps for `seconds` of simulation, rounded: every dt of the sweep divides the durations used.
    int steps_for(Real seconds) const { return static_cast<int>(std::lround(seconds / m_dt)); }
    // A run that blew up (NaN) reports kDiverged: off the chart, but plottable.
    CaseRun result(double error) const {
        return {std::isfinite(error) ? error : kDiverged, m_step_seconds, m_steps * m_dt};
    }

private:
    static SpaceSettings make_settings(const Setting& setting, const Vec3& gravity) {
        SpaceSettings s;
        s.gravity = gravity;
        s.time_step.duration = setting.dt();
        s.solver.substeps = setting.substeps;
        s.solver.iterations = setting.iterations;
        s.solver.contact_hertz = setting.contact_hertz;
        s.sleep.enabled = false;  // a sleeping stack would stop drifting and stop costing
        return s;
    }

    Space m_space;
    Real m_dt;
    double m_step_seconds = 0;
    int m_steps = 0;
};

// Static floor box whose top face is y = 0.
void add_floor(Space& space) {
    BodyDesc floor;
    floor.type = MotionType::Static;
    floor.shape = Shape::box(Vec3(20, 1, 20));
    floor.position = Vec3(0, -1, 0);
    space.create_body(floor);
}

// Static plane y = 0: the other kind of ground, with its own manifold code.
void add_plane(Space& space) {
    BodyDesc plane;
    plane.type = MotionType::Static;
    plane.shape = Shape::plane(Vec3::UnitY(), 0);
    space.create_body(plane);
}

BodyHandle add_body(Space& space, const Shape& shape, const Vec3& position) {
    BodyDesc desc;
    desc.shape = shape;
    desc.position = position;
    desc.allow_sleep = false;
    desc.allow_interpolation = false;  // the cases read internal state; nothing to blend
    return space.create_body(desc);
}

// Ten unit cubes (half extent 0.5) standing touching on the floor; returns the top one.
constexpr int kStackBoxes = 10;
constexpr Real kStackSeconds = 5;
const Vec3 kStackTopIdeal(0, kStackBoxes - 0.5, 0);

BodyHandle add_stack(Space& space) {
    add_floor(space);
    BodyHandle top;
    for (int i = 0; i < kStackBoxes; ++i) top = add_body(space, Shape::box(Vec3::Constant(0.5)), Vec3(0, 0.5 + i, 0));
    return top;
}

// Stack drift: the worst the top box strays from where a rigid stack holds it.
CaseRun stack_drift(const Setting& setting) {
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    const BodyHandle top = add_stack(t.space());
    double worst = 0;
    for (int n = t.steps_for(kStackSeconds); n > 0; --n) {
        t.step();
        worst = std::max(worst, (t.space().internal_position(top) - kStackTopIdeal).norm());
    }
    return t.result(worst);
}

// Penetration at rest: how far the top box sits below its ideal height over the last
// second, the sum of the ten contacts' overlaps (soft contacts compress under load).
CaseRun stack_sink(const Setting& setting) {
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    const BodyHandle top = add_stack(t.space());
    const int steps = t.steps_for(kStackSeconds);
    const int measured = t.steps_for(1);
    double sink = 0;
    for (int n = 0; n < steps; ++n) {
        t.step();
        if (n >= steps - measured) sink += kStackTopIdeal.y() - t.space().internal_position(top).y();
    }
    return t.result(std::abs(sink / measured));
}

// Mass ratio 100: a heavy plank on three light cubes, where an iterative solver lets the
// heavy body press into the light ones. Error: the plank's sink below its ideal height
// over the last second of three.
CaseRun mass_ratio(const Setting& setting) {
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    Space& space = t.space();
    add_floor(space);
    constexpr Real kCube = 0.25;
    for (int i = -1; i <= 1; ++i) {
        BodyDesc cube;
        cube.shape = Shape::box(Vec3::Constant(kCube));
        cube.position = Vec3(1.2 * i, kCube, 0);
        cube.mass = 1;
        cube.allow_sleep = false;
        space.create_body(cube);
    }
    BodyDesc plank;
    plank.shape = Shape::box(Vec3(1.8, 0.25, 0.5));
    plank.mass = 300;  // 100 times the three cubes together
    plank.position = Vec3(0, 2 * kCube + 0.25, 0);
    plank.allow_sleep = false;
    const BodyHandle heavy = space.create_body(plank);
    const Real ideal = plank.position.y();
    const int steps = t.steps_for(3);
    const int measured = t.steps_for(1);
    double sink = 0;
    for (int n = 0; n < steps; ++n) {
        t.step();
        if (n >= steps - measured) sink += ideal - space.internal_position(heavy).y();
    }
    return t.result(std::abs(sink / measured));
}

// Spheres dropped from about 10 m (restitution 0): each meets the ground at sqrt(2h/g),
// and a rigid ground never lets one sink. Whether a step happens to start just above the
// ground is luck, so five balls start 0 to 0.24 m higher (about a step's fall at 1/60 s)
// and the worst of them is the error.
enum class DropMetric { ContactTime, Penetration };

CaseRun drop(const Setting& setting, DropMetric metric) {
    constexpr int kBalls = 5;
    constexpr Real kHeight = 10, kSpread = 0.06, kRadius = 0.5;
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_floor(t.space());
    struct Ball {
        BodyHandle handle;
        Real exact = 0;  // analytic contact time
        Real previous_vy = 0;
        std::optional<Real> contact;
    };
    std::vector<Ball> balls;
    for (int i = 0; i < kBalls; ++i) {
        const Real height = kHeight + kSpread * i;
        balls.push_back({add_body(t.space(), Shape::sphere(kRadius), Vec3(2.0 * i, height + kRadius, 0)),
                         std::sqrt(2 * height / kGravity), 0, std::nullopt});
    }
    Real deepest = 0;
    // A second after the last landing: time for the push-out to lift a sunk ball back.
    for (int n = t.steps_for(balls.back().exact + 1); n > 0; --n) {
        t.step();
        for (Ball& ball : balls) {
            const Real vy = t.space().internal_linear_velocity(ball.handle).y();
            deepest = std::max(deepest, kRadius - t.space().internal_position(ball.handle).y());
            // Free fall only ever speeds a ball up (half a step's gravity of slack ignores rounding),
            // so the first step that slows it is the contact, seen at step resolution.
            if (!ball.contact && vy > ball.previous_vy - 0.5 * kGravity * setting.dt()) ball.contact = t.time();
            ball.previous_vy = vy;
        }
    }
    if (metric == DropMetric::Penetration) return t.result(deepest);
    Real worst = 0;
    for (const Ball& ball : balls)
        worst = std::max(worst, ball.contact ? std::abs(*ball.contact - ball.exact) : ball.exact);
    return t.result(worst);
}

CaseRun free_fall(const Setting& setting) { return drop(setting, DropMetric::ContactTime); }
CaseRun drop_penetration(const Setting& setting) { return drop(setting, DropMetric::Penetration); }

// Projectile: a sphere thrown at (5, 10, 3) m/s without ground, against the exact
// parabola after 2 s. Semi-implicit Euler is off by g t h / 2 (h the substep).
CaseRun projectile(const Setting& setting) {
    constexpr Real kSeconds = 2;
    const Vec3 start(0, 0, 0), velocity(5, 10, 3), gravity(0, -kGravity, 0);
    TimedSpace t(setting, gravity);
    BodyDesc desc;
    desc.shape = Shape::sphere(0.5);
    desc.linear_velocity = velocity;
    desc.allow_sleep = false;
    desc.allow_interpolation = false;
    const BodyHandle ball = t.space().create_body(desc);
    for (int n = t.steps_for(kSeconds); n > 0; --n) t.step();
    const Real time = t.time();
    const Vec3 exact = start + velocity * time + 0.5 * gravity * time * time;
    return t.result((t.space().internal_position(ball) - exact).norm());
}

// A free box spun about its intermediate axis, y (the unstable one: it tumbles over and
// back, the Dzhanibekov effect), no gravity, gyroscopic torque on; a small push off the
// axis starts the tumble. Free rotation keeps both its kinetic energy and its world
// angular momentum.
class SpinningBox {
public:
    SpinningBox(Space& space, const Vec3& half_extents) {
        BodyDesc desc;
        desc.shape = Shape::box(half_extents);  // x < y < z, so y is the intermediate axis
        desc.angular_velocity = Vec3(0.02, 6, 0.02);
        desc.gyroscopic = true;
        desc.allow_sleep = false;
        desc.allow_interpolation = false;
        m_box = space.create_body(desc);
        m_inertia_local = desc.shape.mass_properties(desc.density).inertia;
    }
    Vec3 angular_velocity(const Space& space) const { return space.internal_angular_velocity(m_box); }
    Vec3 angular_momentum(const Space& space) const {
        const Mat3 r = space.internal_orientation(m_box).toRotationMatrix();
        return r * m_inertia_local * r.transpose() * angular_velocity(space);
    }
    Real energy(const Space& space) const { return 0.5 * angular_velocity(space).dot(angular_momentum(space)); }

private:
    BodyHandle m_box;
    Mat3 m_inertia_local;
};

// The size of a scalar's or a vector's change.
double size_of(double x) { return std::abs(x); }
double size_of(const Vec3& v) { return v.norm(); }

// The worst relative change of a quantity from its initial value over `seconds` of steps.
template <class Quantity>
double worst_relative_change(TimedSpace& t, int seconds, Quantity quantity) {
    const auto initial = quantity();
    double worst = 0;
    for (int n = t.steps_for(seconds); n > 0; --n) {
        t.step();
        worst = std::max(worst, size_of(quantity() - initial) / size_of(initial));
    }
    return worst;
}

// Energy drift: the worst relative change of a spinning 0.2 x 0.5 x 0.8 m box's kinetic
// energy in 10 s.
CaseRun spin_energy(const Setting& setting) {
    TimedSpace t(setting, Vec3::Zero());
    const SpinningBox box(t.space(), Vec3(0.1, 0.25, 0.4));
    return t.result(worst_relative_change(t, 10, [&] { return box.energy(t.space()); }));
}

// Bounce: a sphere with restitution 1 dropped from 5 m keeps bouncing back to 5 m. The
// error is the 5th apex's relative shortfall (1 when the ball stops bouncing before it).
CaseRun bounce(const Setting& setting) {
    constexpr Real kHeight = 5, kRadius = 0.5;
    constexpr int kApex = 5;
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_floor(t.space());
    BodyDesc desc;
    desc.shape = Shape::sphere(kRadius);
    desc.position = Vec3(0, kHeight + kRadius, 0);
    desc.restitution = 1;
    desc.allow_sleep = false;
    desc.allow_interpolation = false;
    const BodyHandle ball = t.space().create_body(desc);
    // Each bounce takes 2 sqrt(2h/g) = 2.02 s; the 5th apex comes at about 10.1 s.
    const Real bounce_seconds = 2 * std::sqrt(2 * kHeight / kGravity);
    int apexes = 0;
    Real previous_vy = 0, previous_y = desc.position.y();
    for (int n = t.steps_for((kApex + 1) * bounce_seconds); n > 0; --n) {
        t.step();
        const Real vy = t.space().internal_linear_velocity(ball).y();
        const Real y = t.space().internal_position(ball).y();
        if (previous_vy > 0 && vy <= 0 && ++apexes == kApex) {
            const Real apex = std::max(previous_y, y) - kRadius;
            return t.result(std::abs(apex - kHeight) / kHeight);
        }
        previous_vy = vy;
        previous_y = y;
    }
    return t.result(1);
}

// Pendulum: a 1 kg ball (radius 5 cm) on a 1 m ball-socket joint released at 1 rad. Its
// exact period is the physical pendulum's, 2 pi sqrt(I / m g L), stretched for the
// amplitude by the arithmetic-geometric mean: T = T0 / agm(1, cos(theta0 / 2)). The period
// is measured over 10 s from interpolated zero crossings; the error is relative.
Real agm(Real a, Real b) {
    for (int i = 0; i < 8; ++i) {  // converges quadratically: 8 rounds is beyond double precision
        const Real m = (a + b) / 2;
        b = std::sqrt(a * b);
        a = m;
    }
    return a;
}

BodyHandle add_static_point(Space& space, const Vec3& position) {
    BodyDesc anchor;
    anchor.type = MotionType::Static;
    anchor.shape = Shape::sphere(0.05);
    anchor.position = position;
    return space.create_body(anchor);
}

CaseRun pendulum(const Setting& setting) {
    constexpr Real kLength = 1, kTheta0 = 1, kRadius = 0.05, kMass = 1;
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    Space& space = t.space();
    const Vec3 pivot(0, 2, 0);
    const BodyHandle anchor = add_static_point(space, pivot);
    BodyDesc bob;
    bob.shape = Shape::sphere(kRadius);
    bob.mass = kMass;
    bob.position = pivot + kLength * Vec3(std::sin(kTheta0), -std::cos(kTheta0), 0);
    bob.allow_sleep = false;
    bob.allow_interpolation = false;
    const BodyHandle ball = space.create_body(bob);
    space.create_joint(JointDesc::ball_socket_at(anchor, ball, pivot));

    const Real inertia_at_pivot = kMass * kLength * kLength + 0.4 * kMass * kRadius * kRadius;
    const Real exact = 2 * kPi * std::sqrt(inertia_at_pivot / (kMass * kGravity * kLength)) /
                       agm(1, std::cos(kTheta0 / 2));
    std::vector<Real> crossings;
    Real previous = bob.position.x() - pivot.x();
    for (int n = 0, steps = t.steps_for(10); n < steps; ++n) {
        t.step();
        const Real x = space.internal_position(ball).x() - pivot.x();
        if (!std::isfinite(x)) return t.result(1);
        if ((previous < 0) != (x < 0)) crossings.push_back(setting.dt() * (n + previous / (previous - x)));
        previous = x;
    }
    if (crossings.size() < 3) return t.result(1);  // it stopped swinging: wrong by a whole period
    const Real period = 2 * (crossings.back() - crossings.front()) / static_cast<Real>(crossings.size() - 1);
    return t.result(std::abs(period - exact) / exact);
}

// Joint error: ten 25 cm, 1 kg bars on ball-socket joints with a 100 kg ball at the end,
// released horizontally so the load whips through the bottom of the swing. Rigid joints
// keep every anchor pair together; the error is the worst separation in 3 s.
CaseRun chain_joint_error(const Setting& setting) {
    constexpr int kLinks = 10;
    constexpr Real kSpacing = 0.25, kBallRadius = 0.1;
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    Space& space = t.space();
    const Vec3 top(0, 5, 0);
    BodyHandle previous = add_static_point(space, top);
    std::vector<JointHandle> joints;
    for (int i = 0; i <= kLinks; ++i) {
        BodyDesc d;
        if (i < kLinks) {
            d.shape = Shape::box(Vec3(kSpacing / 2, 0.02, 0.02));
            d.position = top + Vec3(kSpacing * (i + 0.5), 0, 0);
            d.mass = 1;
        } else {
            d.shape = Shape::sphere(kBallRadius);
            d.position = top + Vec3(kSpacing * kLinks + kBallRadius, 0, 0);
            d.mass = 100;
        }
        d.allow_sleep = false;
        d.allow_interpolation = false;
        const BodyHandle body = space.create_body(d);
        joints.push_back(space.create_joint(JointDesc::ball_socket_at(previous, body, top + Vec3(kSpacing * i, 0, 0))));
        previous = body;
    }
    double worst = 0;
    for (int n = t.steps_for(3); n > 0; --n) {
        t.step();
        for (JointHandle j : joints) {
            const double error = space.internal_joint_error(j).linear;
            if (!std::isfinite(error)) return t.result(kDiverged);
            worst = std::max(worst, error);
        }
    }
    return t.result(worst);
}

// Rolling: a ball (radius 0.5) launched sliding at 6 m/s without spin. Friction slows it
// and spins it up until it rolls at 5/7 of the launch speed (its angular momentum about the
// contact point is kept), 2 v / (7 mu g) = 0.29 s after launch; then nothing slows it.
// Measured over 2 s: the final speed, or the deepest it sinks into the floor while rolling.
enum class RollMetric { Speed, Sink };

CaseRun roll(const Setting& setting, RollMetric metric) {
    constexpr Real kRadius = 0.5, kLaunch = 6;
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_floor(t.space());
    BodyDesc desc;
    desc.shape = Shape::sphere(kRadius);
    desc.position = Vec3(-6, kRadius, 0);  // ends about 9 m further, well on the floor
    desc.linear_velocity = Vec3(kLaunch, 0, 0);
    desc.allow_sleep = false;
    desc.allow_interpolation = false;
    const BodyHandle ball = t.space().create_body(desc);
    Real deepest = 0;
    for (int n = t.steps_for(2); n > 0; --n) {
        t.step();
        deepest = std::max(deepest, kRadius - t.space().internal_position(ball).y());
    }
    if (metric == RollMetric::Sink) return t.result(1000 * deepest);
    const Vec3 v = t.space().internal_linear_velocity(ball);
    return t.result(std::abs(std::hypot(v.x(), v.z()) - kLaunch * 5 / 7));
}

CaseRun rolling_speed(const Setting& setting) { return roll(setting, RollMetric::Speed); }
CaseRun rolling_sink(const Setting& setting) { return roll(setting, RollMetric::Sink); }

// Thin box at rest: a 7.5 x 1.5 x 2.5 cm block of pine (700 kg/m^3) set flat on a plane. It
// is thinner than the speculative distance, so its top corners are within reach of the
// plane too; a manifold that takes one of them tilts the block. At rest it neither moves
// nor sinks: the error is its horizontal creep plus its height error after 2 s, in mm.
CaseRun thin_box(const Setting& setting) {
    const Vec3 half(0.0375, 0.0075, 0.0125);
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_plane(t.space());
    BodyDesc desc;
    desc.shape = Shape::box(half);
    desc.position = Vec3(0, half.y(), 0);
    desc.density = 700;
    desc.allow_sleep = false;
    desc.allow_interpolation = false;
    const BodyHandle box = t.space().create_body(desc);
    for (int n = t.steps_for(2); n > 0; --n) t.step();
    const Vec3 moved = t.space().internal_position(box) - desc.position;
    return t.result(1000 * (std::hypot(moved.x(), moved.z()) + std::abs(moved.y())));
}

// Creep: static friction keeps a body at rest where it settled, so none of `bodies` (all
// built resting, unit cubes or 1 m thick) moves sideways after `settle` seconds. Steps to
// `seconds` and returns the furthest any strays horizontally from its position at `settle`,
// or, when further, how far one ends below where it was built once that passes half its
// height: it went through what held it, maybe before `settle`, and a fallen stack lies still.
double worst_creep(TimedSpace& t, std::span<const BodyHandle> bodies, Real settle, Real seconds) {
    constexpr Real kHalfHeight = 0.5;
    std::vector<Vec3> built, settled;
    for (BodyHandle b : bodies) built.push_back(t.space().internal_position(b));
    for (int n = t.steps_for(settle); n > 0; --n) t.step();
    for (BodyHandle b : bodies) settled.push_back(t.space().internal_position(b));
    double worst = 0;
    for (int n = t.steps_for(seconds) - t.steps_for(settle); n > 0; --n) {
        t.step();
        for (std::size_t i = 0; i < bodies.size(); ++i) {
            const Vec3 moved = t.space().internal_position(bodies[i]) - settled[i];
            const double drift = std::hypot(moved.x(), moved.z());
            if (!std::isfinite(drift)) return kDiverged;
            worst = std::max(worst, drift);
        }
    }
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        const double fall = built[i].y() - t.space().internal_position(bodies[i]).y();
        if (fall > kHalfHeight) worst = std::max(worst, fall);
    }
    return worst;
}

// Creep under a heavy body: the mass_ratio scene's 1000 kg slab (6 x 1 x 6 m) on four 1 kg
// unit cubes at its corners, on a plane. Error: the furthest any of the five drifts
// horizontally between 1 s and 10 s (or falls: worst_creep).
CaseRun slab_creep(const Setting& setting) {
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    Space& space = t.space();
    add_plane(space);
    std::vector<BodyHandle> bodies;
    for (Real x : {-2, 2}) {
        for (Real z : {-2, 2}) {
            BodyDesc cube;
            cube.shape = Shape::box(Vec3::Constant(0.5));
            cube.position = Vec3(x, 0.5, z);
            cube.mass = 1;
            cube.allow_sleep = false;
            cube.allow_interpolation = false;
            bodies.push_back(space.create_body(cube));
        }
    }
    BodyDesc slab;
    slab.shape = Shape::box(Vec3(3, 0.5, 3));
    slab.position = Vec3(0, 1.5, 0);
    slab.mass = 1000;
    slab.allow_sleep = false;
    slab.allow_interpolation = false;
    bodies.push_back(space.create_body(slab));
    return t.result(worst_creep(t, bodies, 1, 10));
}

// Angular momentum: a spinning 2 x 1 x 0.5 m box for 20 s. It flips over and back every
// few seconds while its world angular momentum R I R^T w stays what it was. Error: the worst
// relative change of that vector (which bounds the change of its magnitude), in percent.
CaseRun spin_momentum(const Setting& setting) {
    TimedSpace t(setting, Vec3::Zero());
    const SpinningBox box(t.space(), Vec3(1, 0.5, 0.25));
    return t.result(100 * worst_relative_change(t, 20, [&] { return box.angular_momentum(t.space()); }));
}

// A column of 30 unit cubes standing touching on the floor: the taller the column, the less
// it takes to lean it over, so the contacts must hold each cube where it stands on the one
// below. Error: the top cube's furthest horizontal drift between 1 s and 15 s (or its fall:
// worst_creep).
CaseRun column_drift(const Setting& setting) {
    constexpr int kCubes = 30;
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_floor(t.space());
    BodyHandle top;
    for (int i = 0; i < kCubes; ++i) top = add_body(t.space(), Shape::box(Vec3::Constant(0.5)), Vec3(0, 0.5 + i, 0));
    return t.result(worst_creep(t, std::span(&top, 1), 1, 15));
}

// Heavy on light: 1, 100 and 10,000 kg unit cubes stacked heaviest on top on a box floor
// (issue 16). A soft contact's stiffness follows its effective mass, which the light
// body dominates, so without support mass scaling (support_scales.cpp) the 1 kg cube is
// squeezed out. Error: the worst distance of any cube from its ideal place (resting
// exactly on the one below) over the last 2 s of 3.
CaseRun heavy_stack(const Setting& setting) {
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_floor(t.space());
    std::vector<BodyHandle> cubes;
    const Real masses[] = {1, 100, 10000};
    for (int i = 0; i < 3; ++i) {
        BodyDesc cube;
        cube.shape = Shape::box(Vec3::Constant(0.5));
        cube.position = Vec3(0, 0.5 + i, 0);
        cube.mass = masses[i];
        cube.allow_sleep = false;
        cube.allow_interpolation = false;
        cubes.push_back(t.space().create_body(cube));
    }
    const int steps = t.steps_for(3);
    const int first_measured = steps - t.steps_for(2);
    double worst = 0;
    for (int n = 0; n < steps; ++n) {
        t.step();
        if (n < first_measured) continue;
        for (int i = 0; i < 3; ++i) {
            const double off =
                (t.space().internal_position(cubes[static_cast<std::size_t>(i)]) - Vec3(0, 0.5 + i, 0)).norm();
            if (!std::isfinite(off)) return t.result(off);
            worst = std::max(worst, off);
        }
    }
    return t.result(worst);
}

// A thin semicircular arch of 21 voussoirs (hulls between radii 2 and 2.3 m, 1 m deep,
// 2,500 kg/m^3, friction 0.6) built touching on a box floor, as Delicate's thin arch in
// tests/stability: a rigid arch stands without sagging, and a soft-contact one sags as
// its joints compress under the thrust, as one over the contact stiffness squared.
// Error: the keystone's worst sag over 5 s (about 2 m if the arch falls).
CaseRun arch_sag(const Setting& setting) {
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_floor(t.space());
    constexpr int kStones = 21;
    constexpr Real kInner = 2, kOuter = 2.3;
    BodyHandle keystone;
    for (int i = 0; i < kStones; ++i) {
        const Real from = i * kPi / kStones, to = (i + 1) * kPi / kStones, mid = (from + to) / 2;
        const Vec3 origin = (kInner + kOuter) / 2 * Vec3(std::cos(mid), std::sin(mid), 0);
        std::vector<Vec3> corners;
        for (Real r : {kInner, kOuter}) {
            for (Real angle : {from, to}) {
                for (Real z : {-0.5, 0.5})
                    corners.push_back(Vec3(r * std::cos(angle), r * std::sin(angle), z) - origin);
            }
        }
        BodyDesc stone;
        stone.shape = Shape::convex_hull(corners);
        stone.position = origin;
        stone.density = 2500;
        stone.allow_sleep = false;
        stone.allow_interpolation = false;
        const BodyHandle body = t.space().create_body(stone);
        if (i == kStones / 2) keystone = body;
    }
    const Real built = t.space().internal_position(keystone).y();
    double worst = 0;
    const int steps = t.steps_for(5);
    for (int n = 0; n < steps; ++n) {
        t.step();
        const double sag = built - t.space().internal_position(keystone).y();
        if (!std::isfinite(sag)) return t.result(sag);
        worst = std::max(worst, sag);
    }
    return t.result(worst);
}

constexpr Case kCases[] = {
    {"stack_drift", "10-box stack, 5 s: worst distance of the top box from its ideal position", "m", stack_drift},
    {"stack_sink", "10-box stack at rest: top box below its ideal height (last 1 s of 5)", "m", stack_sink},
    {"mass_ratio", "300 kg plank on three 1 kg cubes: plank below its ideal height (last 1 s of 3)", "m", mass_ratio},
    {"free_fall", "five spheres dropped 10-10.24 m: worst first-contact time against sqrt(2h/g)", "s", free_fall},
    {"drop_penetration", "five spheres dropped 10-10.24 m: deepest any sinks into the ground", "m", drop_penetration},
    {"projectile", "sphere thrown, no ground: position against the exact parabola after 2 s", "m", projectile},
    {"spin_energy", "box spun about its intermediate axis, gyroscopic, 10 s: worst relative change of kinetic energy",
     "rel", spin_energy},
    {"pendulum",
     "1 m ball-socket pendulum released at 1 rad: relative period error over 10 s (exact: physical pendulum, AGM "
     "amplitude correction)",
     "rel", pendulum},
    {"chain_joint_error",
     "ten 1 kg bars and a 100 kg ball on ball-socket joints, released horizontally, 3 s: worst anchor separation", "m",
     chain_joint_error},
    {"bounce", "sphere, restitution 1, dropped 5 m: relative error of the 5th apex height", "rel", bounce},
    {"rolling_speed",
     "ball of radius 0.5 launched sliding at 6 m/s without spin on a box floor: speed after 2 s against 5/7 of 6 m/s",
     "m/s", rolling_speed},
    {"rolling_sink", "the same ball, 2 s: deepest it sinks below the floor while sliding and rolling", "mm",
     rolling_sink},
    {"thin_box", "7.5 x 1.5 x 2.5 cm box (700 kg/m³) set flat on a plane: horizontal creep plus height error after 2 s",
     "mm", thin_box},
    {"slab_creep",
     "1000 kg slab on four 1 kg cubes on a plane: furthest any body drifts horizontally from its place at 1 s, to 10 s "
     "(or how far one fell, if it ends more than 0.5 m below where it was built)",
     "m", slab_creep},
    {"spin_momentum",
     "free 2 x 1 x 0.5 m box spun about its intermediate axis, gyroscopic, 20 s: worst change of its angular "
     "momentum vector, relative",
     "%", spin_momentum},
    {"column_drift",
     "30 unit cubes in a column on a box floor: top cube's furthest horizontal drift from its place at 1 s, to 15 s "
     "(or how far it fell, if it ends more than 0.5 m below where it was built)",
     "m", column_drift},
    {"heavy_stack",
     "1, 100 and 10,000 kg unit cubes stacked heaviest on top on a box floor: worst distance of any cube from its "
     "ideal place over the last 2 s of 3",
     "m", heavy_stack},
    {"arch_sag",
     "thin arch of 21 voussoirs (radii 2-2.3 m, 1 m deep, 240 kg each) on a box floor: the keystone's worst sag over "
     "5 s",
     "m", arch_sag},
};

}  // namespace

std::span<const Case> accuracy_cases() { return kCases; }

}  // namespace spindle::bench
