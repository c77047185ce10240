// `spindle run --trace FILE`: the scheduler's trace (stage spans of the physics loop,
// every job with its worker and PU) plus the game thread's frames, as Chrome
// trace-event JSON (chrome://tracing, https://ui.perfetto.dev), with a named row per
// thread.
#pragma once

#include <cstdint>
#include <ostream>
#include <span>

#include <spindle/platform/layout.hpp>
#include <spindle/scheduler/work_stealing.hpp>

namespace spindle::app {

// A span on the game thread, times from spindle::now_nanoseconds().
struct GameSpan {
    const char* name;  // a string literal
    std::int64_t begin_ns;
    std::int64_t end_ns;
};

// Rows: "physics loop: stages" (the stage spans), "worker i" (jobs; worker 0 is the
// physics loop thread), "game" (frames). Timestamps in microseconds from the first event.
void write_run_trace(std::ostream& out, std::span<const TraceEvent> scheduler, std::span<const GameSpan> game,
                     const LayoutMapping& mapping, std::span<const unsigned> worker_pus);

}  // namespace spindle::app
