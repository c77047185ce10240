// How close rendered motion is to the truth. A rendered frame shows the bodies at some
// instant of simulated time; the truth for that frame is where they were at the frame's
// own instant (the simulated time the runner had reached by then, from the published
// step, its banked time and the clock the update measured it at). The meter keeps what
// each way of reading showed for a sample of moving bodies, and the step states the raw
// reads revealed; at the end it sets every frame beside the reference: the recorded
// steps around the frame's instant, blended linearly.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include <spindle/engine/motion_state_manager.hpp>

namespace spindle::app {

// The ways a frame can be read: blended by the reader's clock, blended as the seed does
// (by the time the last update banked), and the newest step unblended.
enum class ShownAs : std::uint8_t { ReadClock, UpdateClock, Raw, Count };
const char* to_string(ShownAs shown) noexcept;

struct TruthReport {
    std::uint64_t frames = 0;   // frames with recorded steps close around their instant
    std::uint64_t samples = 0;  // body positions compared (bodies moving at that instant)
    double error_mean_m = 0;    // distance from the reference
    double error_p95_m = 0;
    double lag_mean_ms = 0;    // how far the instant shown is behind the frame's instant
    double lag_jitter_ms = 0;  // its standard deviation: what the eye sees as stutter
};

class MotionTruthMeter {
public:
    // `bodies`: indices (into every frame's states) of the bodies that may move; at most
    // `max_sampled` of them, spread evenly, are compared.
    MotionTruthMeter(const std::vector<std::uint32_t>& bodies, std::size_t max_sampled);

    // One frame, read under one hold of the motion-state lock taken at `at_ns`:
    // `shown[k]` is every body's state as read the ShownAs k way.
    void add_frame(const PublishedTime& time, std::int64_t at_ns, double read_alpha,
                   const std::array<std::span<const MotionState>, static_cast<std::size_t>(ShownAs::Count)>& shown);

    TruthReport report(ShownAs shown) const;
    std::uint64_t steps_recorded() const noexcept { return m_steps.size(); }
    bool has_clock() const noexcept { return m_has_clock; }

private:
    struct Frame {
        double instant = 0;                          // simulated seconds the frame stands for
        std::array<double, 3> shown_instant{};       // per ShownAs
        std::array<std::vector<Vec3>, 3> positions;  // per ShownAs, per sampled body
    };
    std::vector<std::uint32_t> m_sampled;
    std::map<std::uint64_t, std::vector<Vec3>> m_steps;  // step count -> sampled positions then
    std::vector<Frame> m_frames;
    double m_step_seconds = 0;
    bool m_has_clock = false;
};

}  // namespace spindle::app
