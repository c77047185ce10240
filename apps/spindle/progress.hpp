// Progress output while a scene runs: on a terminal one line rewritten in place a few
// times a second; otherwise (a pipe, a log, a test) a plain line once a second.
#pragma once

#include <cstdint>
#include <cstdio>

namespace spindle::app {

struct ProgressSample {
    double wall_seconds = 0;
    double simulated_seconds = 0;
    double steps_per_second = 0;
    std::uint32_t awake_bodies = 0;
    std::uint32_t contacts = 0;
    double update_ms = 0;  // the last physics update that took a step
    double frame_ms = 0;   // the game thread's work for the last frame
};

class Progress {
public:
    // live: rewrite one line in place (the output is a terminal).
    Progress(std::FILE* out, bool live);
    // Whether a line is due at wall time `seconds` (every 0.25 s live, every 1 s otherwise).
    bool due(double seconds) const noexcept { return seconds >= m_next_print; }
    void print(const ProgressSample& sample);
    // Ends the live line so the summary starts on a fresh one.
    void finish();

private:
    std::FILE* m_out;
    bool m_live;
    double m_next_print = 0;
    bool m_printed = false;
};

}  // namespace spindle::app
