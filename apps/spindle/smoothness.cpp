// SmoothnessMeter: frame-to-frame displacement and its jerk.
#include "smoothness.hpp"

#include <cmath>

namespace spindle::app {

void SmoothnessMeter::add_frame(std::span<const MotionState> states) {
    if (m_bodies.empty()) return;
    if (!m_has_previous) {
        m_previous.resize(m_bodies.size());
        for (std::size_t i = 0; i < m_bodies.size(); ++i) m_previous[i] = states[m_bodies[i]].position;
        m_has_previous = true;
        return;
    }
    double sum = 0;
    for (std::size_t i = 0; i < m_bodies.size(); ++i) {
        const Vec3& p = states[m_bodies[i]].position;
        sum += (p - m_previous[i]).norm();
        m_previous[i] = p;
    }
    const double step = sum / static_cast<double>(m_bodies.size());
    m_frames += 1;
    m_sum_step += step;
    if (step == 0) m_frozen += 1;
    if (m_has_step) {
        const double jerk = step - m_last_step;
        m_sum_jerk_squared += jerk * jerk;
        m_jerk_samples += 1;
    }
    m_last_step = step;
    m_has_step = true;
}

SmoothnessReport SmoothnessMeter::report() const {
    SmoothnessReport r;
    r.frames = m_frames;
    r.frozen_frames = m_frozen;
    if (m_frames > 0) r.mean_step_m = m_sum_step / static_cast<double>(m_frames);
    if (m_jerk_samples > 0) r.jerk_rms_m = std::sqrt(m_sum_jerk_squared / static_cast<double>(m_jerk_samples));
    if (r.mean_step_m > 0) r.relative_jerk = r.jerk_rms_m / r.mean_step_m;
    return r;
}

}  // namespace spindle::app
