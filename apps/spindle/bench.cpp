// `spindle bench`: a scene stepped as fast as possible, without the async runner or
// rendering, in fixed 1/60 s steps; one line of results, for scripts and comparisons.
#include <spindle/scene/scene.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <iostream>
#include <limits>

#include "commands.hpp"
#include "jobs.hpp"
#include "scenes.hpp"

namespace spindle::app {
namespace {

constexpr const char* kBenchUsage =
    "usage: spindle bench SCENE [--threads N] [--steps N] [--substeps N] [--stages]\n"
    "Steps SCENE (a built-in name or a .toml file) N times by 1/60 s with Space::update(), no\n"
    "async runner and no rendering, and prints one line:\n"
    "  scene=NAME bodies=N threads=N steps=N steps_per_s=X top_y=Y hash=0x...\n"
    "bodies: dynamic bodies; top_y: the highest dynamic body centre at the end (m); hash:\n"
    "Space::state_hash() of the final state (equal hashes = bitwise equal states).\n"
    "options:\n"
    "  --threads N    scheduler workers (default 1)\n"
    "  --steps N      steps to take (default 300)\n"
    "  --substeps N   solver substeps per step (default: the scene's)\n"
    "  --stages       a second line: milliseconds per step in each stage that took time,\n"
    "                 e.g. stages_ms Broadphase=0.14 Narrowphase=0.35 Solver=2.6\n";

// Fixed, whatever the scene says, so that numbers compare across scenes and with
// Jolt's PerformanceTest (which steps by 1/60 s).
constexpr Real kBenchStep = 1.0 / 60.0;

}  // namespace

int bench_command(Args& args) {
    if (args.help()) {
        std::cout << kBenchUsage;
        return 0;
    }
    const auto threads = static_cast<unsigned>(args.integer("threads", 1, 1024).value_or(1));
    const std::int64_t steps = args.integer("steps", 1, 100'000'000).value_or(300);
    const std::optional<std::int64_t> substeps = args.integer("substeps", 1, 1000);
    const bool stages = args.flag("stages");
    const std::vector<std::string> names = args.positionals(1);
    if (names.empty()) throw UsageError("missing the SCENE to run");
    const SceneDesc scene = resolve_scene(names[0]);

    const std::unique_ptr<JobSystem> jobs = make_jobs(threads);
    if (jobs->worker_count() != threads) {
        std::cerr << "spindle bench: note: " << threads << " threads asked for, the scheduler runs "
                  << jobs->worker_count() << '\n';
    }
    SpaceSettings settings = scene.settings;
    settings.time_step.duration = kBenchStep;
    settings.time_step.use_internal_time_stepping = false;
    Space space(settings, jobs.get());
    const std::vector<BodyHandle> handles = build(scene, space);
    TimeStepSettings time_step = space.settings().time_step;
    time_step.duration = kBenchStep;  // build() applied the scene's
    space.set_time_step(time_step);
    if (substeps) {
        SolverSettings solver = space.settings().solver;
        solver.substeps = static_cast<int>(*substeps);
        space.set_solver(solver);
    }

    std::array<double, static_cast<int>(Stage::Count)> stage_seconds{};
    const Stopwatch watch;
    for (std::int64_t i = 0; i < steps; ++i) {
        space.update();
        const UpdateStats& stats = space.last_update();
        for (std::size_t k = 0; k < stage_seconds.size(); ++k) stage_seconds[k] += stats.stage_seconds[k];
    }
    const double seconds = watch.elapsed_seconds();

    double top_y = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < handles.size(); ++i) {
        if (scene.bodies[i].desc.type == MotionType::Dynamic) top_y = std::max(top_y, space.internal_position(handles[i]).y());
    }
    if (scene.dynamic_body_count() == 0) top_y = 0;
    std::printf("scene=%s bodies=%zu threads=%u steps=%lld steps_per_s=%.1f top_y=%.4f hash=0x%016llx\n",
                scene.name.c_str(), scene.dynamic_body_count(), jobs->worker_count(), static_cast<long long>(steps),
                seconds > 0 ? static_cast<double>(steps) / seconds : 0.0, top_y,
                static_cast<unsigned long long>(space.state_hash()));
    if (stages) {
        std::printf("stages_ms");
        for (std::size_t k = 0; k < stage_seconds.size(); ++k) {
            if (stage_seconds[k] > 0) {
                std::printf(" %s=%.3g", to_string(static_cast<Stage>(k)), 1e3 * stage_seconds[k] / static_cast<double>(steps));
            }
        }
        std::printf("\n");
    }
    return 0;
}

}  // namespace spindle::app
