// bench_engine: Spindle's throughput on named scenes (the table below), each at 1 and 2
// threads; one benchmark iteration is one 60 Hz step. Reports steps/s and heap bytes per body.
// Scenes: Jolt's pyramid, 196 small pyramids, a mixed pile on a terrain mesh, a pile of 100
// jointed capsule chains, Jolt's ragdoll piles (the built-in scene `ragdolls`), a 10k box grid
// awake and asleep, and the peers' scenes from configs/scenes (Box3D's large_pyramid,
// convex_pile, washer, junkyard, joint_grid, rain, trees and large_world, Jolt's
// ConvexVsMesh), each with its own settings as `spindle bench` runs it.
//
// Own flags (taken out before Google Benchmark sees the rest):
//   --quick   a tenth of each scene's steps (at least 5)
//   --memory  a line per run: the bytes per body of each structure (api/memory_report.hpp)
#include "common/jobs.hpp"

#include <spindle/scene/scene.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "api/memory_report.hpp"
#include "common/run.hpp"
#include "common/scenes.hpp"
#include "common/timing.hpp"
#include "heap_counter.hpp"
#include "memory/huge_page_vector.hpp"

namespace spindle::bench {
namespace {

enum class SceneKind {
    Pyramid,          // Jolt's pyramid (as bench_peers), from the drop
    ManyPyramids,     // 196 small pyramids, from rest
    MixedPileOnMesh,  // four shape types falling onto a terrain mesh, from the drop
    ChainPile,        // 100 ball-socket chains of 10 capsules landing in a tangle (ragdoll-pile load)
    Ragdolls,         // configs/scenes/ragdolls.toml: 160 ragdolls in 16 piles on a heightfield, from the drop
    SceneFile,        // configs/scenes/<name>.toml, from its second step
    GridAwake,        // 10k resting boxes, sleeping disabled: the full pipeline every step
    GridSleeping,     // the same boxes once asleep: what a sleeping body costs per step
};

struct EngineScene {
    const char* name;  // SceneFile: the built-in scene's name too
    SceneKind kind;
    int steps;  // timed steps per run
};

// Step counts keep the whole default run (both thread counts) to a few minutes even on a
// loaded machine (the peers' scene files about a minute of it, much of that large_world's
// million static bodies being built). The pyramid takes 300 steps here (it stands after
// ~60); bench_peers runs the full 500-step Jolt measure against Bullet.
constexpr EngineScene kScenes[] = {
    {"pyramid", SceneKind::Pyramid, 300},
    {"many_pyramids", SceneKind::ManyPyramids, 40},
    {"mixed_pile_on_mesh", SceneKind::MixedPileOnMesh, 200},
    {"chain_pile", SceneKind::ChainPile, 100},
    {"ragdolls", SceneKind::Ragdolls, 300},  // five seconds: dropped, piled and come to rest
    {"grid_10k_awake", SceneKind::GridAwake, 60},
    {"grid_10k_sleeping", SceneKind::GridSleeping, 300},
    {"large_pyramid", SceneKind::SceneFile, 100},   // Box3D's: standing from the start
    {"convex_pile", SceneKind::SceneFile, 100},     // falling hulls
    {"washer", SceneKind::SceneFile, 60},           // cubes tumbling in the drum
    {"junkyard", SceneKind::SceneFile, 60},         // rocks falling into the yard
    {"joint_grid", SceneKind::SceneFile, 60},       // chains swinging down
    {"rain", SceneKind::SceneFile, 240},            // the ragdolls land at about step 120
    {"trees", SceneKind::SceneFile, 300},           // falling, landing and rolling
    {"large_world", SceneKind::SceneFile, 60},      // a million static boxes: about 10 s to build
    {"convex_vs_mesh", SceneKind::SceneFile, 300},  // dropped, bouncing, rolling
};

constexpr int kGridPerSide = 100;  // 10,000 boxes
constexpr int kMixedPileBodies = 2048;
constexpr int kChains = 100;
constexpr int kLinksPerChain = 10;
// The top layer lands after about 60 steps: timing starts on a pile, not on free fall.
constexpr int kChainSettleSteps = 60;
constexpr int kGridSettleSteps = 30;  // awake grid: contacts made and warm before timing
constexpr int kMaxStepsToSleep = 600;

bool g_quick = false;
bool g_memory = false;

struct Built {
    std::unique_ptr<JobSystem> jobs;
    std::unique_ptr<Space> space;
    std::vector<BodyHandle> bodies;   // the dynamic ones
    std::vector<JointHandle> joints;  // scenes from files: their joints
    bool asleep = true;               // GridSleeping: did every body fall asleep before timing
    std::int64_t heap_before = 0;     // live heap before the space was made
    std::int64_t mapped_before = 0;   // and held in the blocks mapped for huge pages (mapped_bytes_held)

    // The memory the space holds now (bodies, shapes, broadphase, contacts, solver scratch)
    // per dynamic body: the heap, and the pages held in the blocks mapped for huge pages (the
    // arrays on them, the medium block pool's chunks whole), which the heap's count does not
    // see; taken after the timed steps, so every scene counts the same.
    double bytes_per_body() const {
        const auto handle_bytes = static_cast<std::int64_t>(bodies.capacity() * sizeof(BodyHandle));
        const auto mapped = static_cast<std::int64_t>(mapped_bytes_held());
        const std::int64_t held = live_heap_bytes() - heap_before + mapped - mapped_before;
        return static_cast<double>(held - handle_bytes) / static_cast<double>(bodies.size());
    }
};

// Builds the scene and takes the untimed steps it needs.
Built build(const EngineScene& scene_entry, unsigned threads) {
    const SceneKind kind = scene_entry.kind;
    Built built;
    built.jobs = make_bench_jobs(threads);
    SpaceSettings settings;
    settings.sleep.enabled = kind == SceneKind::GridSleeping;
    BoxScene boxes;
    switch (kind) {
        case SceneKind::Pyramid: boxes = pyramid_scene(); break;
        case SceneKind::ManyPyramids: boxes = many_pyramids_scene(); break;
        case SceneKind::GridAwake:
        case SceneKind::GridSleeping: boxes = box_grid_scene(kGridPerSide); break;
        case SceneKind::MixedPileOnMesh:
        case SceneKind::ChainPile:
        case SceneKind::Ragdolls:
        case SceneKind::SceneFile: break;
    }
    built.heap_before = live_heap_bytes();
    built.mapped_before = static_cast<std::int64_t>(mapped_bytes_held());
    built.space = std::make_unique<Space>(settings, built.jobs.get());
    Space& space = *built.space;
    if (kind == SceneKind::MixedPileOnMesh) {
        built.bodies = add_mixed_pile_on_mesh(space, kMixedPileBodies);
    } else if (kind == SceneKind::ChainPile) {
        built.bodies = add_chain_pile(space, kChains, kLinksPerChain);
    } else if (kind == SceneKind::Ragdolls || kind == SceneKind::SceneFile) {
        // The scene's own settings (ragdolls: sleeping on, as in Jolt's), like `spindle bench`.
        const std::string name = kind == SceneKind::Ragdolls ? "ragdolls" : scene_entry.name;
        const SceneDesc scene = load_scene(SPINDLE_SOURCE_DIR "/configs/scenes/" + name + ".toml");
        const std::vector<BodyHandle> handles = spindle::build(scene, space, &built.joints);
        for (std::size_t i = 0; i < handles.size(); ++i) {
            if (scene.bodies[i].desc.type == MotionType::Dynamic) built.bodies.push_back(handles[i]);
        }
    } else {
        built.bodies = add_to_space(space, boxes, {.floor = FloorShape::Box, .allow_sleep = settings.sleep.enabled});
    }
    if (kind == SceneKind::GridAwake) {
        for (int i = 0; i < kGridSettleSteps; ++i) space.update();
    } else if (kind == SceneKind::ChainPile) {
        for (int i = 0; i < kChainSettleSteps; ++i) space.update();
    } else if (kind == SceneKind::SceneFile) {
        space.update();  // the first step makes every contact: left out, as the peers' benchmarks do
    } else if (kind == SceneKind::GridSleeping) {
        int steps = 0;
        do {
            space.update();
        } while (space.last_update().awake_bodies > 0 && ++steps < kMaxStepsToSleep);
        built.asleep = space.last_update().awake_bodies == 0;
    }
    return built;
}

struct WorstJointError {
    Real linear = 0;   // m: anchors apart
    Real angular = 0;  // rad: axes apart, outside a cone or twist range, or a hinge outside its limits
};

WorstJointError worst_joint_error(const Space& space, const std::vector<JointHandle>& joints) {
    WorstJointError worst;
    for (JointHandle joint : joints) {
        const JointError error = space.internal_joint_error(joint);
        worst.linear = std::max(worst.linear, error.linear);
        worst.angular = std::max(worst.angular, error.angular);
        const JointDesc desc = space.joint_desc(joint);
        if (desc.type == JointType::Hinge && desc.hinge.enable_limit) {
            const Real angle = space.internal_hinge_angle(joint);
            worst.angular = std::max({worst.angular, desc.hinge.lower_angle - angle, angle - desc.hinge.upper_angle});
        }
    }
    return worst;
}

// Where bytes_per_body goes: each structure's share at its capacity, and the rest: what the
// heap counter sees besides (published buffers, write buffer, events, joints, shapes'
// shared data, job arenas) and the pages held beyond the arrays' bytes (a huge page's
// unused part, the medium block pool's chunks whole). `mapped` is the pages held in the
// blocks mapped for huge pages, of bytes_per_body.
void print_memory(const char* name, unsigned threads, const Built& built) {
    const MemoryReport report = memory_report(*built.space);
    const double per_body = 1.0 / static_cast<double>(built.bodies.size());
    const auto at = [&](std::size_t bytes) { return static_cast<double>(bytes) * per_body; };
    std::printf("memory %s/threads:%u bytes_per_body=%.0f bodies=%.0f contacts=%.0f extras=%.0f lookup=%.0f wide=%.0f "
                "push_rows=%.0f solver_other=%.0f broadphase=%.0f query_scenes=%.0f rest=%.0f mapped=%.0f\n",
                name, threads, built.bytes_per_body(), at(report.bodies), at(report.contacts),
                at(report.contact_extras), at(report.contact_lookup), at(report.wide_contacts), at(report.push_rows),
                at(report.solver_other), at(report.broadphase), at(report.query_scenes),
                built.bytes_per_body() - at(report.total()),
                static_cast<double>(static_cast<std::int64_t>(mapped_bytes_held()) - built.mapped_before) * per_body);
    std::fflush(stdout);
}

void bm_scene(benchmark::State& state, EngineScene scene) {
    const auto threads = static_cast<unsigned>(state.range(0));
    Built built = build(scene, threads);
    if (!built.asleep) {
        state.SkipWithError("the grid did not fall asleep within the step cap");
        return;
    }
    Space& space = *built.space;
    const StepClock clock;
    for (auto _ : state) space.update();
    const double wall = clock.wall_seconds();
    const double cpu = clock.cpu_seconds();
    const auto steps = static_cast<double>(state.iterations());
    state.counters["steps_per_s"] = steps / wall;
    state.counters["cpu_steps_per_s"] = steps / cpu;
    state.counters["bodies"] = static_cast<double>(built.bodies.size());
    state.counters["bytes_per_body"] = built.bytes_per_body();
    state.counters["workers"] = built.jobs->worker_count();
    state.counters["awake"] = space.last_update().awake_bodies;
    state.counters["contacts"] = space.last_update().contacts;
    if (scene.kind == SceneKind::Pyramid) state.counters["top_y"] = height_of(space, built.bodies.back());
    if (g_memory) print_memory(scene.name, threads, built);
    if (!built.joints.empty()) {
        const WorstJointError worst = worst_joint_error(space, built.joints);
        state.counters["joint_error_m"] = worst.linear;
        state.counters["joint_error_rad"] = worst.angular;
    }
}

void print_notes() {
    std::printf("bench_engine notes:\n");
    for (unsigned threads : {1u, 2u}) {
        std::printf("  threads:%u runs %u worker(s) (bench/common/jobs.hpp make_bench_jobs)\n", threads,
                    make_bench_jobs(threads)->worker_count());
    }
    std::fflush(stdout);
}

}  // namespace
}  // namespace spindle::bench

int main(int argc, char** argv) {
    using namespace spindle::bench;
    std::vector<char*> rest = take_own_flags(argc, argv, [](const char* arg) {
        if (std::strcmp(arg, "--quick") == 0) return g_quick = true;
        if (std::strcmp(arg, "--memory") == 0) return g_memory = true;
        return false;
    });
    for (const EngineScene& scene : kScenes) {
        const int steps = g_quick ? std::max(5, scene.steps / 10) : scene.steps;
        benchmark::RegisterBenchmark(scene.name, bm_scene, scene)
            ->ArgName("threads")
            ->Arg(1)
            ->Arg(2)
            ->Iterations(steps)
            ->UseRealTime()
            ->Unit(benchmark::kMillisecond);
    }
    print_notes();
    return run_registered_benchmarks(rest);
}
