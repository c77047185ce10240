// Live heap bytes of everything allocated through operator new (the engine's containers),
// counted by the replaced global operators in heap_counter.cpp.
#pragma once

#include <cstdint>

namespace spindle::bench {

// Bytes currently allocated through operator new, as malloc_usable_size reports them
// (what the allocator really handed out, rounding included). Any thread.
std::int64_t live_heap_bytes() noexcept;

}  // namespace spindle::bench
