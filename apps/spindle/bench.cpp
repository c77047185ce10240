// `spindle bench`: a scene stepped as fast as possible, without the async runner or
// rendering, in fixed 1/60 s steps; one line of results, for scripts and comparisons.
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/scene/scene.hpp>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>

#include "checks.hpp"
#include "commands.hpp"
#include "jobs.hpp"
#include "scenes.hpp"
#include "serial_fraction.hpp"

namespace spindle::app {
namespace {

// Fixed, whatever the scene says, so that numbers compare across scenes and with
// Jolt's PerformanceTest (which steps by 1/60 s).
constexpr Real kBenchStep = 1.0 / 60.0;

struct BenchOptions {
    std::string scene;
    std::int64_t threads = 1;
    std::int64_t steps = 300;
    std::optional<std::int64_t> substeps;  // none: the scene's
    bool stages = false;
    bool joint_errors = false;
    bool serial = false;
    bool serial_first = false;
};

// Parts of the step shorter than this share of it are left out of --serial's list.
constexpr double kSerialPartShown = 0.02;

// Parts of the first step at least this long are listed by --serial-first: the first step
// is one profile (no quieter half), and a part worth splitting is a millisecond or more.
constexpr double kFirstStepPartShown = 1e-3;

// The first step's profile: its serial time, and its serial parts of a millisecond or more.
void print_first_step_serial(const SerialProfile& p) {
    std::printf("first_step_traced_ms=%.3f first_step_serial_ms=%.3f first_step_serial_fraction=%.4f "
                "first_step_serial_code_ms=%.3f\n",
                1e3 * p.step_seconds, 1e3 * p.serial_seconds, p.serial_fraction(), 1e3 * p.outside_jobs_seconds);
    for (const SerialPart& part : p.parts) {
        if (part.seconds < kFirstStepPartShown) break;
        std::printf("first_step_part ms=%.3f name=\"%s\"\n", 1e3 * part.seconds, part.name.c_str());
    }
}

// The quieter half of the steps' profiles (serial_fraction.hpp), and the fraction of all of them.
void print_serial(const std::vector<SerialProfile>& steps, double phases, double barriers) {
    const SerialProfile p = quieter_half(steps);
    const auto used = static_cast<double>((steps.size() + 1) / 2);
    const SerialProfile all = sum_profiles(steps);
    std::printf("serial_fraction=%.4f serial_work_fraction=%.4f amdahl_4=%.2f amdahl_8=%.2f amdahl_16=%.2f "
                "traced_steps=%zu all_steps_serial_fraction=%.4f serial_code_fraction=%.4f\n",
                p.serial_fraction(), p.serial_work_fraction(), amdahl_speedup(p.serial_work_fraction(), 4),
                amdahl_speedup(p.serial_work_fraction(), 8), amdahl_speedup(p.serial_work_fraction(), 16), steps.size(),
                all.serial_fraction(), all.serial_code_fraction());
    // The serial time by kind (serial_fraction.hpp), as shares of the step: what a phase's
    // start, its tail and the barrier after it cost, beside the stages' own code.
    const double step = p.step_seconds > 0 ? p.step_seconds : 1;
    std::printf("serial_kinds phase_start=%.4f phase_tail=%.4f barrier=%.4f stage_code=%.4f lone_jobs=%.4f\n",
                p.phase_start_seconds / step, p.phase_tail_seconds / step, p.barrier_seconds / step,
                p.stage_code_seconds() / step, p.lone_job_seconds / step);
    // What the kinds' time is spent on: the solver's phases per step and the barriers they
    // met (consecutive one-block phases share one).
    const auto traced = static_cast<double>(steps.size());
    std::printf("phases_per_step=%.1f barriers_per_step=%.1f\n", phases / traced, barriers / traced);
    for (const SerialPart& part : p.parts) {
        const double share = p.step_seconds > 0 ? part.seconds / p.step_seconds : 0;
        if (share < kSerialPartShown) break;
        std::printf("serial_part share=%.4f ms_per_step=%.3f name=\"%s\"\n", share, 1e3 * part.seconds / used,
                    part.name.c_str());
    }
}

// The worst error of one joint type's joints at the end of a run.
struct WorstJointError {
    int count = 0;
    Real linear = 0;   // m: Space::internal_joint_error's linear
    Real angular = 0;  // rad: its angular (hinge: axes apart; swing-twist: outside the cone or twist range)
    Real limit = 0;    // rad: a limited hinge's angle outside its range
};

void print_joint_errors(const Space& space, const std::vector<JointHandle>& joints) {
    std::array<WorstJointError, static_cast<int>(JointType::Motor) + 1> worst{};
    for (JointHandle joint : joints) {
        const JointDesc desc = space.joint_desc(joint);
        WorstJointError& w = worst[static_cast<std::size_t>(desc.type)];
        const JointError error = space.internal_joint_error(joint);
        w.count += 1;
        w.linear = std::max(w.linear, error.linear);
        w.angular = std::max(w.angular, error.angular);
        if (desc.type == JointType::Hinge && desc.hinge.enable_limit) {
            const Real angle = space.internal_hinge_angle(joint);
            w.limit = std::max({w.limit, desc.hinge.lower_angle - angle, angle - desc.hinge.upper_angle});
        }
    }
    for (std::size_t t = 0; t < worst.size(); ++t) {
        const WorstJointError& w = worst[t];
        if (w.count == 0) continue;
        std::printf("joint_errors type=%s joints=%d linear_m=%.5f angular_rad=%.4f hinge_limit_rad=%.4f\n",
                    to_string(static_cast<JointType>(t)), w.count, w.linear, w.angular, w.limit);
    }
}

int bench(const BenchOptions& o) {
    const SceneDesc scene = resolve_scene(o.scene);
    const auto threads = static_cast<unsigned>(o.threads);

    const std::unique_ptr<JobSystem> jobs = make_jobs(threads);
    auto* traced = dynamic_cast<WorkStealingJobSystem*>(jobs.get());
    if (o.serial && (!traced || threads < 2 || o.steps < 2)) {
        std::cerr << "spindle bench: --serial needs --threads 2 or more (one worker has no parallel part) and "
                     "--steps 2 or more (the first step is not traced)\n";
        return 2;
    }
    if (o.serial_first && (!traced || threads < 2)) {
        std::cerr << "spindle bench: --serial-first needs --threads 2 or more (one worker has no parallel part)\n";
        return 2;
    }
    if (jobs->worker_count() != threads) {
        std::cerr << "spindle bench: note: " << threads << " threads asked for, the scheduler runs "
                  << jobs->worker_count() << '\n';
    }
    SpaceSettings settings = scene.settings;
    settings.time_step.duration = kBenchStep;
    settings.time_step.use_internal_time_stepping = false;
    Space space(settings, jobs.get());
    std::vector<JointHandle> joints;
    const std::vector<BodyHandle> handles = build(scene, space, &joints);
    TimeStepSettings time_step = space.settings().time_step;
    time_step.duration = kBenchStep;  // build() applied the scene's
    space.set_time_step(time_step);
    if (o.substeps) {
        SolverSettings solver = space.settings().solver;
        solver.substeps = static_cast<int>(*o.substeps);
        space.set_solver(solver);
    }

    std::array<double, static_cast<int>(Stage::Count)> stage_seconds{};
    std::vector<SerialProfile> serial_steps;
    std::vector<std::vector<TraceEvent>> traced_steps;     // --serial's, one trace a step
    double analysis_seconds = 0;                           // --serial's, left out of the run's time
    std::uint64_t phases_before = 0, barriers_before = 0;  // run_phases' counts before the traced steps
    const Stopwatch watch;
    double first_step_seconds = 0;
    std::optional<SerialProfile> first_step_serial;
    for (std::int64_t i = 0; i < o.steps; ++i) {
        // The first step makes every contact: timed apart, and left out of --serial's trace
        // (--serial-first traces it alone).
        if (i == 0 && o.serial_first) traced->enable_trace(true);
        if (i == 1 && o.serial) {
            traced->enable_trace(true);
            phases_before = traced->phases_run();
            barriers_before = traced->phase_barriers();
        }
        space.update();
        if (i == 0) first_step_seconds = watch.elapsed_seconds();
        if (i == 0 && o.serial_first) {
            const Stopwatch analysis;
            traced->enable_trace(false);
            first_step_serial = serial_profile(traced->trace_events());
            traced->clear_trace();
            analysis_seconds += analysis.elapsed_seconds();
        }
        const UpdateStats& stats = space.last_update();
        for (std::size_t k = 0; k < stage_seconds.size(); ++k) stage_seconds[k] += stats.stage_seconds[k];
        if (i >= 1 && o.serial) {
            // Kept, and profiled after the run: profiling a step takes longer than an idle
            // worker spins before it sleeps, so every traced step would begin by waking the
            // workers, a wait untraced steps never have.
            const Stopwatch analysis;
            traced_steps.push_back(traced->trace_events());
            traced->clear_trace();
            analysis_seconds += analysis.elapsed_seconds();
        }
    }
    const double seconds = watch.elapsed_seconds() - analysis_seconds;
    for (const std::vector<TraceEvent>& events : traced_steps) serial_steps.push_back(serial_profile(events));
    if (o.serial) traced->enable_trace(false);
    const double ms_per_step = o.steps > 1 ? 1e3 * (seconds - first_step_seconds) / static_cast<double>(o.steps - 1)
                                           : 0;

    double top_y = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < handles.size(); ++i) {
        if (scene.bodies[i].desc.type == MotionType::Dynamic)
            top_y = std::max(top_y, space.internal_position(handles[i]).y());
    }
    if (scene.dynamic_body_count() == 0) top_y = 0;
    std::printf("scene=%s bodies=%zu threads=%u steps=%lld steps_per_s=%.1f ms_per_step=%.3f first_step_ms=%.3f "
                "top_y=%.4f hash=0x%016llx\n",
                scene.name.c_str(), scene.dynamic_body_count(), jobs->worker_count(), static_cast<long long>(o.steps),
                seconds > 0 ? static_cast<double>(o.steps) / seconds : 0.0, ms_per_step, 1e3 * first_step_seconds,
                top_y, static_cast<unsigned long long>(space.state_hash()));
    if (o.stages) {
        std::printf("stages_ms");
        for (std::size_t k = 0; k < stage_seconds.size(); ++k) {
            if (stage_seconds[k] > 0) {
                std::printf(" %s=%.3g", to_string(static_cast<Stage>(k)),
                            1e3 * stage_seconds[k] / static_cast<double>(o.steps));
            }
        }
        std::printf("\n");
    }
    if (o.joint_errors) print_joint_errors(space, joints);
    if (first_step_serial) print_first_step_serial(*first_step_serial);
    if (o.serial) {
        print_serial(serial_steps, static_cast<double>(traced->phases_run() - phases_before),
                     static_cast<double>(traced->phase_barriers() - barriers_before));
    }
    return 0;
}

}  // namespace

Command add_bench_command(CLI::App& program) {
    CLI::App* cli = program.add_subcommand("bench", "step a scene as fast as possible; prints one line of results");
    cli->footer(
        "Steps SCENE N times by 1/60 s with Space::update(), no async runner and no rendering, and\n"
        "prints one line:\n"
        "  scene=NAME bodies=N threads=N steps=N steps_per_s=X ms_per_step=X first_step_ms=X top_y=Y hash=0x...\n"
        "bodies: dynamic bodies; steps_per_s: over all steps; ms_per_step: the mean step after the\n"
        "first (0 for one step); first_step_ms: the first step (it makes every contact); top_y: the\n"
        "highest dynamic body origin at the end (m); hash: Space::state_hash() of the final state\n"
        "(equal hashes = bitwise equal states).");
    auto o = std::make_shared<BenchOptions>();
    cli->add_option("--threads", o->threads, "scheduler workers, 1 to 1024 (default 1)")
        ->option_text("N")
        ->transform(integer_in(1, 1024));
    cli->add_option("--steps", o->steps, "steps to take, 1 to 100000000 (default 300)")
        ->option_text("N")
        ->transform(integer_in(1, 100'000'000));
    cli->add_option("--substeps", o->substeps, "solver substeps per step, 1 to 1000 (default: the scene's)")
        ->option_text("N")
        ->transform(integer_in(1, 1000));
    cli->add_flag("--stages", o->stages,
                  "a second line: milliseconds per step in each stage that took time,\n"
                  "e.g. stages_ms Broadphase=0.14 Narrowphase=0.35 Solver=2.6")
        ->check(no_value());
    cli->add_flag("--joint-errors", o->joint_errors,
                  "a line per joint type at the end: its joints' worst error (Space::internal_joint_error),\n"
                  "e.g. joint_errors type=hinge joints=640 linear_m=0.0046 angular_rad=0.08 hinge_limit_rad=0.01")
        ->check(no_value());
    cli->add_flag("--serial", o->serial,
                  "trace each step after the first and print the serial fraction of a step (time with\n"
                  "at most one worker working) over the quieter half of the steps, Amdahl's bound on 4,\n"
                  "8 and 16 workers, that time by kind (a solver phase's start, its tail, the barrier\n"
                  "after it, the stages' own code, lone jobs) and a line per serial part over 2% of a\n"
                  "step; needs --threads 2 or more, e.g.\n"
                  "serial_fraction=0.08 serial_work_fraction=0.04 amdahl_4=3.55 amdahl_8=6.2 amdahl_16=9.9\n"
                  "  traced_steps=299 all_steps_serial_fraction=0.09 serial_code_fraction=0.02\n"
                  "serial_kinds phase_start=0.02 phase_tail=0.02 barrier=0.01 stage_code=0.02 lone_jobs=0.01\n"
                  "serial_part share=0.031 ms_per_step=0.29 name=\"Islands outside jobs\"")
        ->check(no_value());
    cli->add_flag("--serial-first", o->serial_first,
                  "trace the first step alone (it makes every contact) and print its traced and serial\n"
                  "time and a line per serial part of 1 ms or more, longest first; needs --threads 2 or\n"
                  "more, e.g.\n"
                  "first_step_traced_ms=31.2 first_step_serial_ms=9.8 first_step_serial_fraction=0.3141\n"
                  "  first_step_serial_code_ms=4.1\n"
                  "first_step_part ms=2.310 name=\"Broadphase outside jobs\"")
        ->check(no_value());
    cli->add_option("SCENE", o->scene, "a built-in scene (see `spindle scenes`) or a .toml scene file")
        ->required()
        ->type_name("")
        ->check(check_scene);
    return {cli, [o] { return bench(*o); }};
}

}  // namespace spindle::app
