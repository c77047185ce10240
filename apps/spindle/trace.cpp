// TracingJobSystem: records spans with their thread and writes Chrome trace-event JSON.
#include "trace.hpp"

#include <spindle/platform/clock.hpp>
#include <spindle/platform/thread.hpp>

#include <cstdio>

namespace spindle::app {
namespace {

// Open stage spans of the calling thread. Spans nest per thread, so one stack per
// thread serves every tracer.
struct OpenSpan {
    const char* name;
    std::int64_t begin_ns;
};
thread_local std::vector<OpenSpan> t_open;

void write_string(std::ostream& out, std::string_view text) {
    out << '"';
    for (const char c : text) {
        if (c == '"' || c == '\\') {
            out << '\\' << c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
            out << escaped;
        } else {
            out << c;
        }
    }
    out << '"';
}

}  // namespace

TracingJobSystem::TracingJobSystem(JobSystem& inner, std::size_t max_events)
    : m_inner(inner), m_max_events(max_events), m_origin_ns(now_nanoseconds()) {}

void TracingJobSystem::parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                                    RangeFn fn) {
    const std::thread::id caller = std::this_thread::get_id();
    const std::int64_t start = now_nanoseconds();
    // Chunks the calling thread runs are inside the call's own span; only chunks run
    // by other threads (workers) get spans of their own, which keeps a single-threaded
    // trace small while a multi-threaded one still shows who ran what.
    auto traced = [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
        if (std::this_thread::get_id() == caller) {
            fn(lo, hi, worker);
            return;
        }
        const std::int64_t chunk_start = now_nanoseconds();
        fn(lo, hi, worker);
        add_span(name, chunk_start, now_nanoseconds());
    };
    m_inner.parallel_for(name, begin, end, grain, traced);
    add_span(name, start, now_nanoseconds());
}

void TracingJobSystem::trace_begin(const char* stage) noexcept {
    try {
        t_open.push_back({stage, now_nanoseconds()});
    } catch (...) {
        // Out of memory for the stack: the span is lost, the program goes on.
    }
    m_inner.trace_begin(stage);
}

void TracingJobSystem::trace_end() noexcept {
    m_inner.trace_end();
    if (t_open.empty()) return;
    const OpenSpan span = t_open.back();
    t_open.pop_back();
    add_span(span.name, span.begin_ns, now_nanoseconds());
}

std::uint32_t TracingJobSystem::thread_id_locked() {
    const auto [it, inserted] = m_tids.try_emplace(std::this_thread::get_id(), static_cast<std::uint32_t>(m_tids.size()));
    if (inserted) {
        std::string name = current_thread_name();
        m_thread_names.push_back(name.empty() ? "thread " + std::to_string(it->second) : std::move(name));
    }
    return it->second;
}

void TracingJobSystem::add_span(const char* name, std::int64_t begin_ns, std::int64_t end_ns) noexcept {
    try {
        std::scoped_lock guard(m_lock);
        if (m_events.size() >= m_max_events) {
            m_truncated = true;
            return;
        }
        m_events.push_back({name, begin_ns, end_ns, thread_id_locked()});
    } catch (...) {
        m_truncated = true;  // out of memory: drop the event rather than stop the program
    }
}

std::size_t TracingJobSystem::event_count() const {
    std::scoped_lock guard(m_lock);
    return m_events.size();
}

bool TracingJobSystem::truncated() const {
    std::scoped_lock guard(m_lock);
    return m_truncated;
}

void TracingJobSystem::write(std::ostream& out) const {
    std::scoped_lock guard(m_lock);
    out << "{\"traceEvents\":[\n";
    out << R"({"name":"process_name","ph":"M","pid":1,"tid":0,"args":{"name":"spindle"}})";
    for (std::uint32_t tid = 0; tid < m_thread_names.size(); ++tid) {
        out << ",\n{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":" << tid << ",\"args\":{\"name\":";
        write_string(out, m_thread_names[tid]);
        out << "}}";
    }
    char number[64];
    for (const Event& e : m_events) {
        out << ",\n{\"name\":";
        write_string(out, e.name ? e.name : "?");
        std::snprintf(number, sizeof number, "%.3f", static_cast<double>(e.begin_ns - m_origin_ns) * 1e-3);
        out << ",\"ph\":\"X\",\"ts\":" << number;
        std::snprintf(number, sizeof number, "%.3f", static_cast<double>(e.end_ns - e.begin_ns) * 1e-3);
        out << ",\"dur\":" << number << ",\"pid\":1,\"tid\":" << e.tid << '}';
    }
    out << "\n],\"displayTimeUnit\":\"ms\",\"otherData\":{\"truncated\":" << (m_truncated ? "true" : "false")
        << "}}\n";
}

}  // namespace spindle::app
