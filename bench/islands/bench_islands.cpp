// bench_islands: the time to wake, and to put back to sleep, one island of jointed bodies
// beside many awake bodies (which never sleep), single-threaded. One iteration wakes
// the island by a buffered wake and flushes (timed: the ApplyWrites stage), then takes
// one step in which it sleeps again (timed for the sleep case: the Islands stage).
#include <benchmark/benchmark.h>

#include <spindle/engine/space.hpp>

#include <vector>

#include "common/run.hpp"

namespace spindle::bench {
namespace {

constexpr int kIslandBodies = 4000;
constexpr int kAwakeBodies = 16000;

struct Scene {
    Space space;
    BodyHandle island_member;
    std::vector<BodyHandle> island;
};

// The island first, so its slots come before the awake bodies' (each of its bodies
// wakes into the front of the awake list: the costly place). No gravity: everything rests
// where it is made; the island sleeps after one resting step (the loose bodies never rest).
void build(Scene& s) {
    s.space.set_gravity(Vec3::Zero());
    s.space.set_sleep(SleepSettings{.time_to_sleep = 1e-6});
    BodyDesc link;
    link.shape = Shape::sphere(0.25);
    for (int i = 0; i < kIslandBodies; ++i) {
        link.position = Vec3(0.5 * i, -10, 0);
        s.island.push_back(s.space.create_body(link));
        if (i > 0) {
            s.space.create_joint(JointDesc::ball_socket_at(s.island[i - 1], s.island[i], Vec3(0.5 * i - 0.25, -10, 0)));
        }
    }
    s.island_member = s.island[kIslandBodies / 2];
    BodyDesc loose;
    loose.shape = Shape::sphere(0.25);
    loose.allow_sleep = false;
    for (int i = 0; i < kAwakeBodies; ++i) {
        loose.position = Vec3(i % 128, 10 + i / 128, 0);
        s.space.create_body(loose);
    }
}

Real stage_time(const Space& space, Stage stage) { return space.last_update().stage_seconds[static_cast<int>(stage)]; }

// Times one stage of each wake-then-sleep cycle: ApplyWrites (the wake) or Islands (the sleep).
void bm_island(benchmark::State& state, Stage timed) {
    Scene s;
    build(s);
    s.space.update();
    if (s.space.internal_is_awake(s.island_member)) {
        state.SkipWithError("the island did not fall asleep");
        return;
    }
    for (auto _ : state) {
        s.space.wake(s.island_member);
        s.space.flush();
        if (!s.space.internal_is_awake(s.island.front()) || !s.space.internal_is_awake(s.island.back())) {
            state.SkipWithError("the island did not wake whole");
            return;
        }
        const Real wake = stage_time(s.space, Stage::ApplyWrites);
        s.space.update();
        if (s.space.internal_is_awake(s.island_member)) {
            state.SkipWithError("the island did not fall asleep again");
            return;
        }
        state.SetIterationTime(timed == Stage::ApplyWrites ? wake : stage_time(s.space, Stage::Islands));
    }
    state.counters["island"] = kIslandBodies;
    state.counters["awake"] = s.space.last_update().awake_bodies;
}

}  // namespace
}  // namespace spindle::bench

int main(int argc, char** argv) {
    using namespace spindle::bench;
    using spindle::Stage;
    benchmark::RegisterBenchmark("wake_island_4k_beside_16k_awake", bm_island, Stage::ApplyWrites)
        ->Iterations(20)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("sleep_island_4k_beside_16k_awake", bm_island, Stage::Islands)
        ->Iterations(20)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
    std::vector<char*> rest = take_own_flags(argc, argv, [](const char*) { return false; });
    return run_registered_benchmarks(rest);
}
