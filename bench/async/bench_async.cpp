// Buffering costs: get_motion_states for 1k/10k/100k bodies next to a plain memcpy of
// the same bytes (the ratio is the price of the lock and the interpolation), the
// FlipReadBuffers lock hold, and the game thread's read latency while an AsyncRunner
// steps the space on another thread.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <vector>

namespace {

using namespace spindle;

// n kinematic bodies drifting without contacts: every step publishes all of them.
std::unique_ptr<Space> make_space(int n, bool interpolate) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    settings.sleep.enabled = false;
    settings.time_step.use_internal_time_stepping = true;
    auto space = std::make_unique<Space>(settings);
    for (int i = 0; i < n; ++i) {
        BodyDesc d;
        d.type = MotionType::Kinematic;
        d.shape = Shape::sphere(0.1);
        d.position = Vec3(i % 100, (i / 100) % 100, i / 10000) * 0.5;
        d.linear_velocity = Vec3(0.1, 0, 0);
        d.allow_interpolation = interpolate;
        space->create_body(d);
    }
    space->update(1.0 / 60.0);
    space->update(1.0 / 60.0 + 0.004);  // leaves time over, so interpolating bodies blend
    return space;
}

void GetMotionStates(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    const bool interpolate = state.range(1) != 0;
    auto space = make_space(n, interpolate);
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    space->motion_states().get_all_motion_states(handles, states);
    for (auto _ : state) {
        space->motion_states().get_all_motion_states(handles, states);
        benchmark::DoNotOptimize(states.data());
    }
    state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(n * sizeof(MotionState)));
    state.counters["ns_per_body"] = benchmark::Counter(
        static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void Memcpy(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    std::vector<MotionState> from(n), to(n);
    for (auto _ : state) {
        std::memcpy(static_cast<void*>(to.data()), from.data(), n * sizeof(MotionState));
        benchmark::DoNotOptimize(to.data());
    }
    state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(n * sizeof(MotionState)));
    state.counters["ns_per_body"] = benchmark::Counter(
        static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// One update that takes a step, with the flip's lock hold reported from UpdateStats.
void FlipLockHold(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    auto space = make_space(n, true);
    double held = 0, worst = 0;
    for (auto _ : state) {
        space->update(1.0 / 60.0);
        held += space->last_update().flip_lock_seconds;
        worst = std::max(worst, space->last_update().flip_lock_seconds);
    }
    state.counters["lock_hold_ns"] = held / static_cast<double>(state.iterations()) * 1e9;
    state.counters["lock_hold_max_ns"] = worst * 1e9;
}

// The game thread reading one body and copying all states while the physics loop runs.
void ReadLatencyWhilePhysicsRuns(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    auto space = make_space(n, true);
    AsyncRunner runner(*space);
    runner.start();
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    space->motion_states().get_all_motion_states(handles, states);
    std::vector<double> latencies;
    latencies.reserve(1 << 20);
    for (auto _ : state) {
        const std::int64_t t0 = now_nanoseconds();
        space->motion_states().get_all_motion_states(handles, states);
        latencies.push_back(static_cast<double>(now_nanoseconds() - t0));
    }
    runner.stop();
    std::sort(latencies.begin(), latencies.end());
    state.counters["p50_us"] = latencies[latencies.size() / 2] * 1e-3;
    state.counters["p99_us"] = latencies[latencies.size() * 99 / 100] * 1e-3;
    state.counters["max_us"] = latencies.back() * 1e-3;
    state.counters["physics_steps"] = static_cast<double>(runner.stats().steps);
}

}  // namespace

BENCHMARK(GetMotionStates)->ArgsProduct({{1000, 10000, 100000}, {0, 1}})->ArgNames({"bodies", "interpolate"});
BENCHMARK(Memcpy)->Arg(1000)->Arg(10000)->Arg(100000)->ArgName("bodies");
BENCHMARK(FlipLockHold)->Arg(1000)->Arg(10000)->Arg(100000)->ArgName("bodies");
BENCHMARK(ReadLatencyWhilePhysicsRuns)->Arg(10000)->ArgName("bodies")->MinTime(1.0);
BENCHMARK_MAIN();
