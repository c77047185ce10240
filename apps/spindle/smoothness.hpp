// How smooth rendered motion looks: per rendered frame, the mean displacement of the
// moving bodies since the previous frame; smooth motion changes it little from frame
// to frame, stutter (a frame with no new step, then one with two) changes it a lot.
// The run measures interpolated states and raw newest-step states side by side.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <spindle/engine/body.hpp>

namespace spindle::app {

struct SmoothnessReport {
    std::uint64_t frames = 0;         // frames with a previous frame to compare with
    double mean_step_m = 0;           // mean per-frame displacement (m)
    double jerk_rms_m = 0;            // RMS of the frame-to-frame change of that displacement (m)
    double relative_jerk = 0;         // jerk_rms / mean_step: scale-free, 0 = perfectly even
    std::uint64_t frozen_frames = 0;  // frames showing exactly the previous frame's poses
};

class SmoothnessMeter {
public:
    // `bodies`: indices (into the states of every frame) of the bodies to measure.
    explicit SmoothnessMeter(std::vector<std::uint32_t> bodies) : m_bodies(std::move(bodies)) {}

    void add_frame(std::span<const MotionState> states);
    SmoothnessReport report() const;

private:
    std::vector<std::uint32_t> m_bodies;
    std::vector<Vec3> m_previous;
    bool m_has_previous = false;
    bool m_has_step = false;
    double m_last_step = 0;
    std::uint64_t m_frames = 0;
    std::uint64_t m_jerk_samples = 0;
    std::uint64_t m_frozen = 0;
    double m_sum_step = 0;
    double m_sum_jerk_squared = 0;
};

}  // namespace spindle::app
