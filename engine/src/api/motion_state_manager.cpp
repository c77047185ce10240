// MotionStateManager: locked copies out of the published buffer, and the flip.
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>

namespace spindle {

MotionState MotionStateManager::blend(const PublishedBody& body, double alpha) {
    if (!body.interpolate || alpha >= 1) return body.current;
    MotionState s = body.current;
    const Real t = alpha;
    s.position = body.previous_position + (body.current.position - body.previous_position) * t;
    s.center_of_mass = body.previous_center_of_mass + (body.current.center_of_mass - body.previous_center_of_mass) * t;
    s.orientation = slerp_shortest(body.previous_orientation, body.current.orientation, t);
    return s;
}

const PublishedBody& MotionStateManager::checked_locked(BodyHandle body) const {
    if (!is_published_locked(body)) {
        throw Error("motion state: " + to_string(body) + " is not a live body of this space (stale or foreign handle)");
    }
    return (*m_front)[body.index];
}

bool MotionStateManager::is_published_locked(BodyHandle body) const noexcept {
    return body.generation != 0 && body.index < m_front->size() && (*m_front)[body.index].generation == body.generation;
}

MotionState MotionStateManager::read_locked(BodyHandle body) const { return blend(checked_locked(body), m_alpha); }

MotionState MotionStateManager::read(BodyHandle body) const {
    std::scoped_lock guard(m_lock);
    return read_locked(body);
}

std::size_t MotionStateManager::get_motion_states(std::vector<BodyHandle>& handles,
                                                  std::vector<MotionState>& states) const {
    std::scoped_lock guard(m_lock);
    const std::vector<PublishedBody>& front = *m_front;
    std::size_t count = 0;
    for (const PublishedBody& b : front) count += b.generation != 0;
    handles.resize(count);
    states.resize(count);
    std::size_t k = 0;
    for (std::uint32_t i = 0; i < front.size(); ++i) {
        if (front[i].generation == 0) continue;
        handles[k] = BodyHandle{i, front[i].generation};
        states[k] = blend(front[i], m_alpha);
        ++k;
    }
    return count;
}

void MotionStateManager::get_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const {
    if (out.size() < bodies.size()) throw Error("get_motion_states: output span is shorter than the handle list");
    std::scoped_lock guard(m_lock);
    for (BodyHandle b : bodies) checked_locked(b);
    for (std::size_t i = 0; i < bodies.size(); ++i) out[i] = blend((*m_front)[bodies[i].index], m_alpha);
}

void MotionStateManager::get_raw_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const {
    if (out.size() < bodies.size()) throw Error("get_raw_motion_states: output span is shorter than the handle list");
    std::scoped_lock guard(m_lock);
    for (BodyHandle b : bodies) checked_locked(b);
    for (std::size_t i = 0; i < bodies.size(); ++i) out[i] = (*m_front)[bodies[i].index].current;
}

std::uint64_t MotionStateManager::published_steps() const {
    std::scoped_lock guard(m_lock);
    return m_steps;
}

double MotionStateManager::alpha() const {
    std::scoped_lock guard(m_lock);
    return m_alpha;
}

double MotionStateManager::flip(double alpha, std::uint64_t steps) {
    std::scoped_lock guard(m_lock);
    const std::int64_t acquired = now_nanoseconds();
    std::swap(m_front, m_back);
    m_alpha = alpha;
    m_steps = steps;
    return static_cast<double>(now_nanoseconds() - acquired) * 1e-9;  // hold time, not wait time
}

}  // namespace spindle
