// Buffering costs: get_motion_states for 1k/10k/100k bodies next to a plain memcpy of
// the same bytes (the ratio is the price of the lock and the interpolation), the
// FlipReadBuffers lock hold, and the game thread's read latency while an AsyncRunner
// steps the space on another thread, and the writes per second several threads make
// beside the steps per second the loop keeps.
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

namespace {

using namespace spindle;

// n kinematic bodies drifting and turning without contacts: every step publishes all of
// them, and a blended read turns each (0.6 to 1.8 rad/s, as tumbling debris).
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
        d.angular_velocity = Vec3(0.6, 0.2 * (i % 7), 1.0);
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

// Writer threads flat out (apply_impulse and set_angular_velocity on random bodies of n)
// while an AsyncRunner steps the space at 60 Hz: the writes per second made, beside the
// steps per second the loop kept (the write buffer coalesces per body, so ApplyWrites
// costs per body written; a log of every write once left the loop 1-12 steps a second).
void WritesWhilePhysicsRuns(benchmark::State& state) {
    const int writers = static_cast<int>(state.range(0));
    constexpr int kBodies = 1000;
    auto space = make_space(kBodies, false);
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    space->motion_states().get_all_motion_states(handles, states);
    AsyncRunner runner(*space);
    runner.start();
    std::atomic<bool> writing{true};
    std::atomic<std::uint64_t> made{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < writers; ++t) {
        threads.emplace_back([&, t] {
            std::uint64_t count = 0;
            std::uint32_t k = 2654435761u * static_cast<std::uint32_t>(t + 1);
            while (writing.load(std::memory_order_relaxed)) {
                k = k * 1664525u + 1013904223u;
                space->apply_impulse(handles[k % handles.size()], Vec3(0.001, 0, 0));
                space->set_angular_velocity(handles[(k >> 8) % handles.size()], Vec3(0, 0, 0.1));
                count += 2;
            }
            made.fetch_add(count);
        });
    }
    const std::uint64_t steps_before = runner.stats().steps;
    const std::int64_t t0 = now_nanoseconds();
    for (auto _ : state) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const double seconds = static_cast<double>(now_nanoseconds() - t0) * 1e-9;
    const AsyncStats stats = runner.stats();
    writing.store(false);
    for (std::thread& t : threads) t.join();
    runner.stop();
    state.counters["writes_per_s"] = static_cast<double>(made.load()) / seconds;
    state.counters["steps_per_s"] = static_cast<double>(stats.steps - steps_before) / seconds;
    state.counters["update_ms_p99"] = stats.update_ms_p99;
}

}  // namespace

BENCHMARK(WritesWhilePhysicsRuns)->DenseRange(0, 4, 2)->ArgName("writers")->Iterations(20)->UseRealTime();
BENCHMARK(GetMotionStates)->ArgsProduct({{1000, 10000, 100000}, {0, 1}})->ArgNames({"bodies", "interpolate"});
BENCHMARK(Memcpy)->Arg(1000)->Arg(10000)->Arg(100000)->ArgName("bodies");
BENCHMARK(FlipLockHold)->Arg(1000)->Arg(10000)->Arg(100000)->ArgName("bodies");
BENCHMARK(ReadLatencyWhilePhysicsRuns)->Arg(10000)->ArgName("bodies")->MinTime(1.0);
BENCHMARK_MAIN();
