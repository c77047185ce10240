// Contact events on the Jolt pyramid (1240 boxes dropped layer on layer, about 8k
// touching pairs once they land): every box asks for events (events 1) or none does
// (events 0); one benchmark iteration is one step and one read of the events it
// published, over the first 200 steps (the landing makes the begins, ends and hits).
// Reported: events per step, the step's time beside the same steps without events (the
// difference is what the events cost), and the read's time on the game side.
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>

#include <benchmark/benchmark.h>

#include "common/scenes.hpp"

namespace {

using namespace spindle;

void PyramidEvents(benchmark::State& state) {
    const bool events = state.range(0) != 0;
    Space space;
    bench::add_to_space(space, bench::pyramid_scene(), {.allow_sleep = false, .contact_events = events});
    std::vector<ContactEvent> read;
    std::uint64_t total = 0;
    double read_seconds = 0;
    for (auto _ : state) {
        space.update();
        read.clear();
        const std::int64_t t0 = now_nanoseconds();
        total += space.read_contact_events(read);
        read_seconds += static_cast<double>(now_nanoseconds() - t0) * 1e-9;
    }
    const double steps = static_cast<double>(state.iterations());
    state.counters["events_per_step"] = static_cast<double>(total) / steps;
    state.counters["read_us"] = read_seconds / steps * 1e6;
    state.counters["touching"] = static_cast<double>(space.last_update().contacts);
}

}  // namespace

BENCHMARK(PyramidEvents)->Arg(0)->Arg(1)->ArgName("events")->Iterations(200)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
