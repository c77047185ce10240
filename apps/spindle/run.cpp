// `spindle run`: plays a scene like a game would (the seed, section 3). The main
// thread is the game thread, pinned per the layout, "rendering" at --render-hz by
// copying interpolated motion states; the physics loop runs in an AsyncRunner on its
// own pinned thread with internal time stepping; the JobSystem comes from make_jobs()
// (work stealing, workers pinned per the layout, the physics loop thread as worker 0).
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/layout.hpp>
#include <spindle/scene/scene.hpp>

#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <thread>

#include "checks.hpp"
#include "commands.hpp"
#include "jobs.hpp"
#include "motion_truth.hpp"
#include "physics_probe.hpp"
#include "play.hpp"
#include "progress.hpp"
#include "recorder.hpp"
#include "scenes.hpp"
#include "session.hpp"
#include "trace.hpp"

namespace spindle::app {
namespace {

// Moving bodies whose rendered motion is set beside the recorded steps (spread evenly).
constexpr std::size_t kTruthBodies = 64;

struct RunOptions {
    std::string scene{kDefaultScene};
    std::optional<std::string> layout_file;
    double seconds = 5;
    double render_hz = 60;
    std::string idle = "poll";
    std::optional<std::string> trace_file;
    std::optional<std::string> record_file;
    bool play = false;
};

// What the game thread measured.
struct GameStats {
    std::uint64_t frames = 0;
    std::uint64_t late_frames = 0;  // frames that started more than a frame period late
    double wall_seconds = 0;
    double frame_ms_max = 0;
    double frame_ms_sum = 0;
};

void print_truth(ShownAs shown, const TruthReport& r) {
    std::printf("    %-16s %8.3f mm %8.3f mm %10.2f ms %9.2f ms %8llu\n", to_string(shown), r.error_mean_m * 1e3,
                r.error_p95_m * 1e3, r.lag_mean_ms, r.lag_jitter_ms, static_cast<unsigned long long>(r.frames));
}

void print_play(const PlayStats& play, const WorkCounters& counters) {
    const double frames = play.frames ? static_cast<double>(play.frames) : 1.0;
    std::printf("  play           %llu queries (%.1f us each, %.3f ms per frame on the game thread), %llu picks, "
                "%llu shots, %.1f bodies in the trigger box per frame, %llu query scenes copied\n",
                static_cast<unsigned long long>(play.queries),
                play.queries ? play.query_seconds * 1e6 / static_cast<double>(play.queries) : 0.0,
                play.query_seconds * 1e3 / frames, static_cast<unsigned long long>(play.picks),
                static_cast<unsigned long long>(play.shots), static_cast<double>(play.in_trigger) / frames,
                static_cast<unsigned long long>(counters.query_scene_copies));
    std::printf("  events         %llu begin, %llu end, %llu hit; sensors %llu begin, %llu end; read in %.1f us per "
                "frame on the game thread\n",
                static_cast<unsigned long long>(play.begins), static_cast<unsigned long long>(play.ends),
                static_cast<unsigned long long>(play.hits), static_cast<unsigned long long>(play.sensor_begins),
                static_cast<unsigned long long>(play.sensor_ends), play.event_seconds * 1e6 / frames);
}

void print_summary(const SceneDesc& scene, const Layout& layout, const RunOptions& o, const GameStats& game,
                   const AsyncStats& physics, const ProbeTotals& probe, double step_seconds,
                   const MotionTruthMeter& truth) {
    std::printf("summary: scene %s, layout %s, %.2f s wall, idle %s\n", scene.name.c_str(), layout.name.c_str(),
                game.wall_seconds, o.idle.c_str());
    std::printf("  simulated      %.3f s in %llu steps (%.1f steps/s) over %llu updates\n",
                static_cast<double>(probe.steps) * step_seconds, static_cast<unsigned long long>(probe.steps),
                physics.steps_per_second, static_cast<unsigned long long>(probe.updates));
    std::printf("  rendered       %llu frames at %.0f Hz (%llu late), frame work mean %.3f ms, max %.3f ms\n",
                static_cast<unsigned long long>(game.frames), o.render_hz,
                static_cast<unsigned long long>(game.late_frames),
                game.frames ? game.frame_ms_sum / static_cast<double>(game.frames) : 0.0, game.frame_ms_max);
    std::printf("  update         p50 %.3f ms, p99 %.3f ms, max %.3f ms (updates that took a step)\n",
                physics.update_ms_p50, physics.update_ms_p99, physics.update_ms_max);
    std::printf("  motion lock    held p50 %.2f us, p99 %.2f us, max %.2f us (FlipReadBuffers)\n", physics.lock_us_p50,
                physics.lock_us_p99, physics.lock_us_max);
    std::printf("  dropped        %llu steps (%.3f s of time beyond the %d-steps-per-update cap)\n",
                static_cast<unsigned long long>(physics.steps_dropped), probe.dropped_seconds,
                scene.settings.time_step.max_steps_per_frame);
    double total = 0;
    for (double s : probe.stage_seconds) total += s;
    // ApplyWrites and FlipReadBuffers run on every update, stepping or not; with
    // --idle poll or spin there are many updates per step, so their share is the price
    // of publishing fresh interpolated states between steps.
    std::printf("  stages         %-20s %10s %12s %7s   (%.0f updates per step)\n", "", "total s", "ms per step",
                "share", probe.steps ? static_cast<double>(probe.updates) / static_cast<double>(probe.steps) : 0.0);
    for (int i = 0; i < static_cast<int>(Stage::Count); ++i) {
        const double s = probe.stage_seconds[static_cast<std::size_t>(i)];
        if (s == 0) continue;  // stages folded into another (the solver integrates) take no time of their own
        std::printf("                 %-20s %10.4f %12.4f %6.1f%%\n", to_string(static_cast<Stage>(i)), s,
                    probe.steps ? s * 1e3 / static_cast<double>(probe.steps) : 0.0, total > 0 ? 100 * s / total : 0.0);
    }
    if (!truth.has_clock()) return;
    // Each frame against where the bodies were at its own instant (motion_truth.hpp): the
    // error is mostly the lag times the speed; the lag's jitter is what looks uneven.
    std::printf("  smoothness     frames against the recorded steps at their instants (%llu steps recorded):\n",
                static_cast<unsigned long long>(truth.steps_recorded()));
    std::printf("    %-16s %11s %11s %13s %12s %8s\n", "shown", "error mean", "error p95", "lag mean", "lag jitter",
                "frames");
    for (ShownAs shown : {ShownAs::ReadClock, ShownAs::UpdateClock, ShownAs::Raw})
        print_truth(shown, truth.report(shown));
}

int run(const RunOptions& o) {
    Session session = Session::load(o.scene, o.layout_file);

    // Outputs are opened before anything runs, so a bad path fails at once.
    std::ofstream trace_out;
    if (o.trace_file) {
        trace_out.open(*o.trace_file);
        if (!trace_out) throw Error(*o.trace_file + ": cannot write the trace file");
    }
    std::optional<MotionRecorder> recorder;
    if (o.record_file) recorder.emplace(*o.record_file);

    session.build();
    const SceneDesc& scene = session.scene;
    const Layout& layout = session.layout;
    const LayoutMapping& mapping = session.mapping;
    Space& space = *session.space;
    const std::vector<BodyHandle>& handles = session.handles;
    const SpaceSettings& settings = space.settings();
    auto* const scheduler = dynamic_cast<WorkStealingJobSystem*>(session.jobs.get());
    std::vector<GameSpan> frames;  // the game thread's side of the trace
    if (o.trace_file) {
        if (!scheduler)
            throw Error("--trace: the trace comes from the work-stealing scheduler, which make_jobs did not choose");
        scheduler->enable_trace(true);
        frames.reserve(static_cast<std::size_t>(o.seconds * o.render_hz) + 16);
    }
    std::vector<std::uint32_t> moving;
    for (std::uint32_t i = 0; i < scene.bodies.size(); ++i) {
        if (scene.bodies[i].desc.type != MotionType::Static) moving.push_back(i);
    }

    AsyncRunnerOptions runner_options = session.runner_options();
    runner_options.sleep_when_idle = o.idle == "sleep";
    PhysicsProbe probe;  // before the runner: its posted function points at the probe
    AsyncRunner runner(space, runner_options);
    probe.attach(runner, o.idle == "poll" ? kPollInterval : 0.0);

    std::vector<MotionState> interpolated(handles.size()), by_update(handles.size()), raw(handles.size());
    MotionTruthMeter truth(moving, kTruthBodies);
    Progress progress(stdout, isatty(fileno(stdout)) != 0);
    const double step_seconds = settings.time_step.duration;
    const MotionStateManager& states = space.motion_states();
    GameStats game;

    std::optional<Player> player;
    if (o.play) {
        Aabb bounds;
        for (const SceneBody& body : scene.bodies) {
            if (body.desc.type != MotionType::Static) bounds.include(body.desc.position);
        }
        if (!bounds.valid()) bounds = {Vec3(-5, 0, -5), Vec3(5, 5, 5)};
        player.emplace(space, runner, bounds);
    }

    runner.start();
    const Stopwatch wall;
    const double period = 1.0 / o.render_hz;
    double deadline = 0;
    double last_print_time = 0;
    std::uint64_t last_print_steps = 0;
    ProgressSample sample;
    while (deadline < o.seconds) {
        wait_until(wall, deadline);
        const std::int64_t frame_start = now_nanoseconds();
        const double now = wall.elapsed_seconds();
        {
            // One hold: the frame as the game shows it (blended at the read), beside what
            // the seed's blend and the newest step would have shown at the same instant.
            const MotionStateLock::Hold hold(states.lock());
            states.get_motion_states(handles, interpolated, BlendClock::Read);
            states.get_motion_states(handles, by_update, BlendClock::Update);
            states.get_raw_motion_states(handles, raw);
            truth.add_frame(states.published_time(), states.lock().taken_at_ns(), states.alpha_locked(BlendClock::Read),
                            {interpolated, by_update, raw});
        }
        if (recorder) recorder->write_frame(game.frames, now, interpolated);
        if (player) player->frame(now);
        const std::int64_t frame_end = now_nanoseconds();
        if (o.trace_file) frames.push_back({"Frame", frame_start, frame_end});

        const double frame_ms = static_cast<double>(frame_end - frame_start) * 1e-6;
        game.frames += 1;
        game.frame_ms_sum += frame_ms;
        game.frame_ms_max = std::max(game.frame_ms_max, frame_ms);
        if (progress.due(now)) {
            const std::uint64_t steps = states.published_steps();
            sample.wall_seconds = now;
            sample.simulated_seconds = static_cast<double>(steps) * step_seconds;
            sample.steps_per_second =
                now > last_print_time ? static_cast<double>(steps - last_print_steps) / (now - last_print_time) : 0;
            sample.awake_bodies = probe.awake_bodies();
            sample.contacts = probe.contacts();
            sample.update_ms = probe.last_step_update_ms();
            sample.frame_ms = frame_ms;
            progress.print(sample);
            last_print_time = now;
            last_print_steps = steps;
        }
        deadline += period;
        if (now - deadline > period) {  // more than a frame behind: start again from now
            game.late_frames += 1;
            deadline = now;
        }
    }
    game.wall_seconds = wall.elapsed_seconds();
    runner.stop();
    progress.finish();

    print_summary(scene, layout, o, game, runner.stats(), probe.totals(), step_seconds, truth);
    if (player) print_play(player->stats(), space.counters());
    if (recorder) {
        recorder->close();
        std::printf("  record         %s (%llu frames x %zu bodies)\n", o.record_file->c_str(),
                    static_cast<unsigned long long>(game.frames), handles.size());
    }
    if (o.trace_file) {
        const std::vector<TraceEvent> events = scheduler->trace_events();
        const std::vector<unsigned> pus = scheduler_pus(mapping);
        write_run_trace(trace_out, events, frames, mapping, pus);
        trace_out.close();
        if (!trace_out) throw Error(*o.trace_file + ": writing the trace file failed");
        std::printf("  trace          %s (%zu spans)\n", o.trace_file->c_str(), events.size() + frames.size());
    }
    return 0;
}

}  // namespace

Command add_run_command(CLI::App& program) {
    CLI::App* cli = program.add_subcommand("run", "play a scene asynchronously, like a game (the default command)");
    cli->footer("Plays SCENE asynchronously: the game thread renders interpolated motion states while the\n"
                "physics loop thread steps the space with internal time stepping. Prints progress and a\n"
                "summary. `spindle` without a command runs the default scene for 5 s.");
    auto o = std::make_shared<RunOptions>();
    cli->add_option("--layout", o->layout_file,
                    "affinity layout (configs/layouts/*.toml); default: this machine, all PUs")
        ->option_text("FILE")
        ->check(not_an_option());
    cli->add_option("--seconds", o->seconds, "how long to run, wall clock, 0.01 to 1000000 (default 5)")
        ->option_text("S")
        ->check(real_in(0.01, 1e6));
    cli->add_option("--render-hz", o->render_hz,
                    "frames per second the game thread reads states at, 1 to 1000 (default 60)")
        ->option_text("HZ")
        ->check(real_in(1, 1000));
    cli->add_option("--idle", o->idle,
                    "what the physics loop does between steps: poll (update every 0.5 ms, so\n"
                    "every frame gets a fresh interpolation; default), spin (update without\n"
                    "pause, the seed's loop; burns its hardware thread) or sleep (until the\n"
                    "next step is due: publishes only at steps, little to interpolate)")
        ->option_text("MODE")
        ->check(CLI::IsMember({"poll", "spin", "sleep"}));
    cli->add_flag("--play", o->play,
                  "play as a game would on the game thread: each frame a ray picks a target and\n"
                  "checks the line of sight, an overlap counts the bodies in a trigger box; six\n"
                  "times a second a ball is shot at the target (layer 1); the summary counts them");
    cli->add_option("--trace", o->trace_file, "write a Chrome trace-event JSON of the run (open in Perfetto)")
        ->option_text("FILE")
        ->check(not_an_option());
    cli->add_option("--record", o->record_file,
                    "write every rendered frame's motion states as CSV:\n"
                    "frame,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz")
        ->option_text("FILE")
        ->check(not_an_option());
    // After the options: CLI11 checks in this order, and a FILE option that took the next option
    // as its value ("missing value") says more than the positional it left over.
    cli->add_option("SCENE", o->scene,
                    "a built-in scene (see `spindle scenes`) or a .toml scene file (default " +
                        std::string(kDefaultScene) + ")")
        ->type_name("")
        ->check(check_scene);
    return {cli, [o] { return run(*o); }};
}

}  // namespace spindle::app
