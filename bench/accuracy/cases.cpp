// The accuracy cases: stacks, a mass ratio, free flight, a spinning box and a bounce, each
// with its ideal answer written next to it. Sleeping is off everywhere, so every setting
// pays for (and is judged on) every step it simulates.
#include "accuracy/cases.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <spindle/engine/space.hpp>

namespace spindle::bench {

std::string Setting::label() const {
    char text[48];
    std::snprintf(text, sizeof text, "%dx%d @1/%d", substeps, iterations, step_hz);
    return text;
}

namespace {

constexpr Real kGravity = 9.81;

// A single-threaded Space under one setting that times its own steps.
class TimedSpace {
public:
    TimedSpace(const Setting& setting, const Vec3& gravity) : m_space(make_settings(setting, gravity)), m_dt(setting.dt()) {}

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
    CaseRun result(double error) const { return {error, m_step_seconds, m_steps * m_dt}; }

private:
    static SpaceSettings make_settings(const Setting& setting, const Vec3& gravity) {
        SpaceSettings s;
        s.gravity = gravity;
        s.time_step.duration = setting.dt();
        s.solver.substeps = setting.substeps;
        s.solver.iterations = setting.iterations;
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

// Free fall: a sphere dropped from 10 m (restitution 0) meets the ground at sqrt(2h/g).
// The contact is seen at step resolution: the first step that slows the fall.
CaseRun free_fall(const Setting& setting) {
    constexpr Real kHeight = 10, kRadius = 0.5;
    TimedSpace t(setting, Vec3(0, -kGravity, 0));
    add_floor(t.space());
    const BodyHandle ball = add_body(t.space(), Shape::sphere(kRadius), Vec3(0, kHeight + kRadius, 0));
    const Real exact = std::sqrt(2 * kHeight / kGravity);
    Real previous_vy = 0;
    for (int n = t.steps_for(2 * exact); n > 0; --n) {
        t.step();
        const Real vy = t.space().internal_linear_velocity(ball).y();
        // Free fall only ever speeds the ball up; half a step's gravity of slack ignores rounding.
        if (vy > previous_vy - 0.5 * kGravity * setting.dt()) return t.result(std::abs(t.time() - exact));
        previous_vy = vy;
    }
    return t.result(exact);  // never landed: the whole time is the error
}

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

// Energy drift: a box spun about its intermediate axis (the unstable one: it tumbles
// over and back, the Dzhanibekov effect), no gravity, gyroscopic torque on. Free
// rotation keeps its kinetic energy; the error is the worst relative change in 10 s.
CaseRun spin_energy(const Setting& setting) {
    TimedSpace t(setting, Vec3::Zero());
    BodyDesc desc;
    desc.shape = Shape::box(Vec3(0.1, 0.25, 0.4));  // intermediate axis: y
    desc.angular_velocity = Vec3(0.02, 6, 0.02);    // a small push off the axis starts the tumble
    desc.gyroscopic = true;
    desc.allow_sleep = false;
    desc.allow_interpolation = false;
    const BodyHandle box = t.space().create_body(desc);
    const Mat3 inertia_local = desc.shape.mass_properties(desc.density).inertia;
    auto energy = [&] {
        const Mat3 r = t.space().internal_orientation(box).toRotationMatrix();
        const Vec3 w = t.space().internal_angular_velocity(box);
        return 0.5 * w.dot(r * inertia_local * r.transpose() * w);
    };
    const double initial = energy();
    double worst = 0;
    for (int n = t.steps_for(10); n > 0; --n) {
        t.step();
        worst = std::max(worst, std::abs(energy() - initial) / initial);
    }
    return t.result(worst);
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

constexpr Case kCases[] = {
    {"stack_drift", "10-box stack, 5 s: worst distance of the top box from its ideal position", "m", stack_drift},
    {"stack_sink", "10-box stack at rest: top box below its ideal height (last 1 s of 5)", "m", stack_sink},
    {"mass_ratio", "300 kg plank on three 1 kg cubes: plank below its ideal height (last 1 s of 3)", "m", mass_ratio},
    {"free_fall", "sphere dropped 10 m: first-contact time against sqrt(2h/g)", "s", free_fall},
    {"projectile", "sphere thrown, no ground: position against the exact parabola after 2 s", "m", projectile},
    {"spin_energy", "box spun about its intermediate axis, gyroscopic, 10 s: worst relative change of kinetic energy", "rel", spin_energy},
    {"bounce", "sphere, restitution 1, dropped 5 m: relative error of the 5th apex height", "rel", bounce},
};

}  // namespace

std::span<const Case> accuracy_cases() { return kCases; }

}  // namespace spindle::bench
