// The run's Chrome trace-event JSON: scheduler events and game-thread frames merged.
#include "trace.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>
#include <string_view>

namespace spindle::app {
namespace {

// Rows of the trace (Chrome's "tid"): workers keep their index.
constexpr unsigned kStageRow = 1000;
constexpr unsigned kGameRow = 2000;

void write_string(std::ostream& out, std::string_view text) {
    out << '"';
    for (const char c : text) {
        if (c == '"' || c == '\\') {
            out << '\\' << c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
            out << escaped;
        } else {
            out << c;
        }
    }
    out << '"';
}

void write_row_name(std::ostream& out, unsigned row, const std::string& name, unsigned order) {
    out << ",\n{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":" << row << ",\"args\":{\"name\":";
    write_string(out, name);
    out << "}},\n{\"name\":\"thread_sort_index\",\"ph\":\"M\",\"pid\":1,\"tid\":" << row
        << ",\"args\":{\"sort_index\":" << order << "}}";
}

void write_span(std::ostream& out, const char* name, const char* category, unsigned row, std::int64_t begin_ns,
                std::int64_t end_ns, std::int64_t origin_ns, int pu) {
    char times[96];
    std::snprintf(times, sizeof times, "\"ts\":%.3f,\"dur\":%.3f", static_cast<double>(begin_ns - origin_ns) * 1e-3,
                  static_cast<double>(end_ns - begin_ns) * 1e-3);
    out << ",\n{\"name\":";
    write_string(out, name ? name : "?");
    out << ",\"ph\":\"X\",\"cat\":";
    write_string(out, category ? category : "");
    out << ',' << times << ",\"pid\":1,\"tid\":" << row << ",\"args\":{\"pu\":" << pu << "}}";
}

}  // namespace

void write_run_trace(std::ostream& out, std::span<const TraceEvent> scheduler, std::span<const GameSpan> game,
                     const LayoutMapping& mapping, std::span<const unsigned> worker_pus) {
    std::int64_t origin = std::numeric_limits<std::int64_t>::max();
    for (const TraceEvent& e : scheduler) origin = std::min(origin, e.begin_ns);
    for (const GameSpan& s : game) origin = std::min(origin, s.begin_ns);
    if (origin == std::numeric_limits<std::int64_t>::max()) origin = 0;

    out << "{\"traceEvents\":[\n";
    out << R"({"name":"process_name","ph":"M","pid":1,"tid":0,"args":{"name":"spindle run"}})";
    write_row_name(out, kGameRow, "game (PU " + std::to_string(mapping.game.real_pu) + ")", 0);
    write_row_name(out, kStageRow, "physics loop: stages (PU " + std::to_string(mapping.physics.real_pu) + ")", 1);
    for (unsigned w = 0; w < worker_pus.size(); ++w) {
        write_row_name(out, w,
                       "worker " + std::to_string(w) + (w == 0 ? " = physics loop" : "") + " (PU " +
                           std::to_string(worker_pus[w]) + ")",
                       2 + w);
    }
    for (const GameSpan& s : game) {
        write_span(out, s.name, "game", kGameRow, s.begin_ns, s.end_ns, origin, static_cast<int>(mapping.game.real_pu));
    }
    for (const TraceEvent& e : scheduler) {
        const bool stage = std::string_view(e.stage ? e.stage : "") == "stage";
        write_span(out, e.name, e.stage, stage ? kStageRow : e.worker, e.begin_ns, e.end_ns, origin, e.pu);
    }
    out << "\n],\"displayTimeUnit\":\"ms\"}\n";
}

}  // namespace spindle::app
