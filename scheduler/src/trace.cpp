// WorkStealingJobSystem's trace: stage spans, the per-worker job events merged, and the
// Chrome trace-event JSON writer.
#include "worker.hpp"

#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <algorithm>
#include <fstream>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace spindle {

void WorkStealingJobSystem::trace_begin(const char* stage) noexcept {
    if (!trace_enabled()) return;
    std::scoped_lock guard(m_stage_lock);
    m_open_stages.emplace_back(stage, now_nanoseconds());
}

void WorkStealingJobSystem::trace_end() noexcept {
    if (!trace_enabled()) return;
    std::scoped_lock guard(m_stage_lock);
    if (m_open_stages.empty()) return;
    const auto [stage, begin] = m_open_stages.back();
    m_open_stages.pop_back();
    m_stage_events.push_back(TraceEvent{stage, "stage", begin, now_nanoseconds(), 0, current_cpu()});
}

std::vector<TraceEvent> WorkStealingJobSystem::trace_events() const {
    std::vector<TraceEvent> all;
    {
        std::scoped_lock guard(m_stage_lock);
        all = m_stage_events;
    }
    for (const auto& w : m_workers) all.insert(all.end(), w->events.begin(), w->events.end());
    std::sort(all.begin(), all.end(), [](const TraceEvent& a, const TraceEvent& b) { return a.begin_ns < b.begin_ns; });
    return all;
}

void WorkStealingJobSystem::clear_trace() {
    std::scoped_lock guard(m_stage_lock);
    m_stage_events.clear();
    for (auto& w : m_workers) w->events.clear();
}

void write_chrome_trace(std::ostream& out, const std::vector<TraceEvent>& events) {
    out << "{\"traceEvents\":[";
    const std::int64_t origin = events.empty() ? 0 : events.front().begin_ns;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const TraceEvent& e = events[i];
        // Stage spans on their own row (tid 1000) so they frame the job rows.
        const unsigned tid = std::string_view(e.stage) == "stage" ? 1000u : e.worker;
        out << (i ? ",\n" : "\n") << "{\"name\":\"" << e.name << "\",\"cat\":\"" << e.stage
            << "\",\"ph\":\"X\",\"pid\":1,\"tid\":" << tid
            << ",\"ts\":" << static_cast<double>(e.begin_ns - origin) / 1e3
            << ",\"dur\":" << static_cast<double>(e.end_ns - e.begin_ns) / 1e3 << ",\"args\":{\"worker\":" << e.worker
            << ",\"pu\":" << e.pu << "}}";
    }
    out << "\n],\"displayTimeUnit\":\"ms\"}\n";
}

void WorkStealingJobSystem::write_trace(std::ostream& out) const { write_chrome_trace(out, trace_events()); }

void WorkStealingJobSystem::write_trace(const std::string& path) const {
    std::ofstream out(path);
    if (!out) throw Error(path + ": cannot write the trace");
    write_trace(out);
}

}  // namespace spindle
