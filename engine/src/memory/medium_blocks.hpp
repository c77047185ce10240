// Blocks of a few pages up to half a huge page (HugePageAllocator's middle sizes: a 10k-body
// scene's pair lists, keys, push velocities, manifold lists), several to a huge page. A
// first step makes a dozen such arrays; as ordinary blocks each page's first write cost a
// fault of its own on virtual machines, even mapped at once (huge_page_vector.hpp), and on
// whole huge pages of their own a 100 KB array would round up to 2 MB. Here huge pages
// (chunks) are shared by blocks of whole 64 KB units, up to 1 MB, and a freed block
// serves the next that fits, so an array that moves as it grows takes memory already
// written. Process-wide, under a lock: such blocks come and go a few times a step.
#pragma once

#include <array>
#include <cstddef>

namespace spindle {

// The smallest and one past the largest block size served: smaller blocks stay ordinary
// heap blocks (mostly from memory the heap holds mapped already), larger ones are whole
// huge pages of their own.
inline constexpr std::size_t kMediumBlockMinBytes = std::size_t{64} << 10;
inline constexpr std::size_t kMediumBlockEndBytes = std::size_t{1} << 20;

// Empty chunks kept for the next blocks beyond those in use: a scene whose contacts come
// and go moves its arrays between sizes, and a kept chunk is memory already written.
inline constexpr std::size_t kKeptEmptyMediumChunks = 2;

// The room a block of `bytes` takes in a chunk: its whole units of kMediumBlockMinBytes.
// Not its power-of-two size: the pyramid's nine blocks held 1.63 MB in 2 MB of powers of
// two, and shared two chunks (docs/benchmarks.md, issue 19).
constexpr std::size_t medium_block_bytes(std::size_t bytes) {
    return (bytes + kMediumBlockMinBytes - 1) / kMediumBlockMinBytes * kMediumBlockMinBytes;
}

// A block of at least `bytes` (kMediumBlockMinBytes <= bytes < kMediumBlockEndBytes),
// aligned to a unit, its pages mapped. Throws std::bad_alloc when the system
// has no memory for a new chunk.
void* allocate_medium_block(std::size_t bytes);

// Gives back a block from allocate_medium_block(bytes), the same `bytes`.
void free_medium_block(void* p, std::size_t bytes) noexcept;

// The block sizes served: k + 1 units for k below this.
inline constexpr int kMediumBlockSizes = static_cast<int>(kMediumBlockEndBytes / kMediumBlockMinBytes);

// Chunks the pool holds (in use or kept empty for the next blocks), how many of them are
// empty, and the blocks in use of each size (blocks[k]: k + 1 units, medium_block_size_index):
// for tests and the memory report.
struct MediumBlockCounts {
    std::size_t chunks = 0;
    std::size_t empty_chunks = 0;
    std::array<std::size_t, kMediumBlockSizes> blocks{};
};
MediumBlockCounts medium_block_counts();

// The index in MediumBlockCounts::blocks of a block of `bytes`.
constexpr std::size_t medium_block_size_index(std::size_t bytes) {
    return medium_block_bytes(bytes) / kMediumBlockMinBytes - 1;
}

}  // namespace spindle
