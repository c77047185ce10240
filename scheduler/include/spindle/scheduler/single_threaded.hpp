// SingleThreadedJobSystem: every job runs on the calling thread, chunks in order.
// Used for workers = 1 and by tests that need a fixed order.
#pragma once

#include <spindle/scheduler/job_system.hpp>

#include <type_traits>

namespace spindle {

class SingleThreadedJobSystem final : public JobSystem {
public:
    unsigned worker_count() const noexcept override { return 1; }
    void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                      RangeFn fn) override;
    // Each phase in one block, in order.
    void run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) override;
    // Nodes in index order among those ready (a deterministic topological order).
    void run_graph(StageGraph& graph) override;
    // Runs fn at once; an exception is kept for wait(), as the threaded system does.
    template <typename F>
    void submit(JobGroup& group, const char*, F&& fn) {
        try {
            if constexpr (std::is_invocable_v<F&, unsigned>) {
                fn(0u);
            } else {
                fn();
            }
        } catch (...) {
            keep_error(group, std::current_exception());
        }
    }
    void wait(JobGroup& group);
    void trace_begin(const char*) noexcept override {}
    void trace_end() noexcept override {}

private:
    static void keep_error(JobGroup& group, std::exception_ptr error);
};

}  // namespace spindle
