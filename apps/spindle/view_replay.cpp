// RecordPlayer: a `--record` CSV played on the view page (view_replay.hpp).
#include "view_replay.hpp"

#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "session.hpp"

namespace spindle::app {
namespace {

constexpr std::string_view kHeader = "frame,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz";
constexpr std::size_t kColumns = 13;

// The row's 13 numbers, or false when it has another count or a field is not a number.
bool read_row(std::string_view line, std::array<double, kColumns>& out) {
    std::size_t column = 0;
    while (column < kColumns) {
        const std::size_t comma = line.find(',');
        const std::string_view field = line.substr(0, comma);
        const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), out[column]);
        if (error != std::errc() || end != field.data() + field.size() || !std::isfinite(out[column])) return false;
        ++column;
        if (comma == std::string_view::npos) break;
        line.remove_prefix(comma + 1);
    }
    return column == kColumns && line.find(',') == std::string_view::npos;
}

}  // namespace

RecordPlayer::RecordPlayer(const SceneDesc& scene, const std::string& path)
    : m_scene(scene), m_path(path), m_bodies(scene.bodies.size()) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot read the record file");
    std::string line;
    std::size_t number = 1;
    const auto fail = [&](const std::string& what) { return Error(path + ":" + std::to_string(number) + ": " + what); };
    if (!std::getline(in, line) || line != kHeader) {
        throw fail("not a `spindle run --record` file: the first line must be " + std::string(kHeader));
    }
    std::array<double, kColumns> row{};
    double frame = -1;
    std::size_t body = 0;
    while (std::getline(in, line)) {
        ++number;
        if (line.empty()) continue;
        if (!read_row(line, row)) throw fail("expected 13 comma-separated numbers");
        if (row[0] != frame) {
            if (!m_times.empty() && body != m_bodies) {
                throw fail("frame " + std::to_string(static_cast<long long>(frame)) + " has " + std::to_string(body) +
                           " bodies; scene " + m_scene.name + " has " + std::to_string(m_bodies) +
                           " (replay a record with the scene it was made of)");
            }
            if (!m_times.empty() && row[1] < m_times.back()) throw fail("time goes backwards");
            frame = row[0];
            body = 0;
            m_times.push_back(row[1]);
        }
        if (row[2] != static_cast<double>(body) || body >= m_bodies) {
            throw fail("expected body " + std::to_string(body) + " of scene " + m_scene.name + " (" +
                       std::to_string(m_bodies) + " bodies)");
        }
        MotionState s;
        s.position = Vec3(row[3], row[4], row[5]);
        s.orientation = Quat(row[6], row[7], row[8], row[9]);
        if (!(s.orientation.norm() > 0.5)) throw fail("orientation is not a unit quaternion");
        s.orientation.normalize();
        s.linear_velocity = Vec3(row[10], row[11], row[12]);
        m_states.push_back(s);
        ++body;
    }
    if (m_times.empty()) throw fail("the record holds no frames");
    if (body != m_bodies) throw fail("the last frame is cut short");
    const double start = m_times.front();
    for (double& t : m_times) t -= start;
}

void RecordPlayer::attach(ViewServer& server) {
    m_server = &server;
    std::vector<ViewBody> bodies;
    for (const SceneBody& b : m_scene.bodies) {
        bodies.push_back({b.shape, b.desc.type != MotionType::Static, false, b.desc.sensor});
    }
    server.publish_scene(scene_json(1, m_scene.name + " (replay)", m_scene.shapes, bodies));
    publish();
}

std::size_t RecordPlayer::frame_at(double time) const {
    const auto after = std::upper_bound(m_times.begin(), m_times.end(), time);
    return after == m_times.begin() ? 0 : static_cast<std::size_t>(after - m_times.begin()) - 1;
}

void RecordPlayer::apply(const ViewCommand& command) {
    switch (command.action) {
        case ViewAction::Pause: m_paused = true; break;
        case ViewAction::Resume:
            m_paused = false;
            if (m_clock >= m_times.back()) m_clock = 0;  // resuming at the end plays it again
            break;
        case ViewAction::Step: {
            m_paused = true;
            const std::size_t next = std::min(frame_at(m_clock) + 1, m_times.size() - 1);
            m_clock = m_times[next];
            break;
        }
        case ViewAction::Speed: m_speed = command.value; break;
        case ViewAction::Seek: m_clock = std::min(command.value, m_times.back()); break;
        default: break;  // the parser lets only the replay's commands through
    }
}

void RecordPlayer::publish() {
    const std::size_t f = frame_at(m_clock);
    FrameHeader header;
    header.scene_version = 1;
    header.flags = kFrameReplay | (m_paused ? kFramePaused : 0u);
    header.simulated_seconds = m_times[f];
    header.steps = static_cast<double>(f);
    const std::span<const MotionState> states(m_states.data() + f * m_bodies, m_bodies);
    m_server->publish_frame(encode_frame(header, states, {}, {}));

    char json[256];
    std::snprintf(json, sizeof json,
                  "{\"replay\":true,\"mode\":\"%s\",\"speed\":%g,\"time\":%.6g,\"duration\":%.6g,\"frame\":%zu,"
                  "\"frames\":%zu,\"bodies\":%zu}",
                  m_paused ? "paused" : "playing", m_speed, m_times[f], m_times.back(), f, m_times.size(), m_bodies);
    m_server->publish_stats(json);
}

void RecordPlayer::run(double render_hz, std::optional<double> seconds, const std::atomic<bool>& stop_requested) {
    const double period = 1.0 / render_hz;
    const Stopwatch wall;
    double deadline = 0;
    while (!stop_requested.load(std::memory_order_relaxed) && (!seconds || deadline < *seconds)) {
        wait_until(wall, deadline);
        for (const ViewCommand& command : m_server->take_commands()) apply(command);
        if (!m_paused) {
            m_clock += period * m_speed;
            if (m_clock >= m_times.back()) {  // the end: hold the last frame
                m_clock = m_times.back();
                m_paused = true;
            }
        }
        publish();
        deadline += period;
        const double now = wall.elapsed_seconds();
        if (now - deadline > period) deadline = now;
    }
}

}  // namespace spindle::app
