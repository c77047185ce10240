// The setup `spindle run` and `spindle view` share: a scene and an affinity layout,
// the calling thread pinned as the game thread, the scene built into a Space with
// internal time stepping whose parallel stages run on the scheduler make_jobs() places
// per the layout. The AsyncRunner stays the command's: each drives it its own way.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/layout.hpp>
#include <spindle/scene/scene.hpp>
#include <spindle/scheduler/job_system.hpp>

namespace spindle::app {

struct Session {
    SceneDesc scene;
    Layout layout;
    LayoutMapping mapping;
    std::unique_ptr<JobSystem> jobs;  // before the space, which runs on it
    std::unique_ptr<Space> space;
    std::vector<BodyHandle> handles;  // one per scene body, in scene order

    // Reads the scene (a built-in name or a file) and the layout (none: this machine)
    // and maps the layout onto the machine; builds nothing, so a bad file fails before
    // anything runs (spindle::Error naming file:line:column).
    static Session load(const std::string& scene, const std::optional<std::string>& layout_file);

    // Names and pins the calling thread as the game thread, makes the scheduler and the
    // space, builds the scene and prints what runs where. Once, from the game thread.
    void build();

    // The physics loop's placement for an AsyncRunner over `space`.
    AsyncRunnerOptions runner_options() const;
};

// Sleeps until `deadline` on the stopwatch, the last stretch with yields: a sleeping
// thread wakes up to a scheduler tick late, and that lateness would show as jitter in
// the interpolated poses (a display refreshes on time; a late read shows a later pose).
void wait_until(const Stopwatch& wall, double deadline);

}  // namespace spindle::app
