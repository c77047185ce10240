// MotionTruthMeter: frames against the recorded steps around their instants.
#include "motion_truth.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace spindle::app {

const char* to_string(ShownAs shown) noexcept {
    switch (shown) {
        case ShownAs::ReadClock: return "blend at read";
        case ShownAs::UpdateClock: return "blend at update";
        case ShownAs::Raw: return "raw steps";
        case ShownAs::Count: break;
    }
    return "?";
}

MotionTruthMeter::MotionTruthMeter(const std::vector<std::uint32_t>& bodies, std::size_t max_sampled) {
    const std::size_t n = std::min(bodies.size(), max_sampled);
    for (std::size_t k = 0; k < n; ++k) m_sampled.push_back(bodies[k * bodies.size() / n]);
}

void MotionTruthMeter::add_frame(
    const PublishedTime& time, std::int64_t at_ns, double read_alpha,
    const std::array<std::span<const MotionState>, static_cast<std::size_t>(ShownAs::Count)>& shown) {
    // Without the update's clock (updates that do not follow real time) there is no
    // frame instant to compare with.
    if (time.clock_ns == 0 || time.steps == 0 || m_sampled.empty()) return;
    m_has_clock = true;
    m_step_seconds = time.step_seconds;
    const double step = time.step_seconds;
    const auto newest = static_cast<double>(time.steps);
    auto sample = [&](std::span<const MotionState> states) {
        std::vector<Vec3> out(m_sampled.size());
        for (std::size_t k = 0; k < m_sampled.size(); ++k) out[k] = states[m_sampled[k]].position;
        return out;
    };
    const auto raw = static_cast<std::size_t>(ShownAs::Raw);
    if (!m_steps.contains(time.steps)) m_steps.emplace(time.steps, sample(shown[raw]));

    Frame f;
    f.instant = (newest + time.banked_alpha) * step +
                static_cast<double>(at_ns - time.clock_ns) * 1e-9 * time.clock_rate;
    auto blended_instant = [&](double alpha) { return alpha < 1 ? (newest - 1 + alpha) * step : newest * step; };
    f.shown_instant[static_cast<std::size_t>(ShownAs::ReadClock)] = blended_instant(read_alpha);
    f.shown_instant[static_cast<std::size_t>(ShownAs::UpdateClock)] = blended_instant(time.banked_alpha);
    f.shown_instant[raw] = newest * step;
    for (std::size_t k = 0; k < f.positions.size(); ++k) f.positions[k] = sample(shown[k]);
    m_frames.push_back(std::move(f));
}

TruthReport MotionTruthMeter::report(ShownAs shown) const {
    const auto k = static_cast<std::size_t>(shown);
    TruthReport r;
    std::vector<double> errors;
    double lag_sum = 0, lag_squares = 0;
    for (const Frame& f : m_frames) {
        // The recorded steps around the frame's instant: at most two steps apart (a
        // step no frame saw is bridged, a longer gap is no reference).
        const double at = f.instant / m_step_seconds;
        auto after = m_steps.upper_bound(static_cast<std::uint64_t>(std::floor(at)));
        if (after == m_steps.end() || after == m_steps.begin()) continue;
        const auto before = std::prev(after);
        if (after->first - before->first > 2) continue;
        const double w = (at - static_cast<double>(before->first)) / static_cast<double>(after->first - before->first);
        r.frames += 1;
        const double lag = f.instant - f.shown_instant[k];
        lag_sum += lag;
        lag_squares += lag * lag;
        for (std::size_t b = 0; b < f.positions[k].size(); ++b) {
            const Vec3& p0 = before->second[b];
            const Vec3& p1 = after->second[b];
            if ((p1 - p0).squaredNorm() < 1e-12) continue;  // at rest: nothing to show
            const Vec3 reference = p0 + (p1 - p0) * w;
            errors.push_back((f.positions[k][b] - reference).norm());
        }
    }
    if (r.frames > 0) {
        const auto n = static_cast<double>(r.frames);
        r.lag_mean_ms = lag_sum / n * 1e3;
        r.lag_jitter_ms = std::sqrt(std::max(0.0, lag_squares / n - (lag_sum / n) * (lag_sum / n))) * 1e3;
    }
    r.samples = errors.size();
    if (!errors.empty()) {
        double sum = 0;
        for (double e : errors) sum += e;
        r.error_mean_m = sum / static_cast<double>(errors.size());
        const auto p95 = static_cast<std::ptrdiff_t>(0.95 * static_cast<double>(errors.size() - 1));
        std::nth_element(errors.begin(), errors.begin() + p95, errors.end());
        r.error_p95_m = errors[static_cast<std::size_t>(p95)];
    }
    return r;
}

}  // namespace spindle::app
