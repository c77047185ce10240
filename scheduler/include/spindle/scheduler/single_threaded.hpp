// SingleThreadedJobSystem: every job runs on the calling thread, chunks in order.
// Used for workers = 1 and by tests that need a fixed order.
#pragma once

#include <spindle/scheduler/job_system.hpp>

namespace spindle {

class SingleThreadedJobSystem final : public JobSystem {
public:
    unsigned worker_count() const noexcept override { return 1; }
    void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                      RangeFn fn) override;
    void trace_begin(const char*) noexcept override {}
    void trace_end() noexcept override {}
};

}  // namespace spindle
