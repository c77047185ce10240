// MotionStateManager: the published (read) side of the space's double buffer. The
// game thread copies consistent motion states out of it, under the same lock that
// FlipReadBuffers takes to swap the buffers, so it never sees half of one step and
// half of the next (the seed, section 2.A).
#pragma once

#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

#include <spindle/engine/body.hpp>

namespace spindle {

// One body as published at a flip: the newest step, and the one before for blending.
struct PublishedBody {
    std::uint32_t generation = 0;  // 0: no body in this slot
    bool interpolate = false;      // allow_interpolation and internal time stepping
    MotionState current;
    Vec3 previous_position = Vec3::Zero();
    Quat previous_orientation = Quat::Identity();
    Vec3 previous_center_of_mass = Vec3::Zero();
};

class MotionStateManager {
public:
    // The lock FlipReadBuffers takes. Hold it to make several reads of one published
    // step (then use the *_locked reads). Any thread may take it; hold it briefly, it
    // delays the physics thread's flip. Deadlock: calling update() or any non-locked
    // read of this manager while holding it.
    std::mutex& lock() const noexcept { return m_lock; }

    // Every live body, in handle order: handles and interpolated states, into the
    // caller's vectors (resized; no allocation once they are large enough). Returns the count.
    std::size_t get_motion_states(std::vector<BodyHandle>& handles, std::vector<MotionState>& states) const;
    // The listed bodies into out[0..bodies.size()). A stale handle throws spindle::Error
    // naming it, before anything is written.
    void get_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const;
    // As above, the newest step without interpolation.
    void get_raw_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const;

    // One body (interpolated where allowed); throws for a stale handle. Takes the lock.
    MotionState read(BodyHandle body) const;
    // The same, for a caller that already holds lock().
    MotionState read_locked(BodyHandle body) const;
    bool is_published_locked(BodyHandle body) const noexcept;
    // The generation published for a slot (0: none), for a caller that holds lock().
    std::uint32_t published_generation_locked(std::uint32_t slot) const noexcept {
        return slot < m_front->size() ? (*m_front)[slot].generation : 0;
    }

    // Steps published so far and the weight of the newest step in blended reads.
    std::uint64_t published_steps() const;
    std::uint64_t published_steps_locked() const noexcept { return m_steps; }
    double alpha() const;

private:
    // The physics side (the update thread): only the buffering stages reach it, through
    // MotionStatePublisher (engine/src/stages/buffering.cpp); a game never does.
    friend class MotionStatePublisher;
    // The buffer being filled for the next flip; never read by other threads.
    std::vector<PublishedBody>& back() noexcept { return *m_back; }
    int back_index() const noexcept { return m_back == &m_buffers[0] ? 0 : 1; }  // which buffer back() is
    // Both buffers, for a caller that holds lock() (publishing a created body at once).
    std::vector<PublishedBody>& buffer_locked(int k) noexcept { return m_buffers[k]; }
    // Swaps back and front under the lock; returns seconds the lock was held.
    double flip(double alpha, std::uint64_t steps);

    static MotionState blend(const PublishedBody& body, double alpha);
    const PublishedBody& checked_locked(BodyHandle body) const;

    mutable std::mutex m_lock;
    std::vector<PublishedBody> m_buffers[2];
    std::vector<PublishedBody>* m_front = &m_buffers[0];
    std::vector<PublishedBody>* m_back = &m_buffers[1];
    double m_alpha = 1;
    std::uint64_t m_steps = 0;
};

}  // namespace spindle
