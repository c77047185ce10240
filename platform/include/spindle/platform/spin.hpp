// Spin/yield/pause helpers and cache-line padding for hot atomics, in one place.
#pragma once

#include <cstddef>
#include <thread>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace spindle {

inline constexpr std::size_t cache_line_size = 64;

// One pause instruction: tells the core we are spinning (saves power, frees the
// sibling hyper-thread).
inline void cpu_pause() noexcept {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#elif defined(__aarch64__)
    asm volatile("yield");
#else
    std::this_thread::yield();
#endif
}

// Exponential back-off for short spins: pause 1, 2, 4 ... up to 64 times, then yield.
class Backoff {
public:
    void spin() noexcept {
        if (m_count <= 64) {
            for (unsigned i = 0; i < m_count; ++i) cpu_pause();
            m_count *= 2;
        } else {
            std::this_thread::yield();
        }
    }
    bool saturated() const noexcept { return m_count > 64; }
    void reset() noexcept { m_count = 1; }

private:
    unsigned m_count = 1;
};

// A value alone on its cache line(s), so two hot atomics never false-share.
template <typename T>
struct alignas(cache_line_size) CacheLinePadded {
    T value{};
};

}  // namespace spindle
