// The write side of buffering: writes from any number of threads accumulate here
// until ApplyWrites. Sharded by thread so that writers rarely contend; a global
// sequence number orders writes across shards so the last write to a property wins.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/platform/spin.hpp>

namespace spindle {

enum class WriteKind : std::uint8_t {
    Position,
    Orientation,
    LinearVelocity,
    AngularVelocity,
    MotionState,  // all of it
    Force,        // additive from here on
    Torque,
    Impulse,
    AngularImpulse,
    Wake,
};

struct BufferedWrite {
    std::uint64_t sequence = 0;
    BodyHandle body;
    WriteKind kind = WriteKind::Wake;
    Vec3 vector = Vec3::Zero();        // position, velocity, force, impulse
    Quat rotation = Quat::Identity();  // orientation
    MotionState state;                 // motion state
};

class WriteBuffer {
public:
    // Any thread. Never blocks on the physics thread for long: a shard lock is held
    // for one push_back.
    void push(BufferedWrite write);
    // The update thread: every pending write, in the order they were made. `out` is
    // reused between updates (no allocation in steady state).
    void drain(std::vector<BufferedWrite>& out);
    std::uint64_t pending_hint() const noexcept;

private:
    static constexpr unsigned kShards = 16;
    struct alignas(cache_line_size) Shard {
        std::mutex lock;
        std::vector<BufferedWrite> writes;
    };
    Shard m_shards[kShards];
    CacheLinePadded<std::atomic<std::uint64_t>> m_sequence;
    std::vector<BufferedWrite> m_spare;
};

}  // namespace spindle
