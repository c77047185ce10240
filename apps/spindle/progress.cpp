// Progress: the live line on a terminal, periodic lines elsewhere.
#include "progress.hpp"

namespace spindle::app {

Progress::Progress(std::FILE* out, bool live) : m_out(out), m_live(live), m_next_print(live ? 0.25 : 1.0) {}

void Progress::print(const ProgressSample& s) {
    m_next_print += m_live ? 0.25 : 1.0;
    if (m_next_print <= s.wall_seconds) m_next_print = s.wall_seconds + (m_live ? 0.25 : 1.0);
    // "\x1b[K" clears what a longer previous line left behind.
    std::fprintf(
        m_out, "%swall %5.1f s  sim %7.2f s  %6.1f steps/s  %6u awake  %6u contacts  update %7.3f ms  frame %6.3f ms%s",
        m_live ? "\r" : "", s.wall_seconds, s.simulated_seconds, s.steps_per_second, s.awake_bodies, s.contacts,
        s.update_ms, s.frame_ms, m_live ? "\x1b[K" : "\n");
    std::fflush(m_out);
    m_printed = true;
}

void Progress::finish() {
    if (m_live && m_printed) std::fputc('\n', m_out);
    std::fflush(m_out);
}

}  // namespace spindle::app
