// WriteBuffer: sharded pending writes, drained in sequence order.
#include "api/write_buffer.hpp"

#include <algorithm>

namespace spindle {
namespace {

unsigned shard_of_this_thread(unsigned shards) {
    static std::atomic<unsigned> next{0};
    thread_local const unsigned shard = next.fetch_add(1, std::memory_order_relaxed);
    return shard % shards;
}

}  // namespace

void WriteBuffer::push(BufferedWrite write) {
    Shard& shard = m_shards[shard_of_this_thread(kShards)];
    std::scoped_lock guard(shard.lock);
    // Taking the number under the shard lock keeps each shard sorted by sequence.
    write.sequence = m_sequence.value.fetch_add(1, std::memory_order_relaxed);
    shard.writes.push_back(write);
}

void WriteBuffer::drain(std::vector<BufferedWrite>& out) {
    out.clear();
    for (Shard& shard : m_shards) {
        {
            std::scoped_lock guard(shard.lock);
            std::swap(shard.writes, m_spare);  // m_spare is empty: the shard keeps a buffer
        }
        out.insert(out.end(), m_spare.begin(), m_spare.end());
        m_spare.clear();
    }
    std::sort(out.begin(), out.end(),
              [](const BufferedWrite& a, const BufferedWrite& b) { return a.sequence < b.sequence; });
}

std::uint64_t WriteBuffer::pending_hint() const noexcept { return m_sequence.value.load(std::memory_order_relaxed); }

}  // namespace spindle
