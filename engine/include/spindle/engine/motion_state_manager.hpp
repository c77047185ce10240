// MotionStateManager: the published (read) side of the space's double buffer. The
// game thread copies consistent motion states out of it, under the same lock that
// FlipReadBuffers takes to swap the buffers, so it never sees half of one step and
// half of the next (the seed, section 2.A).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include <spindle/engine/body.hpp>

namespace spindle {

class QueryScene;  // engine/src/query/query_scene.hpp: what scene queries read

// Where a blended read takes the weight of the newest step from.
enum class BlendClock : std::uint8_t {
    // The seed's: the time the last update banked (its accumulator over the step), the
    // same for every read until the next flip. Between flips the reads stand still.
    Update,
    // The banked time grown by the reader's clock since the update measured it, capped
    // at the newest step: motion moves on between flips at the real rate, one step
    // behind. Only updates that follow the real clock say when they measured it (an
    // AsyncRunner's); for others this is Update.
    Read,
};

// What the published step is: enough to say which instant a read shows.
struct PublishedTime {
    std::uint64_t steps = 0;                // steps taken when it was published
    double banked_alpha = 1;                // the newest step's weight under BlendClock::Update (1: no blending)
    std::int64_t clock_ns = 0;              // now_nanoseconds() when the update measured the banked time; 0: unknown
    double step_seconds = 0;                // the fixed step
    double clock_rate = 1;                  // simulated seconds per real second (AsyncRunner::set_time_scale)
    BlendClock reads = BlendClock::Update;  // the clock of reads that do not name one
};

// The step before the newest, for blending a body that interpolates.
struct PublishedHistory {
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();
    Vec3 center_of_mass = Vec3::Zero();
};

// One published step, by body slot, as arrays: what every read copies (generation,
// newest state) apart from what only blended reads need, so copying bodies that do not
// interpolate streams like a memcpy of their states. The step before is kept only for
// bodies that can move (a static body never blends), by their history entry.
struct PublishedBuffer {
    std::vector<std::uint32_t> generation;  // 0: no body in this slot
    std::vector<MotionState> current;
    std::vector<std::uint8_t> interpolate;     // allow_interpolation and internal time stepping
    std::vector<std::uint32_t> history_place;  // where interpolate is set: the slot's entry in previous
    std::vector<std::uint64_t> user_data;      // BodyDesc::user_data, as last set (Space::set_user_data)
    std::vector<PublishedHistory> previous;    // by history entry, not by slot

    std::size_t size() const noexcept { return generation.size(); }
    // Room for `slots` slots and `histories` history entries.
    void resize(std::size_t slots, std::size_t histories) {
        generation.resize(slots);
        current.resize(slots);
        interpolate.resize(slots);
        history_place.resize(slots);
        user_data.resize(slots);
        if (previous.size() < histories) previous.resize(histories);
    }
    void reserve(std::size_t slots) {
        generation.reserve(slots);
        current.reserve(slots);
        interpolate.reserve(slots);
        history_place.reserve(slots);
        user_data.reserve(slots);
    }
    // Slot i's step before the newest; the slot must interpolate.
    const PublishedHistory& previous_of(std::uint32_t i) const { return previous[history_place[i]]; }
};

// The motion-state lock: a mutex that knows which thread holds it, so that a thread
// taking it a second time gets a spindle::Error instead of waiting for itself forever.
// Use it as any mutex (std::scoped_lock, std::unique_lock<MotionStateLock>).
class MotionStateLock {
public:
    // Any thread. Waits for the holder (a game thread's read, or the physics thread's
    // flip). Throws spindle::Error if this thread holds it already.
    void lock();
    // As lock(), without waiting: false if another thread holds it.
    bool try_lock();
    // The holder only.
    void unlock() noexcept;
    // Whether the calling thread holds it; exact for the calling thread, lock-free.
    bool held_by_this_thread() const noexcept;
    // now_nanoseconds() when the holder took it: the clock of every read made under one
    // hold (BlendClock::Read), so they all show the same instant. The holder only.
    std::int64_t taken_at_ns() const noexcept { return m_taken_ns; }

    // Holds the lock for a scope, or nothing if this thread holds it already (then the
    // published step cannot change under the caller either way).
    class Hold {
    public:
        explicit Hold(MotionStateLock& lock) : m_lock(lock), m_took(!lock.held_by_this_thread()) {
            if (m_took) m_lock.lock();
        }
        ~Hold() {
            if (m_took) m_lock.unlock();
        }
        Hold(const Hold&) = delete;
        Hold& operator=(const Hold&) = delete;

    private:
        MotionStateLock& m_lock;
        bool m_took;
    };

private:
    std::mutex m_mutex;
    std::atomic<std::thread::id> m_owner{};  // written only by the holder, under m_mutex
    std::int64_t m_taken_ns = 0;             // the same
};

class MotionStateManager {
public:
    MotionStateManager() = default;
    ~MotionStateManager();
    MotionStateManager(const MotionStateManager&) = delete;
    MotionStateManager& operator=(const MotionStateManager&) = delete;

    // The lock FlipReadBuffers takes: hold it to make several reads of one published
    // step. Who may call: any thread; hold it briefly, it delays the physics thread's flip.
    // While a thread holds it:
    //  - that thread's reads of this manager and the space's buffered reads (position(),
    //    motion_state(), get_all_motion_states(), ...) read the held step without locking
    //    again, as the *_locked reads do; other threads' reads wait for it;
    //  - buffered writes (set_position(), apply_impulse(), wake(), ...) from any thread
    //    do not take it (their stale-handle check is lock-free);
    //  - taking it again on the same thread throws spindle::Error;
    //  - on the same thread, Space::update()/flush() and AsyncRunner::stop() throw
    //    spindle::Error (each would wait for a flip that waits for this lock); create_body
    //    and destroy_body publish under the held lock.
    // Deadlock: waiting while holding it for anything that waits for a flip (another
    // thread's update, an AsyncRunner's loop, a posted function's future); destroying a
    // running AsyncRunner while holding it (the destructor cannot throw: it aborts with a
    // message).
    MotionStateLock& lock() const noexcept { return m_lock; }

    // Every live body, in handle order: handles and interpolated states, into the
    // caller's vectors (resized; no allocation once they are large enough). Returns the count.
    std::size_t get_all_motion_states(std::vector<BodyHandle>& handles, std::vector<MotionState>& states) const;
    // The listed bodies into out[0..bodies.size()). A stale handle throws spindle::Error
    // naming it, before anything is written.
    void get_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const;
    // The same with the blend's clock chosen for this read (the others use the one the
    // updates ask for: PublishedTime::reads, AsyncRunnerOptions::blend_clock).
    void get_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out, BlendClock clock) const;
    // As above, the newest step without interpolation.
    void get_raw_motion_states(std::span<const BodyHandle> bodies, std::span<MotionState> out) const;

    // One body (interpolated where allowed); throws for a stale handle. Takes the lock
    // unless this thread holds it.
    MotionState read(BodyHandle body) const;
    // The same, for a caller that already holds lock().
    MotionState read_locked(BodyHandle body) const;
    bool is_published_locked(BodyHandle body) const noexcept;
    // The generation published for a slot (0: none), for a caller that holds lock().
    std::uint32_t published_generation_locked(std::uint32_t slot) const noexcept {
        return slot < m_front->size() ? m_front->generation[slot] : 0;
    }
    // The same without the lock: any thread, lock-free (buffered writes check handles
    // with it, so a thread holding lock() can still write). Equal to the locked value:
    // a slot's generation changes only when a body is created or destroyed, and both
    // publish it to both buffers at once (publish_now), so a flip never changes it.
    std::uint32_t published_generation(std::uint32_t slot) const noexcept { return m_generations.load(slot); }
    // A slot's motion type, and whether its shape can only belong to a static body, as of
    // the last creation or ApplyWrites that changed them: any thread, lock-free, for the
    // checks of writes that depend on them (Space::move_kinematic, set_shape, set_motion_type).
    MotionType published_motion_type(std::uint32_t slot) const noexcept {
        return static_cast<MotionType>(m_kinds.load(slot) & 0xffu);
    }
    bool published_static_only_shape(std::uint32_t slot) const noexcept { return (m_kinds.load(slot) >> 8) != 0; }

    // A body's user data (BodyDesc::user_data, Space::set_user_data) as published; throws
    // for a stale handle. Takes the lock unless this thread holds it.
    std::uint64_t read_user_data(BodyHandle body) const;

    // Steps published so far and the weight of the newest step in blended reads now.
    std::uint64_t published_steps() const;
    std::uint64_t published_steps_locked() const noexcept { return m_time.steps; }
    double alpha() const;
    // The weight a blended read by the lock's holder gives the newest step.
    double alpha_locked() const noexcept { return alpha_locked(m_time.reads); }
    double alpha_locked(BlendClock clock) const noexcept;
    PublishedTime published_time() const;
    // Heap bytes the two published buffers hold, at capacity (the engine's memory report).
    // The update thread: it alone changes them.
    std::size_t buffer_bytes() const noexcept;

private:
    // The physics side (the update thread): only the buffering stages reach it, through
    // MotionStatePublisher (engine/src/stages/buffering.cpp); a game never does.
    friend class MotionStatePublisher;
    friend class QueryLease;  // takes the published query scene under the lock
    // The buffer being filled for the next flip; never read by other threads.
    PublishedBuffer& back() noexcept { return *m_back; }
    int back_index() const noexcept { return m_back == &m_buffers[0] ? 0 : 1; }  // which buffer back() is
    // Both buffers, for a caller that holds lock() (publishing a created body at once).
    PublishedBuffer& buffer_locked(int k) noexcept { return m_buffers[k]; }
    // Swaps back and front under the lock and publishes the query scene that goes with
    // the new front (read under the lock: a first query that holds the lock may build it
    // while the flip waits); returns seconds the lock was held.
    double flip(const PublishedTime& time, const std::shared_ptr<QueryScene>& queries);
    // Takes lock() for the physics side (the thread that may change the space), saying so
    // while it waits: a thread holding the lock then knows the physics side touches
    // nothing until it lets go (publisher_waiting()).
    void lock_for_publishing();
    // Whether the physics side waits for lock(); exact for a caller holding it.
    bool publisher_waiting() const noexcept { return m_publisher_waiting.load(std::memory_order_acquire); }
    // Replaces the published query scene, for a caller that holds lock().
    void set_query_scene_locked(std::shared_ptr<const QueryScene> queries) noexcept {
        m_query_scene = std::move(queries);
    }

    // Records a slot's published generation; the physics side, under lock().
    void set_published_generation(std::uint32_t slot, std::uint32_t generation) {
        m_generations.store(slot, generation);
    }
    void set_published_kind(std::uint32_t slot, MotionType type, bool static_only_shape) {
        m_kinds.store(slot, static_cast<std::uint32_t>(type) | (static_only_shape ? 0x100u : 0u));
    }

    // Slot i of the front buffer as reads return it: blended by `alpha` where it interpolates.
    MotionState blend_locked(std::uint32_t i, double alpha) const;
    void check_locked(BodyHandle body) const;

    // Per slot, an atomic copy of the published generation. Readers take no lock, so
    // storage never moves: chunks of doubling size, allocated by the one writer and
    // never freed before the manager.
    class SlotGenerations {
    public:
        ~SlotGenerations();
        std::uint32_t load(std::uint32_t slot) const noexcept;
        void store(std::uint32_t slot, std::uint32_t generation);  // one writer at a time

    private:
        static constexpr std::uint32_t kFirstChunk = 1024;
        static constexpr int kChunks = 23;  // enough for every 32-bit slot index
        static int chunk_of(std::uint32_t slot, std::uint32_t& offset) noexcept;
        std::atomic<std::atomic<std::uint32_t>*> m_chunks[kChunks] = {};
    };

    mutable MotionStateLock m_lock;
    SlotGenerations m_generations;
    SlotGenerations m_kinds;  // the same storage for motion type | static-only shape << 8
    PublishedBuffer m_buffers[2];
    PublishedBuffer* m_front = &m_buffers[0];
    PublishedBuffer* m_back = &m_buffers[1];
    PublishedTime m_time;
    std::shared_ptr<const QueryScene> m_query_scene;  // null until the space's first query
    std::atomic<bool> m_publisher_waiting{false};     // set before lock_for_publishing() blocks, cleared under the lock
};

}  // namespace spindle
