// TracingJobSystem: a JobSystem decorator that records every stage span
// (trace_begin/trace_end), every parallel_for call and the chunks other threads ran,
// plus spans the program adds (the game thread's frames), and writes them as Chrome
// trace-event JSON (chrome://tracing, Perfetto). Until the work-stealing scheduler
// brings its own trace, this is what `spindle run --trace FILE` writes.
#pragma once

#include <cstdint>
#include <mutex>
#include <ostream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include <spindle/scheduler/job_system.hpp>

namespace spindle::app {

class TracingJobSystem final : public JobSystem {
public:
    // inner runs the jobs and must outlive this. max_events bounds memory; events
    // beyond it are dropped and the trace says it was truncated.
    explicit TracingJobSystem(JobSystem& inner, std::size_t max_events = 1'000'000);

    unsigned worker_count() const noexcept override { return m_inner.worker_count(); }
    void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                      RangeFn fn) override;
    // Stage names must be string literals (they are kept as pointers until write()).
    void trace_begin(const char* stage) noexcept override;
    void trace_end() noexcept override;

    // A span on the calling thread, times from spindle::now_nanoseconds(). Any thread.
    void add_span(const char* name, std::int64_t begin_ns, std::int64_t end_ns) noexcept;

    std::size_t event_count() const;
    bool truncated() const;
    // {"traceEvents":[...]} with thread names; timestamps in microseconds from construction.
    // Call once tracing is over (no thread still recording).
    void write(std::ostream& out) const;

private:
    struct Event {
        const char* name;
        std::int64_t begin_ns;
        std::int64_t end_ns;
        std::uint32_t tid;
    };
    std::uint32_t thread_id_locked();

    JobSystem& m_inner;
    const std::size_t m_max_events;
    const std::int64_t m_origin_ns;

    mutable std::mutex m_lock;
    std::vector<Event> m_events;
    std::unordered_map<std::thread::id, std::uint32_t> m_tids;
    std::vector<std::string> m_thread_names;  // by tid
    bool m_truncated = false;
};

}  // namespace spindle::app
