// MotionStateManager: locked copies out of the published buffer, the flip, the lock
// that knows its holder, and the lock-free copy of each slot's published generation.
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>

#include <bit>

namespace spindle {

// ---- the lock ----

// Only the holder stores its id, and it clears it before unlocking, so a thread reads
// its own id exactly while it holds the lock (relaxed is enough for that question).
bool MotionStateLock::held_by_this_thread() const noexcept {
    return m_owner.load(std::memory_order_relaxed) == std::this_thread::get_id();
}

void MotionStateLock::lock() {
    if (held_by_this_thread()) {
        throw Error("motion-state lock: this thread holds it already (taking it again would wait forever)");
    }
    m_mutex.lock();
    m_owner.store(std::this_thread::get_id(), std::memory_order_relaxed);
}

bool MotionStateLock::try_lock() {
    if (held_by_this_thread()) throw Error("motion-state lock: this thread holds it already");
    if (!m_mutex.try_lock()) return false;
    m_owner.store(std::this_thread::get_id(), std::memory_order_relaxed);
    return true;
}

void MotionStateLock::unlock() noexcept {
    m_owner.store(std::thread::id{}, std::memory_order_relaxed);
    m_mutex.unlock();
}

// ---- published generations ----

MotionStateManager::~MotionStateManager() = default;

MotionStateManager::SlotGenerations::~SlotGenerations() {
    for (auto& chunk : m_chunks) delete[] chunk.load(std::memory_order_relaxed);
}

// Chunk c holds kFirstChunk << c slots, starting at kFirstChunk * (2^c - 1).
int MotionStateManager::SlotGenerations::chunk_of(std::uint32_t slot, std::uint32_t& offset) noexcept {
    const std::uint32_t q = slot / kFirstChunk + 1;
    const int c = std::bit_width(q) - 1;
    offset = slot - kFirstChunk * ((std::uint32_t{1} << c) - 1);
    return c;
}

std::uint32_t MotionStateManager::SlotGenerations::load(std::uint32_t slot) const noexcept {
    std::uint32_t offset = 0;
    const std::atomic<std::uint32_t>* chunk = m_chunks[chunk_of(slot, offset)].load(std::memory_order_acquire);
    return chunk ? chunk[offset].load(std::memory_order_acquire) : 0;
}

void MotionStateManager::SlotGenerations::store(std::uint32_t slot, std::uint32_t generation) {
    std::uint32_t offset = 0;
    const int c = chunk_of(slot, offset);
    std::atomic<std::uint32_t>* chunk = m_chunks[c].load(std::memory_order_relaxed);
    if (!chunk) {
        chunk = new std::atomic<std::uint32_t>[std::size_t{kFirstChunk} << c]();
        m_chunks[c].store(chunk, std::memory_order_release);
    }
    chunk[offset].store(generation, std::memory_order_release);
}

// ---- reads and the flip ----

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
    const MotionStateLock::Hold guard(m_lock);
    return read_locked(body);
}

std::uint64_t MotionStateManager::read_user_data(BodyHandle body) const {
    const MotionStateLock::Hold guard(m_lock);
    return checked_locked(body).user_data;
}

std::size_t MotionStateManager::get_all_motion_states(std::vector<BodyHandle>& handles,
                                                      std::vector<MotionState>& states) const {
    const MotionStateLock::Hold guard(m_lock);
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
    const MotionStateLock::Hold guard(m_lock);
    for (BodyHandle b : bodies) checked_locked(b);
    for (std::size_t i = 0; i < bodies.size(); ++i) out[i] = blend((*m_front)[bodies[i].index], m_alpha);
}

void MotionStateManager::get_raw_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const {
    if (out.size() < bodies.size()) throw Error("get_raw_motion_states: output span is shorter than the handle list");
    const MotionStateLock::Hold guard(m_lock);
    for (BodyHandle b : bodies) checked_locked(b);
    for (std::size_t i = 0; i < bodies.size(); ++i) out[i] = (*m_front)[bodies[i].index].current;
}

std::uint64_t MotionStateManager::published_steps() const {
    const MotionStateLock::Hold guard(m_lock);
    return m_steps;
}

double MotionStateManager::alpha() const {
    const MotionStateLock::Hold guard(m_lock);
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
