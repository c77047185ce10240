// What each effect costs: every case runs the same scene with the effect off and on
// (design.md section 7), one step per iteration, single-threaded.
#include <spindle/engine/joint.hpp>
#include <spindle/engine/space.hpp>

#include <benchmark/benchmark.h>

#include <memory>

namespace {

using namespace spindle;

enum Effect : int { kNone, kDamping, kGyroscopic, kInterpolation, kFriction, kRestitution, kJoints, kContinuous };

// 4096 free bodies (no contacts): the per-body effects.
std::unique_ptr<Space> free_bodies(Effect effect) {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    s.time_step.use_internal_time_stepping = true;
    auto space = std::make_unique<Space>(s);
    for (int i = 0; i < 4096; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.3, 0.2, 0.1));
        d.position = Vec3(i % 64, (i / 64) % 64, 0) * 2.0;
        d.angular_velocity = Vec3(0.1, 3, 0.2);
        d.linear_damping = effect == kDamping ? 0.1 : 0;
        d.angular_damping = effect == kDamping ? 0.1 : 0;
        d.gyroscopic = effect == kGyroscopic;
        d.allow_interpolation = effect == kInterpolation;
        space->create_body(d);
    }
    return space;
}

// 1024 boxes resting on a floor: the contact effects.
std::unique_ptr<Space> resting_boxes(Effect effect) {
    SpaceSettings s;
    s.sleep.enabled = false;
    auto space = std::make_unique<Space>(s);
    BodyDesc floor;
    floor.type = MotionType::Static;
    floor.shape = Shape::box(Vec3(50, 1, 50));
    floor.position = Vec3(0, -1, 0);
    floor.friction = effect == kFriction ? 0.6 : 0;
    floor.restitution = effect == kRestitution ? 0.5 : 0;
    space->create_body(floor);
    for (int i = 0; i < 1024; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.4, 0.4, 0.4));
        d.position = Vec3(i % 32 - 16, 0.4, i / 32 - 16) * 1.0 + Vec3(0, 0, 0);
        d.friction = effect == kFriction ? 0.6 : 0;
        d.restitution = effect == kRestitution ? 0.5 : 0;
        space->create_body(d);
    }
    for (int i = 0; i < 30; ++i) space->update();
    return space;
}

// 64 hanging chains of 16 links: with joints, or the same links free.
std::unique_ptr<Space> chains(Effect effect) {
    SpaceSettings s;
    s.sleep.enabled = false;
    auto space = std::make_unique<Space>(s);
    for (int c = 0; c < 64; ++c) {
        const Vec3 top((c % 8) * 3.0, 20, (c / 8) * 3.0);
        BodyDesc anchor;
        anchor.type = MotionType::Static;
        anchor.shape = Shape::sphere(0.05);
        anchor.position = top;
        BodyHandle previous = space->create_body(anchor);
        for (int k = 0; k < 16; ++k) {
            BodyDesc link;
            link.shape = Shape::capsule(0.15, 0.05);
            // Unjointed links start 0.6 m apart so they never touch: the baseline pays
            // for neither joints nor the contacts the joints would have disabled.
            const double pitch = effect == kJoints ? 0.4 : 1.0;
            link.position = top + Vec3(0, -pitch * k - 0.2, 0);
            const BodyHandle h = space->create_body(link);
            if (effect == kJoints)
                space->create_joint(JointDesc::ball_socket_at(previous, h, top + Vec3(0, -0.4 * k, 0)));
            previous = h;
        }
    }
    return space;
}

// 1024 spheres at 30 m/s between static walls, flagged fast or not.
std::unique_ptr<Space> fast_spheres(Effect effect) {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    auto space = std::make_unique<Space>(s);
    for (int w = -1; w <= 1; w += 2) {
        BodyDesc wall;
        wall.type = MotionType::Static;
        wall.shape = Shape::box(Vec3(0.05, 40, 40));
        wall.position = Vec3(w * 30.0, 0, 0);
        space->create_body(wall);
    }
    for (int i = 0; i < 1024; ++i) {
        BodyDesc d;
        d.shape = Shape::sphere(0.2);
        d.position = Vec3(0, (i % 32) - 16, (i / 32) - 16);
        d.linear_velocity = Vec3(i % 2 ? 30 : -30, 0, 0);
        d.restitution = 1;
        d.friction = 0;
        d.fast = effect == kContinuous;
        space->create_body(d);
    }
    return space;
}

// 10k boxes resting on a floor in a grid: asleep (stepped until they sleep) or awake.
std::unique_ptr<Space> grid(bool sleeping) {
    SpaceSettings s;
    s.sleep.enabled = sleeping;
    auto space = std::make_unique<Space>(s);
    BodyDesc floor;
    floor.type = MotionType::Static;
    floor.shape = Shape::box(Vec3(100, 1, 100));
    floor.position = Vec3(0, -1, 0);
    space->create_body(floor);
    for (int i = 0; i < 10000; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.4, 0.4, 0.4));
        d.position = Vec3(i % 100 - 50, 0.4, i / 100 - 50);
        space->create_body(d);
    }
    for (int i = 0; i < 120; ++i) space->update();
    return space;
}

template <typename Make>
void run(benchmark::State& state, Make make, bool internal_stepping = false) {
    auto space = make();
    for (auto _ : state) {
        if (internal_stepping) {
            space->update(1.0 / 60.0 + 0.004 * (state.iterations() % 2));  // leaves time to blend
        } else {
            space->update();
        }
    }
    state.counters["awake"] = static_cast<double>(space->last_update().awake_bodies);
}

void FreeBodies(benchmark::State& state) {
    const auto e = static_cast<Effect>(state.range(0));
    run(
        state, [&] { return free_bodies(e); }, true);
}
void RestingBoxes(benchmark::State& state) {
    const auto e = static_cast<Effect>(state.range(0));
    run(state, [&] { return resting_boxes(e); });
}
void Chains(benchmark::State& state) {
    const auto e = static_cast<Effect>(state.range(0));
    run(state, [&] { return chains(e); });
}
void FastSpheres(benchmark::State& state) {
    const auto e = static_cast<Effect>(state.range(0));
    run(state, [&] { return fast_spheres(e); });
}
void Grid10k(benchmark::State& state) {
    const bool sleeping = state.range(0) != 0;
    run(state, [&] { return grid(sleeping); });
}

}  // namespace

// Arg: 0 = without the effect, else the effect (see Effect).
BENCHMARK(FreeBodies)
    ->Arg(kNone)
    ->Arg(kDamping)
    ->Arg(kGyroscopic)
    ->Arg(kInterpolation)
    ->ArgName("effect")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(RestingBoxes)
    ->Arg(kNone)
    ->Arg(kFriction)
    ->Arg(kRestitution)
    ->ArgName("effect")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(Chains)->Arg(kNone)->Arg(kJoints)->ArgName("effect")->Unit(benchmark::kMicrosecond);
BENCHMARK(FastSpheres)->Arg(kNone)->Arg(kContinuous)->ArgName("effect")->Unit(benchmark::kMicrosecond);
BENCHMARK(Grid10k)->Arg(0)->Arg(1)->ArgName("sleeping")->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
