// Broadphase benchmarks: named scenes (a table below) of boxes bouncing in a cube; one
// iteration is one step: move_proxy for every moving box, then update_pairs.
#include "spatial/proxy_trees.hpp"

#include <spindle/scheduler/single_threaded.hpp>

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace spindle {
namespace {

struct SceneSpec {
    const char* name;
    int moving;
    int statics;
    double fast_fraction;  // share of bodies at 30 m/s instead of 2 m/s
};

// Box half-sizes 0.2..1 m, about one body per 27 m^3: a few fat-box pairs per body.
constexpr SceneSpec kScenes[] = {
    {"moving_1k", 1000, 0, 0.1},
    {"moving_10k", 10000, 0, 0.1},
    {"moving_10k_slow", 10000, 0, 0.0},
    {"moving_10k_static_10k", 10000, 10000, 0.1},
};

struct Body {
    ProxyId proxy;
    Vec3 center;
    Vec3 half;
    Vec3 velocity;
};

class Scene {
public:
    explicit Scene(const SceneSpec& spec) : m_rng(1234), m_world(1.5 * std::cbrt(double(spec.moving + spec.statics))) {
        BroadphaseSettings settings;
        settings.validate_after_changes = false;
        m_bp = ProxyTrees(settings);
        for (int i = 0; i < spec.statics; ++i) {
            const Body b = make_body(0);
            m_bp.create_proxy(Aabb::from_center_extents(b.center, b.half), m_next_user++, true);
        }
        m_bp.rebuild_static_tree();
        for (int i = 0; i < spec.moving; ++i) {
            Body b = make_body(uniform(0, 1) < spec.fast_fraction ? 30.0 : 2.0);
            b.proxy = m_bp.create_proxy(Aabb::from_center_extents(b.center, b.half), m_next_user++, false);
            m_moving.push_back(b);
        }
        PairList pairs;
        m_bp.update_pairs(m_jobs, pairs);  // the initial pairs are not part of a step
    }

    // Returns (enlarged proxies, new pairs) of this step.
    std::pair<std::size_t, std::size_t> step(PairList& pairs) {
        const double dt = 1.0 / 60.0;
        for (Body& b : m_moving) {
            Vec3 d = b.velocity * dt;
            for (int k = 0; k < 3; ++k) {
                if (std::abs(b.center[k] + d[k]) > m_world) {
                    b.velocity[k] = -b.velocity[k];
                    d[k] = -d[k];
                }
            }
            b.center += d;
            m_bp.move_proxy(b.proxy, Aabb::from_center_extents(b.center, b.half), d);
        }
        const std::size_t enlarged = m_bp.enlarged_count();
        m_bp.update_pairs(m_jobs, pairs);
        return {enlarged, pairs.size()};
    }

    const ProxyTrees& broadphase() const { return m_bp; }

private:
    double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(m_rng); }
    Body make_body(double speed) {
        Body b;
        b.center = Vec3(uniform(-m_world, m_world), uniform(-m_world, m_world), uniform(-m_world, m_world));
        b.half = Vec3(uniform(0.2, 1.0), uniform(0.2, 1.0), uniform(0.2, 1.0));
        b.velocity = Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * speed;
        return b;
    }

    std::mt19937_64 m_rng;
    double m_world;
    ProxyTrees m_bp;
    SingleThreadedJobSystem m_jobs;
    std::vector<Body> m_moving;
    std::uint64_t m_next_user = 1;
};

void bm_step(benchmark::State& state, SceneSpec spec) {
    Scene scene(spec);
    PairList pairs;
    double enlarged = 0;
    double found = 0;
    for (auto _ : state) {
        const auto [e, p] = scene.step(pairs);
        enlarged += double(e);
        found += double(p);
        benchmark::DoNotOptimize(pairs.data());
    }
    state.counters["enlarged"] = benchmark::Counter(enlarged, benchmark::Counter::kAvgIterations);
    state.counters["pairs"] = benchmark::Counter(found, benchmark::Counter::kAvgIterations);
    state.counters["height"] = scene.broadphase().moving_tree().height();
}

// Building a tree of n static boxes: one insert at a time, or in bulk with rebuild().
void bm_build(benchmark::State& state, bool bulk) {
    const int n = static_cast<int>(state.range(0));
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> pos(-30, 30), size(0.2, 1.0);
    std::vector<Aabb> boxes;
    for (int i = 0; i < n; ++i) {
        boxes.push_back(
            Aabb::from_center_extents(Vec3(pos(rng), pos(rng), pos(rng)), Vec3(size(rng), size(rng), size(rng))));
    }
    double cost = 0;
    int height = 0;
    for (auto _ : state) {
        DynamicAabbTree tree(
            AabbTreeSettings{.margin = 0, .displacement_multiplier = 0, .validate_after_changes = false});
        for (int i = 0; i < n; ++i) tree.create_proxy(boxes[static_cast<std::size_t>(i)], std::uint64_t(i));
        if (bulk) tree.rebuild();
        cost = tree.area_cost();
        height = tree.height();
        benchmark::DoNotOptimize(cost);
    }
    state.counters["sah_cost"] = cost;
    state.counters["height"] = height;
}

}  // namespace
}  // namespace spindle

int main(int argc, char** argv) {
    using namespace spindle;
    for (const SceneSpec& spec : kScenes) {
        benchmark::RegisterBenchmark((std::string("step/") + spec.name).c_str(), bm_step, spec)
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::RegisterBenchmark("build/incremental", bm_build, false)->Arg(10000)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("build/incremental+rebuild", bm_build, true)
        ->Arg(10000)
        ->Unit(benchmark::kMillisecond);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
