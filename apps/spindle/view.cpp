// `spindle view`: the scene live in a browser (issue 20). The program serves a page on
// 127.0.0.1 (view_server.hpp) and its main thread is the game thread: it plays the
// scene as `spindle run` does and streams the interpolated poses to the page at the
// render rate (view_live.hpp), or plays a `spindle run --record` file (view_replay.hpp).
#include <spindle/engine/motion_state_manager.hpp>

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "checks.hpp"
#include "commands.hpp"
#include "scenes.hpp"
#include "session.hpp"
#include "view_live.hpp"
#include "view_replay.hpp"
#include "view_server.hpp"

namespace spindle::app {
namespace {

struct ViewOptions {
    std::string scene{kDefaultScene};
    std::optional<std::string> layout_file;
    int port = 8090;
    double render_hz = 60;
    std::optional<double> seconds;
    std::optional<std::string> replay_file;
};

std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

extern "C" void request_stop(int) { g_stop_requested.store(true, std::memory_order_relaxed); }

// Ctrl-C (or a kill) ends the view as --seconds would: the runner stops cleanly, the
// server closes, and the program says what it served.
class StopOnSignal {
public:
    StopOnSignal() : m_int(std::signal(SIGINT, request_stop)), m_term(std::signal(SIGTERM, request_stop)) {}
    ~StopOnSignal() {
        std::signal(SIGINT, m_int);
        std::signal(SIGTERM, m_term);
    }
    StopOnSignal(const StopOnSignal&) = delete;
    StopOnSignal& operator=(const StopOnSignal&) = delete;

private:
    void (*m_int)(int);
    void (*m_term)(int);
};

void announce(const ViewServer& server, const std::optional<double>& seconds) {
    char until[64] = "Ctrl-C stops";
    if (seconds) std::snprintf(until, sizeof until, "stops after %g s", *seconds);
    std::printf("view: http://127.0.0.1:%d/ (open it in a browser; %s)\n", server.port(), until);
    std::fflush(stdout);
}

int view(const ViewOptions& o) {
    const StopOnSignal stop_on_signal;
    if (o.replay_file) {
        const SceneDesc scene = resolve_scene(o.scene);
        RecordPlayer player(scene, *o.replay_file);  // a bad record fails before the port opens
        ViewServer server(o.port, view_assets(), /*replay=*/true);
        player.attach(server);
        announce(server, o.seconds);
        player.run(o.render_hz, o.seconds, g_stop_requested);
        std::printf("view: replay ended, %llu requests refused\n", static_cast<unsigned long long>(server.refused()));
        return 0;
    }
    Session session = Session::load(o.scene, o.layout_file);
    // Every body reports its hits, so the page can mark contacts (the public API publishes
    // contact events, not the solver's contact points).
    for (SceneBody& body : session.scene.bodies) body.desc.contact_events = true;
    ViewServer server(o.port, view_assets(), /*replay=*/false);
    session.build();
    LiveView live(session, server, o.render_hz);
    announce(server, o.seconds);
    live.run(o.seconds, g_stop_requested);
    std::printf("view: stopped after %llu steps, %llu requests refused\n",
                static_cast<unsigned long long>(session.space->motion_states().published_steps()),
                static_cast<unsigned long long>(server.refused()));
    return 0;
}

}  // namespace

Command add_view_command(CLI::App& program) {
    CLI::App* cli = program.add_subcommand("view", "play a scene live in a browser (WebGL), or replay a record");
    cli->footer("Plays SCENE as `spindle run` does and serves a page on 127.0.0.1 that draws it in 3D:\n"
                "orbit with the mouse, click to shoot a ball, drag a body to pull it; pause, step, slow\n"
                "motion, interpolation on or off, contact marks and the stage timings per step. With\n"
                "--replay, plays a `spindle run --record` file of SCENE instead (seek, speed).");
    auto o = std::make_shared<ViewOptions>();
    cli->add_option("--layout", o->layout_file,
                    "affinity layout (configs/layouts/*.toml); default: this machine, all PUs")
        ->option_text("FILE")
        ->check(not_an_option());
    cli->add_option("--port", o->port, "TCP port on 127.0.0.1, 0 to 65535; 0 picks a free one (default 8090)")
        ->option_text("P")
        ->transform(integer_in(0, 65535));
    cli->add_option("--render-hz", o->render_hz,
                    "frames per second the game thread reads states at, 1 to 1000 (default 60)")
        ->option_text("HZ")
        ->check(real_in(1, 1000));
    cli->add_option("--seconds", o->seconds, "stop after this long, wall clock, 0.01 to 1000000 (default: Ctrl-C)")
        ->option_text("S")
        ->check(real_in(0.01, 1e6));
    cli->add_option("--replay", o->replay_file,
                    "play this `spindle run --record` file (CSV) of SCENE instead of simulating")
        ->option_text("FILE")
        ->check(not_an_option());
    cli->add_option("SCENE", o->scene,
                    "a built-in scene (see `spindle scenes`) or a .toml scene file (default " +
                        std::string(kDefaultScene) + ")")
        ->type_name("")
        ->check(check_scene);
    return {cli, [o] { return view(*o); }};
}

}  // namespace spindle::app
