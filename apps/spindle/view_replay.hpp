// RecordPlayer: `spindle view --replay FILE SCENE` plays a `spindle run --record` file
// (recorder.hpp) on the view page: the scene gives the shapes, the record the poses of
// every rendered frame. The page can pause, step a frame, change the speed and seek.
#pragma once

#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/scene/scene.hpp>

#include "view_frames.hpp"
#include "view_server.hpp"

namespace spindle::app {

class RecordPlayer {
public:
    // Reads the whole record; spindle::Error "FILE:LINE: what was wrong" for a malformed
    // one, or one whose frames do not hold one row per body of the scene, in order.
    RecordPlayer(const SceneDesc& scene, const std::string& path);

    // Publishes the scene and the first frame, so the page has something from the start.
    void attach(ViewServer& server);
    // Plays at render_hz until `seconds` of wall time (none: until stop_requested).
    void run(double render_hz, std::optional<double> seconds, const std::atomic<bool>& stop_requested);

private:
    void apply(const ViewCommand& command);
    std::size_t frame_at(double time) const;  // the last frame recorded at or before time
    void publish();

    const SceneDesc& m_scene;
    std::string m_path;
    std::size_t m_bodies = 0;
    std::vector<double> m_times;        // per frame, from the first frame's
    std::vector<MotionState> m_states;  // m_bodies per frame
    ViewServer* m_server = nullptr;
    double m_clock = 0;  // record time shown
    double m_speed = 1;
    bool m_paused = false;
};

}  // namespace spindle::app
