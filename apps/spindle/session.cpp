// Session: scene, layout and space set up as every playing command needs them.
#include "session.hpp"

#include <spindle/engine/async_runner.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/platform/topology.hpp>

#include <chrono>
#include <cstdio>
#include <thread>

#include "jobs.hpp"
#include "scenes.hpp"

namespace spindle::app {

Session Session::load(const std::string& scene, const std::optional<std::string>& layout_file) {
    Session s;
    s.scene = resolve_scene(scene);
    const Topology real = Topology::from_system();
    s.layout = layout_file ? Layout::load(*layout_file, &real) : Layout::native(real);
    const Topology model = s.layout.model_topology(real);
    s.mapping = map_layout(s.layout, model, real);
    return s;
}

void Session::build() {
    set_current_thread_name("spindle-game");
    pin_current_thread(mapping.game.real_pu);
    jobs = make_jobs(mapping);
    SpaceSettings settings = scene.settings;
    settings.time_step.use_internal_time_stepping = true;
    space = std::make_unique<Space>(settings, jobs.get());
    handles = spindle::build(scene, *space);
    const std::size_t dynamic = scene.dynamic_body_count();
    std::printf("scene %s (%s): %zu dynamic + %zu other bodies; %s\n", scene.name.c_str(), scene.source.c_str(),
                dynamic, scene.bodies.size() - dynamic, scene.description.c_str());
    std::printf("layout %s (%s):\n%s", layout.name.c_str(), layout.source.c_str(), mapping.describe().c_str());
    std::fflush(stdout);
}

AsyncRunnerOptions Session::runner_options() const {
    AsyncRunnerOptions options;
    options.physics_pu = mapping.physics.real_pu;
    return options;
}

void wait_until(const Stopwatch& wall, double deadline) {
    constexpr double kSpinSeconds = 1e-3;
    const double sleep = deadline - kSpinSeconds - wall.elapsed_seconds();
    if (sleep > 0) std::this_thread::sleep_for(std::chrono::duration<double>(sleep));
    while (wall.elapsed_seconds() < deadline) std::this_thread::yield();
}

}  // namespace spindle::app
