// Narrowphase cost per shape pair: each named case collides a fixed set of 256 poses,
// most touching or penetrating, and reports the time per pair (per_pair) and how many
// poses produced a manifold (hit_rate).
#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "collision/collide.hpp"
#include "collision/convex_hull.hpp"
#include "collision/triangle_mesh.hpp"

namespace {

using namespace spindle;

constexpr int kPoses = 256;

Shape hull_of_box() {
    std::vector<Vec3> p;
    for (int i = 0; i < 8; ++i) p.emplace_back(i & 1 ? 0.5 : -0.5, i & 2 ? 0.4 : -0.4, i & 4 ? 0.3 : -0.3);
    return Shape::convex_hull(p);
}

// A rounded rock: 32 points on an ellipsoid.
Shape rock() {
    std::mt19937 rng(3);
    std::normal_distribution<Real> g;
    std::vector<Vec3> p;
    for (int i = 0; i < 32; ++i)
        p.push_back(Vec3(g(rng), g(rng), g(rng)).normalized().cwiseProduct(Vec3(0.6, 0.4, 0.5)));
    return Shape::convex_hull(p);
}

// 32 x 32 quads of gently rolling ground around the origin.
Shape terrain() {
    const int n = 32;
    std::vector<Vec3> v;
    std::vector<std::uint32_t> idx;
    for (int z = 0; z <= n; ++z) {
        for (int x = 0; x <= n; ++x) {
            const Real px = x - n / 2.0, pz = z - n / 2.0;
            v.emplace_back(px, 0.1 * std::sin(px * 0.7) * std::cos(pz * 0.5), pz);
        }
    }
    for (int z = 0; z < n; ++z) {
        for (int x = 0; x < n; ++x) {
            const auto at = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
            idx.insert(idx.end(), {at(x, z), at(x, z + 1), at(x + 1, z + 1), at(x, z), at(x + 1, z + 1), at(x + 1, z)});
        }
    }
    return Shape::triangle_mesh(v, idx);
}

struct Case {
    std::string name;
    Shape a;
    Shape b;
    Real spread;    // how far B's centre wanders from the touching distance
    Real distance;  // centre distance at which the pair roughly touches
};

struct PosePair {
    Transform a, b;
};

// Poses around contact: A at random spots and orientations, B offset by about
// `distance` in a random direction (static B keeps its identity pose).
std::vector<PosePair> make_poses(const Case& c) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<Real> u(-1, 1);
    std::vector<PosePair> poses;
    const bool static_b = c.b.static_only();
    for (int i = 0; i < kPoses; ++i) {
        const Quat qa(Eigen::AngleAxis<Real>(3 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()));
        const Quat qb(Eigen::AngleAxis<Real>(3 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()));
        if (static_b) {
            // Convex shapes resting on the ground with a little penetration.
            const Vec3 p(8 * u(rng), c.distance + c.spread * u(rng), 8 * u(rng));
            poses.push_back({{p, qa}, {}});
        } else {
            const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
            poses.push_back({{Vec3::Zero(), qa}, {dir * (c.distance + c.spread * u(rng)), qb}});
        }
    }
    return poses;
}

void run_case(benchmark::State& state, const Case& c) {
    const std::vector<PosePair> poses = make_poses(c);
    Manifold out[4];
    std::int64_t contacts = 0;
    for (auto _ : state) {
        for (const PosePair& p : poses) {
            const int n = collide(c.a, p.a, c.b, p.b, 0.02, out, 4);
            contacts += n;
            benchmark::DoNotOptimize(out[0].normal);
        }
    }
    const auto pairs = static_cast<double>(state.iterations()) * kPoses;
    // Seconds per pair (printed with an SI prefix, e.g. "45.2n" = 45.2 ns).
    state.counters["per_pair"] =
        benchmark::Counter(kPoses, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    state.counters["hit_rate"] = static_cast<double>(contacts) / pairs;
}

std::vector<Case> cases() {
    const Shape sphere = Shape::sphere(0.4);
    const Shape capsule = Shape::capsule(0.5, 0.3);
    const Shape box = Shape::box(Vec3(0.5, 0.4, 0.3));
    const Shape hull8 = hull_of_box();
    const Shape hull32 = rock();
    const Shape plane = Shape::plane(Vec3::UnitY(), 0);
    const Shape ground = terrain();
    return {
        {"sphere_sphere", sphere, sphere, 0.1, 0.78},
        {"sphere_capsule", sphere, capsule, 0.2, 0.9},
        {"sphere_box", sphere, box, 0.2, 0.8},
        {"sphere_hull32", sphere, hull32, 0.2, 0.85},
        {"capsule_capsule", capsule, capsule, 0.3, 0.9},
        {"capsule_box", capsule, box, 0.3, 0.9},
        {"capsule_hull32", capsule, hull32, 0.3, 1.0},
        {"box_box", box, box, 0.2, 0.8},
        {"box_hull8", box, hull8, 0.2, 0.8},
        {"hull8_hull8", hull8, hull8, 0.2, 0.8},
        {"hull32_hull32", hull32, hull32, 0.2, 0.9},
        {"sphere_plane", sphere, plane, 0.05, 0.38},
        {"capsule_plane", capsule, plane, 0.3, 0.5},
        {"box_plane", box, plane, 0.2, 0.5},
        {"hull32_plane", hull32, plane, 0.2, 0.45},
        {"sphere_mesh", sphere, ground, 0.1, 0.38},
        {"capsule_mesh", capsule, ground, 0.3, 0.5},
        {"box_mesh", box, ground, 0.2, 0.5},
        {"hull32_mesh", hull32, ground, 0.2, 0.45},
    };
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<Case> table = cases();
    for (const Case& c : table) {
        benchmark::RegisterBenchmark(("narrowphase/" + c.name).c_str(), [&c](benchmark::State& s) { run_case(s, c); });
    }
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
