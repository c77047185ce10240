// JobSystems for broadphase tests: one that runs chunks on std::threads from the last
// chunk to the first (a different order and worker than SingleThreadedJobSystem), and
// one that counts chunks.
#pragma once

#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <spindle/scheduler/job_system.hpp>
#include <spindle/scheduler/single_threaded.hpp>

namespace spindle::test {

class ReverseThreadedJobSystem final : public JobSystem {
public:
    explicit ReverseThreadedJobSystem(unsigned workers) : m_workers(workers == 0 ? 1 : workers) {}
    unsigned worker_count() const noexcept override { return m_workers; }
    void parallel_for(const char*, std::uint32_t begin, std::uint32_t end, std::uint32_t grain, RangeFn fn) override {
        if (begin >= end) return;
        if (grain == 0) grain = 1;
        const std::uint64_t chunks = (std::uint64_t(end - begin) + grain - 1) / grain;
        std::atomic<std::int64_t> next{static_cast<std::int64_t>(chunks) - 1};
        std::exception_ptr error;
        std::mutex error_mutex;
        auto run = [&](unsigned worker) {
            for (;;) {
                const std::int64_t c = next.fetch_sub(1);
                if (c < 0) return;
                const std::uint32_t lo = begin + static_cast<std::uint32_t>(c) * grain;
                const std::uint32_t hi = end - lo > grain ? lo + grain : end;
                try {
                    fn(lo, hi, worker);
                } catch (...) {
                    std::lock_guard<std::mutex> lock(error_mutex);
                    if (!error) error = std::current_exception();
                }
            }
        };
        std::vector<std::thread> threads;
        for (unsigned w = 1; w < m_workers; ++w) threads.emplace_back(run, w);
        run(0);
        for (std::thread& t : threads) t.join();
        if (error) std::rethrow_exception(error);
    }
    void trace_begin(const char*) noexcept override {}
    void trace_end() noexcept override {}
    void run_graph(StageGraph& graph) override { SingleThreadedJobSystem().run_graph(graph); }
    // Each phase as one reversed parallel_for, in phase order.
    void run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) override {
        for (std::uint32_t p = 0; p < phases.size(); ++p) {
            parallel_for(name, 0, phases[p].count, phases[p].grain,
                         [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) { fn(p, lo, hi, worker); });
        }
    }

private:
    unsigned m_workers;
};

class CountingJobSystem final : public JobSystem {
public:
    unsigned worker_count() const noexcept override { return 1; }
    void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                      RangeFn fn) override {
        m_inner.parallel_for(name, begin, end, grain, [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
            ++chunks;
            fn(lo, hi, worker);
        });
    }
    void trace_begin(const char*) noexcept override {}
    void trace_end() noexcept override {}
    void run_graph(StageGraph& graph) override { SingleThreadedJobSystem().run_graph(graph); }
    void run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) override {
        m_inner.run_phases(name, phases, fn);
    }
    int chunks = 0;

private:
    SingleThreadedJobSystem m_inner;
};

}  // namespace spindle::test
