// SingleThreadedJobSystem: chunks in order on the caller.
#include <spindle/scheduler/single_threaded.hpp>

namespace spindle {

void SingleThreadedJobSystem::parallel_for(const char*, std::uint32_t begin, std::uint32_t end,
                                           std::uint32_t grain, RangeFn fn) {
    if (grain == 0) grain = 1;
    for (std::uint32_t lo = begin; lo < end;) {
        const std::uint32_t hi = end - lo > grain ? lo + grain : end;  // no overflow near UINT32_MAX
        fn(lo, hi, 0);
        lo = hi;
    }
}

}  // namespace spindle
