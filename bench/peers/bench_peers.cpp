// bench_peers: Jolt PerformanceTest's "Pyramid" (1240 boxes, 500 steps at 60 Hz) in Bullet
// and in Spindle, one benchmark iteration per step; prints steps/s and Spindle/Bullet.
//
// Own flags (taken out before Google Benchmark sees the rest):
//   --steps=N             steps per run (default 500; top_y is only comparable at 500)
//   --quick               --steps=60
//   --floor=box|plane     Spindle's floor: the scene's box (default) or a plane at its top face
#include "common/jobs.hpp"
#include "common/run.hpp"
#include "common/scenes.hpp"
#include "common/timing.hpp"

#ifdef SPINDLE_BENCH_HAVE_BULLET
#include "bullet_world.hpp"
#endif

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace spindle::bench {
namespace {

struct Options {
    int steps = 500;
    FloorShape floor = FloorShape::Box;
};
Options g_options;

struct Result {
    double steps_per_s = 0;      // wall clock
    double cpu_steps_per_s = 0;  // process CPU time: steadier when other work shares the cores
    double top_y = 0;

    Result(const StepClock& clock, benchmark::IterationCount steps, double top)
        : steps_per_s(static_cast<double>(steps) / clock.wall_seconds()),
          cpu_steps_per_s(static_cast<double>(steps) / clock.cpu_seconds()),
          top_y(top) {}
};
std::optional<Result> g_bullet;
std::optional<Result> g_spindle;

void report(benchmark::State& state, const Result& result) {
    state.counters["steps_per_s"] = result.steps_per_s;
    state.counters["cpu_steps_per_s"] = result.cpu_steps_per_s;
    state.counters["top_y"] = result.top_y;
}

#ifdef SPINDLE_BENCH_HAVE_BULLET
void bm_bullet_pyramid(benchmark::State& state) {
    const BoxScene scene = pyramid_scene();
    BulletBoxWorld world(scene);
    const StepClock clock;
    for (auto _ : state) world.step();
    const Result result(clock, state.iterations(), world.height(world.box_count() - 1));
    report(state, result);
    state.counters["boxes"] = static_cast<double>(world.box_count());
    g_bullet = result;
}
#endif

void bm_spindle_pyramid(benchmark::State& state) {
    const BoxScene scene = pyramid_scene();
    SpaceSettings settings;
    settings.sleep.enabled = false;  // Jolt's PerformanceTest and Bullet's DISABLE_DEACTIVATION
    const auto jobs = make_bench_jobs(1);
    Space space(settings, jobs.get());
    const std::vector<BodyHandle> boxes = add_to_space(space, scene, {.floor = g_options.floor, .allow_sleep = false});
    const StepClock clock;
    for (auto _ : state) space.update();  // no internal stepping: exactly one 1/60 s step
    const Result result(clock, state.iterations(), height_of(space, boxes.back()));
    report(state, result);
    state.counters["boxes"] = static_cast<double>(boxes.size());
    state.counters["contacts"] = space.last_update().contacts;
    if (g_bullet) {
        state.counters["vs_bullet"] = result.steps_per_s / g_bullet->steps_per_s;
        state.counters["cpu_vs_bullet"] = result.cpu_steps_per_s / g_bullet->cpu_steps_per_s;
    }
    g_spindle = result;
}

bool take_flag(const char* arg) {
    if (std::strncmp(arg, "--steps=", 8) == 0) {
        g_options.steps = std::atoi(arg + 8);
        if (g_options.steps <= 0) {
            std::fprintf(stderr, "bench_peers: --steps must be a positive integer, got '%s'\n", arg + 8);
            std::exit(2);
        }
    } else if (std::strcmp(arg, "--quick") == 0) {
        g_options.steps = 60;
    } else if (std::strcmp(arg, "--floor=box") == 0) {
        g_options.floor = FloorShape::Box;
    } else if (std::strcmp(arg, "--floor=plane") == 0) {
        g_options.floor = FloorShape::Plane;
    } else {
        return false;
    }
    return true;
}

void print_summary() {
    std::printf("\npyramid, %d steps at 60 Hz, 1240 boxes (standing: top box at ~28.99)\n", g_options.steps);
#ifdef SPINDLE_BENCH_HAVE_BULLET
    if (g_bullet) {
        std::printf("  Bullet  %8.1f steps/s (%8.1f per CPU second)   top_y %6.2f\n", g_bullet->steps_per_s,
                    g_bullet->cpu_steps_per_s, g_bullet->top_y);
    }
#else
    std::printf("  Bullet  skipped: Bullet was not found when this binary was configured\n");
#endif
    if (g_spindle) {
        std::printf("  Spindle %8.1f steps/s (%8.1f per CPU second)   top_y %6.2f   (floor: %s)\n",
                    g_spindle->steps_per_s, g_spindle->cpu_steps_per_s, g_spindle->top_y,
                    g_options.floor == FloorShape::Box ? "box" : "plane");
    }
    if (g_bullet && g_spindle) {
        std::printf("  Spindle/Bullet %.2f (wall), %.2f (CPU)\n", g_spindle->steps_per_s / g_bullet->steps_per_s,
                    g_spindle->cpu_steps_per_s / g_bullet->cpu_steps_per_s);
    }
}

}  // namespace
}  // namespace spindle::bench

int main(int argc, char** argv) {
    using namespace spindle::bench;
    std::vector<char*> rest = take_own_flags(argc, argv, take_flag);
#ifdef SPINDLE_BENCH_HAVE_BULLET
    benchmark::RegisterBenchmark("pyramid/bullet", bm_bullet_pyramid)
        ->Iterations(g_options.steps)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
#endif
    benchmark::RegisterBenchmark("pyramid/spindle", bm_spindle_pyramid)
        ->Iterations(g_options.steps)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
    const int code = run_registered_benchmarks(rest);
    if (code == 0) print_summary();
    return code;
}
