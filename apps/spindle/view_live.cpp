// LiveView: the game thread of `spindle view` (view_live.hpp).
#include "view_live.hpp"

#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/platform/clock.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

#include "jobs.hpp"

namespace spindle::app {
namespace {

constexpr std::size_t kMaxShots = 100;   // the oldest shot ball is retired beyond this
constexpr std::size_t kMaxCrates = 400;  // and the oldest dropped crate beyond this
constexpr Real kShotBallRadius = 0.25;
constexpr Real kShotBallSpeed = 25;      // m/s
constexpr Real kRayLength = 1000;        // m: picks and shots reach this far
constexpr int kDropCount = 8;            // crates per press of "drop"
constexpr Real kDragGain = 8;            // 1/s: the grabbed body closes this share of the gap per second
constexpr Real kDragMaxSpeed = 30;       // m/s
constexpr double kSurveyInterval = 0.2;  // s between sleep surveys
constexpr double kHitShown = 1.0;        // s a hit stays marked
constexpr std::size_t kMaxHits = 256;
constexpr std::uint32_t kMaxPointsShown = 1u << 13;  // touching points per frame
constexpr double kStatsInterval = 0.5;               // s
// Single steps a frame asks the runner for at most: a page sending a flood of them must
// not queue physics time without end (the rest are dropped and logged).
constexpr int kMaxStepsPerFrame = 4;

ShapeSpec sphere_spec(Real radius) {
    ShapeSpec s;
    s.type = ShapeType::Sphere;
    s.radius = radius;
    return s;
}

ShapeSpec box_spec(const Vec3& half) {
    ShapeSpec s;
    s.type = ShapeType::Box;
    s.half_extents = half;
    return s;
}

}  // namespace

LiveView::LiveView(Session& session, ViewServer& server, double render_hz)
    : m_session(session),
      m_space(*session.space),
      m_server(server),
      m_period(1.0 / render_hz),
      m_runner(*session.space, [&] {
          AsyncRunnerOptions options = session.runner_options();
          options.sleep_when_idle = false;  // paced by the probe, as `run --idle poll`
          return options;
      }()) {
    m_shapes = session.scene.shapes;
    for (std::size_t i = 0; i < session.scene.bodies.size(); ++i) {
        const SceneBody& b = session.scene.bodies[i];
        m_bodies.push_back({b.shape, b.desc.type != MotionType::Static, false, b.desc.sensor});
    }
    m_handles = session.handles;
    m_ball_shape = add_shape(sphere_spec(kShotBallRadius));
    m_crate_shape = add_shape(box_spec(Vec3(0.3, 0.3, 0.3)));
    m_probe.attach(m_runner, kPollInterval);
    // Something to serve before the first frame's turn: the URL is printed before run().
    publish_frame(0);
    publish_stats(0);
}

std::uint32_t LiveView::add_shape(const ShapeSpec& shape) {
    m_shapes.push_back(shape);
    return static_cast<std::uint32_t>(m_shapes.size() - 1);
}

void LiveView::run(std::optional<double> seconds, const std::atomic<bool>& stop_requested) {
    m_runner.start();
    const Stopwatch wall;
    double deadline = 0;
    while (!stop_requested.load(std::memory_order_relaxed) && (!seconds || deadline < *seconds)) {
        wait_until(wall, deadline);
        const double now = wall.elapsed_seconds();
        m_steps_this_frame = 0;
        for (const ViewCommand& command : m_server.take_commands()) apply(command);
        set_time_scale(m_mode == Mode::Paused ? 0 : m_speed);
        m_paused = pause_taken();
        collect_created();
        pull_grabbed();
        survey_sleep(now);
        read_hits(now);
        publish_frame(now);
        if (now >= m_next_stats) publish_stats(now);
        deadline += m_period;
        if (now - deadline > m_period) deadline = now;  // more than a frame behind: start again from now
    }
    if (m_runner.running()) m_runner.stop();
}

void LiveView::apply(const ViewCommand& command) {
    switch (command.action) {
        case ViewAction::Pause: m_mode = Mode::Paused; break;
        case ViewAction::Resume: m_mode = m_speed < 1 ? Mode::Slow : Mode::Running; break;
        case ViewAction::Step:
            m_mode = Mode::Paused;
            set_time_scale(0);  // before the step's time, so the loop adds nothing more
            if (++m_steps_this_frame <= kMaxStepsPerFrame) {
                m_runner.advance(m_space.settings().time_step.duration);
            } else if (m_steps_this_frame == kMaxStepsPerFrame + 1) {
                std::fprintf(stderr, "spindle view: dropped single steps beyond %d in one frame\n", kMaxStepsPerFrame);
            }
            break;
        case ViewAction::Speed:
            m_speed = command.value;
            if (m_mode != Mode::Paused) m_mode = m_speed < 1 ? Mode::Slow : Mode::Running;
            break;
        case ViewAction::Interpolate: m_interpolate = command.value != 0; break;
        case ViewAction::Contacts: show_contacts(command.value != 0); break;
        case ViewAction::Shoot: shoot(command.origin, command.direction); break;
        case ViewAction::Grab: grab(command.origin, command.direction); break;
        case ViewAction::Drag: drag(command.origin, command.direction); break;
        case ViewAction::Release: m_grab.reset(); break;
        case ViewAction::Drop: drop(); break;
        case ViewAction::Seek: break;  // the parser keeps it for replays
    }
}

// Pause and slow motion are the runner's clock: physics stays on its own thread. A pause
// is shown once an update at scale 0 has begun (a function posted after the change has
// run): from then on the published steps stand still.
void LiveView::set_time_scale(double scale) {
    if (scale == m_runner.time_scale()) return;
    m_runner.set_time_scale(scale);
    m_pause_taken.reset();
    if (scale == 0 && m_runner.running()) m_pause_taken = m_runner.post([](Space&) {});
}

bool LiveView::pause_taken() const {
    return m_mode == Mode::Paused &&
           (!m_pause_taken || m_pause_taken->wait_for(std::chrono::seconds(0)) == std::future_status::ready);
}

const char* LiveView::mode_name() const {
    switch (m_mode) {
        case Mode::Paused: return paused() ? "paused" : "pausing";
        case Mode::Slow: return "slow";
        default: return "running";
    }
}

// Structure goes through the runner while it runs; once it has stopped (after a failure)
// this thread may make it.
void LiveView::create(const BodyDesc& desc, ViewBody body) {
    if (m_runner.running()) {
        m_pending.push_back({m_runner.post([desc](Space& space) { return space.create_body(desc); }), body});
        return;
    }
    std::promise<BodyHandle> made;
    made.set_value(m_space.create_body(desc));
    m_pending.push_back({made.get_future(), body});
}

void LiveView::destroy(BodyHandle body) {
    const auto gone = [body](Space& space) {
        if (space.contains(body)) space.destroy_body(body);
    };
    if (m_runner.running()) {
        m_runner.post(gone);
    } else {
        gone(m_space);
    }
    const auto at = std::find(m_handles.begin(), m_handles.end(), body);
    if (at == m_handles.end()) return;
    const auto i = at - m_handles.begin();
    m_handles.erase(at);
    m_bodies.erase(m_bodies.begin() + i);
    if (m_grab && m_grab->body == body) m_grab.reset();
    m_version += 1;
    m_scene_dirty = true;
}

// Created bodies join the drawn ones once their posted creation has run.
void LiveView::collect_created() {
    while (!m_pending.empty()) {
        Pending& next = m_pending.front();
        if (next.handle.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
        const BodyHandle handle = next.handle.get();  // rethrows a rejected creation: a bug, not input
        m_handles.push_back(handle);
        m_bodies.push_back(next.body);
        (next.body.projectile ? m_shots : m_crates).push_back(handle);
        m_pending.pop_front();
        m_version += 1;
        m_scene_dirty = true;
    }
    for (auto [added, cap] : {std::pair{&m_shots, kMaxShots}, std::pair{&m_crates, kMaxCrates}}) {
        while (added->size() > cap) {
            const BodyHandle oldest = added->front();
            added->pop_front();
            destroy(oldest);
        }
    }
}

void LiveView::shoot(const Vec3& origin, const Vec3& direction) {
    BodyDesc ball;
    ball.shape = m_shapes[m_ball_shape].make();
    ball.position = origin + direction * (2 * kShotBallRadius);  // clear of the camera's near plane
    ball.linear_velocity = direction * kShotBallSpeed;
    ball.fast = true;
    ball.contact_events = true;
    create(ball, {m_ball_shape, true, true});
    m_shots_fired += 1;
}

void LiveView::grab(const Vec3& origin, const Vec3& direction) {
    m_grab.reset();
    const std::optional<QueryHit> hit = m_space.cast_ray(origin, origin + direction * kRayLength);
    if (!hit) return;
    const auto at = std::find(m_handles.begin(), m_handles.end(), hit->body);
    if (at == m_handles.end() || !m_bodies[static_cast<std::size_t>(at - m_handles.begin())].moving) return;
    m_grab = Grab{hit->body, hit->fraction * kRayLength, hit->point};
    m_picks += 1;
}

void LiveView::drag(const Vec3& origin, const Vec3& direction) {
    if (m_grab) m_grab->target = origin + direction * m_grab->distance;
}

// A buffered velocity toward the cursor each frame, so the body follows it through
// contacts instead of teleporting into them.
void LiveView::pull_grabbed() {
    if (!m_grab) return;
    if (!m_space.contains(m_grab->body)) {
        m_grab.reset();
        return;
    }
    Vec3 velocity = (m_grab->target - m_space.position(m_grab->body)) * kDragGain;
    if (velocity.norm() > kDragMaxSpeed) velocity *= kDragMaxSpeed / velocity.norm();
    m_space.set_linear_velocity(m_grab->body, velocity);
    m_space.set_angular_velocity(m_grab->body, m_space.angular_velocity(m_grab->body) * 0.9);
    m_space.wake(m_grab->body);
}

// Crates above the middle of the scene's moving bodies.
void LiveView::drop() {
    Aabb bounds;
    for (std::size_t i = 0; i < m_session.scene.bodies.size(); ++i) {
        if (m_bodies[i].moving) bounds.include(m_space.position(m_session.handles[i]));
    }
    if (!bounds.valid()) bounds = {Vec3(-2, 0, -2), Vec3(2, 2, 2)};
    std::uniform_real_distribution<Real> spread(-1.5, 1.5);
    for (int i = 0; i < kDropCount; ++i) {
        BodyDesc crate;
        crate.shape = m_shapes[m_crate_shape].make();
        crate.position = Vec3(bounds.center().x() + spread(m_random), bounds.max.y() + 2 + 0.8 * i,
                              bounds.center().z() + spread(m_random));
        crate.contact_events = true;
        create(crate, {m_crate_shape, true, false});
    }
    m_dropped += kDropCount;
}

// The space publishes its touching points only while the page draws them (a pass over
// the contacts per update otherwise saved); a settings change is structural: posted.
void LiveView::show_contacts(bool on) {
    if (on == m_contacts) return;
    m_contacts = on;
    const auto change = [on](Space& space) {
        EventSettings events = space.settings().events;
        events.publish_contact_points = on;
        events.max_contact_points = kMaxPointsShown;
        space.set_events(events);
    };
    if (m_runner.running()) {
        m_runner.post(change);
    } else {
        change(m_space);
    }
    m_points.clear();
}

void LiveView::survey_sleep(double now) {
    if (m_survey && m_survey->wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
        std::vector<std::uint8_t> asleep = m_survey->get();
        m_survey.reset();
        if (m_survey_version == m_version) m_asleep = std::move(asleep);
    }
    if (m_survey || now < m_next_survey) return;
    m_next_survey = now + kSurveyInterval;
    m_survey_version = m_version;
    std::vector<BodyHandle> handles = m_handles;
    std::vector<std::uint8_t> moving(m_bodies.size());
    for (std::size_t i = 0; i < m_bodies.size(); ++i) moving[i] = m_bodies[i].moving;
    auto survey = [handles = std::move(handles), moving = std::move(moving)](Space& space) {
        std::vector<std::uint8_t> asleep(handles.size());
        for (std::size_t i = 0; i < handles.size(); ++i) {
            asleep[i] = moving[i] && space.contains(handles[i]) && !space.internal_is_awake(handles[i]);
        }
        return asleep;
    };
    if (m_runner.running()) {
        m_survey = m_runner.post(std::move(survey));
    } else {
        std::promise<std::vector<std::uint8_t>> done;
        done.set_value(survey(m_space));
        m_survey = done.get_future();
    }
}

void LiveView::read_hits(double now) {
    m_events.clear();
    m_space.read_contact_events(m_events);
    for (const ContactEvent& e : m_events) {
        m_begins += e.kind == ContactEventKind::Begin;
        m_ends += e.kind == ContactEventKind::End;
        if (e.kind != ContactEventKind::Hit) continue;
        m_hit_count += 1;
        m_hits.push_back({{e.point, e.normal, 0}, now});
    }
    while (!m_hits.empty() && (m_hits.size() > kMaxHits || now - m_hits.front().time > kHitShown)) m_hits.pop_front();
}

void LiveView::publish_frame(double now) {
    if (m_scene_dirty) {
        m_server.publish_scene(scene_json(m_version, m_session.scene.name, m_shapes, m_bodies));
        m_scene_dirty = false;
    }
    m_states.resize(m_handles.size());
    const MotionStateManager& states = m_space.motion_states();
    if (m_interpolate) {
        states.get_motion_states(m_handles, m_states);
    } else {
        states.get_raw_motion_states(m_handles, m_states);
    }
    std::vector<ContactMark> marks;
    if (m_contacts) m_space.read_contact_points(m_points);
    marks.reserve(m_hits.size() + m_points.size());
    for (const Hit& h : m_hits) marks.push_back({h.mark.point, h.mark.normal, now - h.time});
    for (const ContactPointInfo& p : m_points) marks.push_back({p.point, p.normal, 0});
    FrameHeader header;
    header.scene_version = m_version;
    header.flags = (paused() ? kFramePaused : 0u) | (m_mode == Mode::Slow ? kFrameSlow : 0u) |
                   (m_interpolate ? kFrameInterpolated : 0u);
    const double steps = static_cast<double>(states.published_steps());
    header.steps = steps;
    header.simulated_seconds = steps * m_space.settings().time_step.duration;
    m_asleep.resize(m_handles.size());  // bodies added since the survey: awake until the next
    m_server.publish_frame(encode_frame(header, m_states, m_asleep, marks));
}

void LiveView::publish_stats(double now) {
    const std::uint64_t steps = m_space.motion_states().published_steps();
    if (now > m_stats_time) {
        m_steps_per_second = static_cast<double>(steps - m_stats_steps) / (now - m_stats_time);
    }
    m_stats_time = now;
    m_stats_steps = steps;
    m_next_stats = now + kStatsInterval;

    char number[64];
    const auto num = [&number](double v) {
        std::snprintf(number, sizeof number, "%.6g", v);
        return std::string(number);
    };
    std::string json = "{\"mode\":\"";
    json += mode_name();
    json += "\",\"speed\":" + num(m_speed) + ",\"interpolate\":" + (m_interpolate ? "true" : "false");
    json += ",\"steps\":" + std::to_string(steps) + ",\"steps_per_second\":" + num(m_steps_per_second);
    json += ",\"bodies\":" + std::to_string(m_handles.size()) + ",\"awake\":" + std::to_string(m_probe.awake_bodies());
    json += ",\"contacts\":" + std::to_string(m_probe.contacts()) +
            ",\"update_ms\":" + num(m_probe.last_step_update_ms());
    json += ",\"stages\":[";
    for (int i = 0; i < static_cast<int>(Stage::Count); ++i) {
        if (i) json += ',';
        json += "[" + json_string(to_string(static_cast<Stage>(i))) + "," +
                num(m_probe.recent_stage_ms(static_cast<Stage>(i))) + "]";
    }
    const LayoutMapping& mapping = m_session.mapping;
    json += "],\"layout\":" + json_string(m_session.layout.name) +
            ",\"game_pu\":" + std::to_string(mapping.game.real_pu) +
            ",\"physics_pu\":" + std::to_string(mapping.physics.real_pu) + ",\"worker_pus\":[";
    const std::vector<unsigned> pus = scheduler_pus(mapping);
    for (std::size_t i = 0; i < pus.size(); ++i) json += (i ? "," : "") + std::to_string(pus[i]);
    json += "],\"shots\":" + std::to_string(m_shots_fired) + ",\"dropped\":" + std::to_string(m_dropped) +
            ",\"picks\":" + std::to_string(m_picks) + ",\"grabbing\":" + (m_grab ? "true" : "false") +
            ",\"begins\":" + std::to_string(m_begins) + ",\"ends\":" + std::to_string(m_ends) +
            ",\"hits\":" + std::to_string(m_hit_count) + ",\"contact_points\":" + std::to_string(m_points.size()) +
            ",\"refused\":" + std::to_string(m_server.refused()) + "}";
    m_server.publish_stats(std::move(json));
}

}  // namespace spindle::app
