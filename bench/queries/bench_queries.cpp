// Scene queries while the physics loop runs: a frame of 10k ray casts or 1k shape casts
// (spheres) from the game thread against many_pyramids (10,780 boxes, sleeping off, so
// every body moves the query tree's way each flip) while an AsyncRunner steps it on the
// other core, a frame at most every 1/60 s. Reported: time per query on the game thread,
// hits, and the loop's steps per second beside the same loop with the game thread idle
// (queries 0). FirstQuery: the first ray cast into a space that has never been queried, which
// builds its query scenes from the published states (a field of static boxes, stepped once).
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <thread>

#include "common/scenes.hpp"

namespace {

using namespace spindle;

enum Kind { kIdle = 0, kRays = 1, kSphereCasts = 2 };
constexpr double kFrame = 1.0 / 60;

void QueriesWhilePhysicsRuns(benchmark::State& state) {
    const auto kind = static_cast<Kind>(state.range(0));
    SpaceSettings settings;
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    const bench::BoxScene scene = bench::many_pyramids_scene();
    bench::add_to_space(space, scene, {.allow_sleep = false});
    Aabb extent;
    for (const bench::BoxSpec& box : scene.boxes) extent.include(box.center);
    for (int i = 0; i < 2; ++i) space.update();  // past the first step's contact creation

    AsyncRunner runner(space);
    runner.start();
    std::mt19937 random(11);
    std::uniform_real_distribution<Real> x(extent.min.x(), extent.max.x()), z(extent.min.z(), extent.max.z());
    const int per_frame = kind == kRays ? 10000 : kind == kSphereCasts ? 1000 : 0;
    const Shape probe = Shape::sphere(0.25);
    std::uint64_t queries = 0, hits = 0;
    double query_seconds = 0;
    const std::uint64_t steps_before = runner.stats().steps;
    const std::int64_t start = now_nanoseconds();
    for (auto _ : state) {
        const std::int64_t t0 = now_nanoseconds();
        for (int q = 0; q < per_frame; ++q) {
            const Vec3 from(x(random), extent.max.y() + 5, z(random));
            const Vec3 drop(0, extent.min.y() - extent.max.y() - 6, 0);
            if (kind == kRays) {
                hits += space.cast_ray(from, from + drop).has_value();
            } else {
                hits += space.cast_shape(probe, {from, Quat::Identity()}, drop).has_value();
            }
        }
        const double spent = static_cast<double>(now_nanoseconds() - t0) * 1e-9;
        query_seconds += spent;
        queries += static_cast<std::uint64_t>(per_frame);
        // Frames at 60 Hz at most, as a game's: the rest of the frame is left to the loop.
        if (spent < kFrame) std::this_thread::sleep_for(std::chrono::duration<double>(kFrame - spent));
    }
    const double seconds = static_cast<double>(now_nanoseconds() - start) * 1e-9;
    const AsyncStats stats = runner.stats();
    runner.stop();
    state.counters["steps_per_s"] = static_cast<double>(stats.steps - steps_before) / seconds;
    if (queries > 0) {
        state.counters["ns_per_query"] = query_seconds / static_cast<double>(queries) * 1e9;
        state.counters["hit_fraction"] = static_cast<double>(hits) / static_cast<double>(queries);
        state.counters["ms_per_frame"] = query_seconds / static_cast<double>(state.iterations()) * 1e3;
    }
    state.counters["query_scene_copies"] = static_cast<double>(space.counters().query_scene_copies);
}

// A square field of state.range(0) static unit boxes, 2 m apart, and one falling box,
// stepped once; timed: the first ray cast, straight down onto the field's middle.
void FirstQuery(benchmark::State& state) {
    const auto bodies = static_cast<int>(state.range(0));
    const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(bodies))));
    double build_seconds = 0;
    for (auto _ : state) {
        state.PauseTiming();
        auto space = std::make_unique<Space>();
        BodyDesc field;
        field.type = MotionType::Static;
        field.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        for (int k = 0; k < bodies; ++k) {
            field.position = Vec3(2.0 * (k % side), 0, 2.0 * (k / side));
            space->create_body(field);
        }
        BodyDesc falling;
        falling.position = Vec3(0, 5, 0);
        space->create_body(falling);
        space->update();
        const Vec3 middle(2.0 * (side / 2), 10, 2.0 * (side / 2));
        state.ResumeTiming();
        const std::int64_t t0 = now_nanoseconds();
        const bool hit = space->cast_ray(middle, middle - Vec3(0, 20, 0)).has_value();
        build_seconds += static_cast<double>(now_nanoseconds() - t0) * 1e-9;
        if (!hit) state.SkipWithError("the first ray missed the field");
        state.PauseTiming();
        space.reset();
        state.ResumeTiming();
    }
    state.counters["ms_first_query"] = build_seconds / static_cast<double>(state.iterations()) * 1e3;
}

}  // namespace

BENCHMARK(FirstQuery)
    ->Arg(100000)
    ->Arg(1000000)
    ->ArgName("static_bodies")
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(QueriesWhilePhysicsRuns)
    ->Arg(kIdle)
    ->Arg(kRays)
    ->Arg(kSphereCasts)
    ->ArgName("queries")
    ->Iterations(60)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
