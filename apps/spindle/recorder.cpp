// MotionRecorder: CSV of rendered motion states, formatted with to_chars (a long run
// writes millions of numbers from the game thread, between frames).
#include "recorder.hpp"

#include <spindle/platform/error.hpp>

#include <cerrno>
#include <charconv>
#include <cstring>

namespace spindle::app {
namespace {

char* put(char* out, char* end, double value) {
    *out++ = ',';
    return std::to_chars(out, end, value, std::chars_format::general, 9).ptr;
}

char* put(char* out, char* end, std::uint64_t value) { return std::to_chars(out, end, value).ptr; }

}  // namespace

MotionRecorder::MotionRecorder(const std::string& path) : m_path(path), m_line(512) {
    m_file = std::fopen(path.c_str(), "w");
    if (!m_file) throw Error(path + ": cannot write the record file: " + std::strerror(errno));
    std::fputs("frame,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz\n", m_file);
}

MotionRecorder::~MotionRecorder() {
    if (m_file) std::fclose(m_file);
}

void MotionRecorder::write_frame(std::uint64_t frame, double time, std::span<const MotionState> states) {
    char* const begin = m_line.data();
    char* const end = begin + m_line.size();
    for (std::size_t i = 0; i < states.size(); ++i) {
        const MotionState& s = states[i];
        char* out = put(begin, end, frame);
        out = put(out, end, time);
        *out++ = ',';
        out = put(out, end, static_cast<std::uint64_t>(i));
        for (const double v :
             {s.position.x(), s.position.y(), s.position.z(), s.orientation.w(), s.orientation.x(), s.orientation.y(),
              s.orientation.z(), s.linear_velocity.x(), s.linear_velocity.y(), s.linear_velocity.z()}) {
            out = put(out, end, v);
        }
        *out++ = '\n';
        std::fwrite(begin, 1, static_cast<std::size_t>(out - begin), m_file);
    }
}

void MotionRecorder::close() {
    if (!m_file) return;
    const bool failed = std::ferror(m_file) != 0;
    const bool close_failed = std::fclose(m_file) != 0;
    m_file = nullptr;
    if (failed || close_failed) throw Error(m_path + ": writing the record file failed");
}

}  // namespace spindle::app
