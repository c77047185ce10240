// LiveView: the game thread of `spindle view SCENE`. The physics loop runs in an
// AsyncRunner as in `spindle run`; each frame this thread reads the motion states
// (interpolated, or the newest step's when the page turns blending off), encodes them
// for the page, and acts on the page's commands through the public asynchronous API:
// bodies are created and destroyed by functions posted to the runner, velocities are
// buffered writes, picks are ray casts against the published step.
//
// Pause, single steps and slow motion are the runner's clock (AsyncRunner::set_time_scale
// and advance): physics stays on its own thread throughout, and reads blend at the scaled
// rate, so slow motion is interpolated like real time.
#pragma once

#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/events.hpp>

#include <cstdint>
#include <deque>
#include <future>
#include <optional>
#include <random>
#include <vector>

#include "physics_probe.hpp"
#include "session.hpp"
#include "view_frames.hpp"
#include "view_server.hpp"

namespace spindle::app {

class LiveView {
public:
    // The session must be built; it and the server outlive the view.
    LiveView(Session& session, ViewServer& server, double render_hz);

    // Runs until `seconds` of wall time have passed (none: until stop_requested turns true).
    void run(std::optional<double> seconds, const std::atomic<bool>& stop_requested);

private:
    enum class Mode { Running, Paused, Slow };
    struct Pending {
        std::future<BodyHandle> handle;
        ViewBody body;
    };
    struct Hit {
        ContactMark mark;
        double time = 0;
    };
    struct Grab {
        BodyHandle body;
        double distance = 0;  // along the camera ray, where the body was taken
        Vec3 target = Vec3::Zero();
    };

    void apply(const ViewCommand& command);
    void create(const BodyDesc& desc, ViewBody body);
    void destroy(BodyHandle body);
    void collect_created();
    void shoot(const Vec3& origin, const Vec3& direction);
    void grab(const Vec3& origin, const Vec3& direction);
    void drag(const Vec3& origin, const Vec3& direction);
    void drop();
    void show_contacts(bool on);
    void pull_grabbed();
    void survey_sleep(double now);
    void read_hits(double now);
    void publish_frame(double now);
    void publish_stats(double now);
    void set_time_scale(double scale);
    bool pause_taken() const;  // asked for, and no update at the old scale left
    bool paused() const { return m_paused; }
    const char* mode_name() const;
    std::uint32_t add_shape(const ShapeSpec& shape);

    Session& m_session;
    Space& m_space;
    ViewServer& m_server;
    double m_period;
    PhysicsProbe m_probe;  // before the runner: its posted function points at the probe
    AsyncRunner m_runner;
    Mode m_mode = Mode::Running;
    double m_speed = 1;
    std::optional<std::future<void>> m_pause_taken;  // posted after the scale turned 0
    // pause_taken() as this frame's turn found it, before it read the published step: the
    // frame and the stats made in that turn both show it, so a page that sees "paused"
    // sees the last step there will be (asked again for the stats, a pause taken between
    // the frame and them would show "paused" beside a frame a step old).
    bool m_paused = false;
    bool m_interpolate = true;
    bool m_contacts = false;                 // the page asked for the touching points
    std::vector<ContactPointInfo> m_points;  // the newest step's, when m_contacts
    int m_steps_this_frame = 0;

    // What the page draws, in its order: the scene's bodies, then what the page added.
    std::vector<ShapeSpec> m_shapes;
    std::vector<ViewBody> m_bodies;
    std::vector<BodyHandle> m_handles;
    std::uint32_t m_version = 1;  // of m_bodies; the page fetches the scene when it changes
    bool m_scene_dirty = true;
    std::uint32_t m_ball_shape = 0, m_crate_shape = 0;

    std::deque<Pending> m_pending;  // posted creations, oldest first
    // What the page added, oldest first; the oldest are retired beyond a cap each, so
    // no number of clicks makes the scene grow without bound.
    std::deque<BodyHandle> m_shots, m_crates;
    std::optional<Grab> m_grab;
    std::mt19937 m_random{20};

    // Sleep flags, surveyed on the physics thread (internal_is_awake is the updating
    // thread's) for the bodies as they were at m_survey_version.
    std::optional<std::future<std::vector<std::uint8_t>>> m_survey;
    std::uint32_t m_survey_version = 0;
    double m_next_survey = 0;
    std::vector<std::uint8_t> m_asleep;

    std::vector<ContactEvent> m_events;
    std::deque<Hit> m_hits;
    std::uint64_t m_begins = 0, m_ends = 0, m_hit_count = 0, m_shots_fired = 0, m_dropped = 0, m_picks = 0;
    std::vector<MotionState> m_states;
    double m_next_stats = 0, m_stats_time = 0;
    std::uint64_t m_stats_steps = 0;
    double m_steps_per_second = 0;
};

}  // namespace spindle::app
