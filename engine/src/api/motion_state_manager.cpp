// MotionStateManager: locked copies out of the published buffer, the flip, the lock
// that knows its holder, and the lock-free copy of each slot's published generation.
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>

#include "query/slerp_series.hpp"

#include <algorithm>
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
    m_taken_ns = now_nanoseconds();
}

bool MotionStateLock::try_lock() {
    if (held_by_this_thread()) throw Error("motion-state lock: this thread holds it already");
    if (!m_mutex.try_lock()) return false;
    m_owner.store(std::this_thread::get_id(), std::memory_order_relaxed);
    m_taken_ns = now_nanoseconds();
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

double MotionStateManager::alpha_locked(BlendClock clock) const noexcept {
    const PublishedTime& t = m_time;
    if (clock == BlendClock::Update || t.clock_ns == 0 || t.banked_alpha >= 1) return t.banked_alpha;
    const double grown = static_cast<double>(m_lock.taken_at_ns() - t.clock_ns) * 1e-9 * t.clock_rate / t.step_seconds;
    return std::clamp(t.banked_alpha + grown, t.banked_alpha, 1.0);
}

namespace {

// Slot i of a published buffer as reads return it: blended by the series' fraction where
// it interpolates (the caller leaves out alpha = 1, where every slot reads as its newest state).
MotionState blended(const PublishedBuffer& front, std::uint32_t i, const SlerpSeries& blend) {
    if (!front.interpolate[i]) return front.current[i];
    const PublishedHistory& before = front.previous_of(i);
    MotionState s = front.current[i];
    const Real t = blend.t();
    s.position = before.position + (s.position - before.position) * t;
    s.center_of_mass = before.center_of_mass + (s.center_of_mass - before.center_of_mass) * t;
    s.orientation = blend(before.orientation, s.orientation);
    return s;
}

}  // namespace

MotionState MotionStateManager::blend_locked(std::uint32_t i, double alpha) const {
    if (alpha >= 1) return m_front->current[i];
    return blended(*m_front, i, SlerpSeries(alpha));
}

void MotionStateManager::check_locked(BodyHandle body) const {
    if (!is_published_locked(body)) {
        throw Error("motion state: " + to_string(body) + " is not a live body of this space (stale or foreign handle)");
    }
}

bool MotionStateManager::is_published_locked(BodyHandle body) const noexcept {
    return body.generation != 0 && body.index < m_front->size() && m_front->generation[body.index] == body.generation;
}

MotionState MotionStateManager::read_locked(BodyHandle body) const {
    check_locked(body);
    return blend_locked(body.index, alpha_locked());
}

MotionState MotionStateManager::read(BodyHandle body) const {
    const MotionStateLock::Hold guard(m_lock);
    return read_locked(body);
}

std::uint64_t MotionStateManager::read_user_data(BodyHandle body) const {
    const MotionStateLock::Hold guard(m_lock);
    check_locked(body);
    return m_front->user_data[body.index];
}

std::size_t MotionStateManager::buffer_bytes() const noexcept {
    const auto held = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
    std::size_t bytes = 0;
    for (const PublishedBuffer& p : m_buffers) {
        bytes += held(p.generation) + held(p.current) + held(p.interpolate) + held(p.history_place) +
                 held(p.user_data) + held(p.previous);
    }
    return bytes;
}

// Runs of live slots that need no blending (all of them at alpha 1, else those that do
// not interpolate) are copied as runs, which streams like a memcpy (all slots as one
// run when none is empty); the others are blended one by one.
std::size_t MotionStateManager::get_all_motion_states(std::vector<BodyHandle>& handles,
                                                      std::vector<MotionState>& states) const {
    const MotionStateLock::Hold guard(m_lock);
    const PublishedBuffer& front = *m_front;
    const auto slots = static_cast<std::uint32_t>(front.size());
    std::size_t count = 0, interpolating = 0;
    for (std::uint32_t i = 0; i < slots; ++i) {
        const bool live = front.generation[i] != 0;
        count += live;
        interpolating += live & (front.interpolate[i] != 0);
    }
    handles.resize(count);
    states.resize(count);
    const double alpha = alpha_locked();
    const bool blending = alpha < 1 && interpolating > 0;
    if (!blending && count == slots) {  // no holes, nothing to blend: one copy
        for (std::uint32_t i = 0; i < slots; ++i) handles[i] = BodyHandle{i, front.generation[i]};
        std::copy(front.current.begin(), front.current.end(), states.begin());
        return count;
    }
    auto copied = [&](std::uint32_t i) { return front.generation[i] != 0 && !(blending && front.interpolate[i]); };
    const SlerpSeries blend(blending ? alpha : 0.0);
    std::size_t k = 0;
    for (std::uint32_t i = 0; i < slots;) {
        if (front.generation[i] == 0) {
            ++i;
        } else if (!copied(i)) {
            handles[k] = BodyHandle{i, front.generation[i]};
            states[k++] = blended(front, i++, blend);
        } else {
            std::uint32_t end = i;
            while (end < slots && copied(end)) {
                handles[k + (end - i)] = BodyHandle{end, front.generation[end]};
                ++end;
            }
            std::copy(front.current.begin() + i, front.current.begin() + end,
                      states.begin() + static_cast<std::ptrdiff_t>(k));
            k += end - i;
            i = end;
        }
    }
    return count;
}

// The clock of reads that name none is part of the published time a flip writes: read
// under the lock (the overload's hold below takes nothing more).
void MotionStateManager::get_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const {
    const MotionStateLock::Hold guard(m_lock);
    get_motion_states(bodies, out, m_time.reads);
}

void MotionStateManager::get_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out,
                                           BlendClock clock) const {
    if (out.size() < bodies.size()) throw Error("get_motion_states: output span is shorter than the handle list");
    const MotionStateLock::Hold guard(m_lock);
    for (BodyHandle b : bodies) check_locked(b);
    const double alpha = alpha_locked(clock);
    if (alpha >= 1) {
        for (std::size_t i = 0; i < bodies.size(); ++i) out[i] = m_front->current[bodies[i].index];
        return;
    }
    const SlerpSeries blend(alpha);
    for (std::size_t i = 0; i < bodies.size(); ++i) out[i] = blended(*m_front, bodies[i].index, blend);
}

void MotionStateManager::get_raw_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const {
    if (out.size() < bodies.size()) throw Error("get_raw_motion_states: output span is shorter than the handle list");
    const MotionStateLock::Hold guard(m_lock);
    for (BodyHandle b : bodies) check_locked(b);
    for (std::size_t i = 0; i < bodies.size(); ++i) out[i] = m_front->current[bodies[i].index];
}

std::uint64_t MotionStateManager::published_steps() const {
    const MotionStateLock::Hold guard(m_lock);
    return m_time.steps;
}

double MotionStateManager::alpha() const {
    const MotionStateLock::Hold guard(m_lock);
    return alpha_locked();
}

PublishedTime MotionStateManager::published_time() const {
    const MotionStateLock::Hold guard(m_lock);
    return m_time;
}

// The flag is cleared under the lock, so a holder that reads it set knows the physics
// side is between setting it and taking the lock: it writes nothing there.
void MotionStateManager::lock_for_publishing() {
    m_publisher_waiting.store(true, std::memory_order_release);
    try {
        m_lock.lock();
    } catch (...) {
        m_publisher_waiting.store(false, std::memory_order_relaxed);  // this thread held it: nobody waited
        throw;
    }
    m_publisher_waiting.store(false, std::memory_order_relaxed);
}

double MotionStateManager::flip(const PublishedTime& time, const std::shared_ptr<QueryScene>& queries) {
    lock_for_publishing();
    const std::unique_lock guard(m_lock, std::adopt_lock);
    const std::int64_t acquired = m_lock.taken_at_ns();
    std::swap(m_front, m_back);
    m_time = time;
    m_query_scene = queries;
    return static_cast<double>(now_nanoseconds() - acquired) * 1e-9;  // hold time, not wait time
}

}  // namespace spindle
