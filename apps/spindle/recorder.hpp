// MotionRecorder: `spindle run --record FILE` writes the motion states of every
// rendered frame as CSV, one row per body per frame:
//   frame,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz
// time: seconds since the run started (wall clock, when the frame was read); body: the
// body's index in the scene (file order, generators expanded).
#pragma once

#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <spindle/engine/body.hpp>

namespace spindle::app {

class MotionRecorder {
public:
    // Opens (truncates) the file and writes the header; spindle::Error if it cannot.
    explicit MotionRecorder(const std::string& path);
    ~MotionRecorder();
    MotionRecorder(const MotionRecorder&) = delete;
    MotionRecorder& operator=(const MotionRecorder&) = delete;

    void write_frame(std::uint64_t frame, double time, std::span<const MotionState> states);
    // Flushes and closes; spindle::Error if anything could not be written.
    void close();

private:
    std::string m_path;
    std::FILE* m_file = nullptr;
    std::vector<char> m_line;
};

}  // namespace spindle::app
