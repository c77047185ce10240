// Shared by the AABB tree tests: a seeded generator of boxes, a height bound, and queries
// sorted for comparison with a brute-force overlap list.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "spatial/aabb_tree.hpp"

namespace spindle::test {

#ifdef NDEBUG
constexpr int kScale = 8;  // Release: bigger trees
#else
constexpr int kScale = 2;  // Debug/ASan: every operation also walks the whole tree
#endif

struct Rng {
    std::mt19937_64 engine;
    explicit Rng(std::uint64_t seed) : engine(seed) {}
    Real uniform(Real lo, Real hi) { return std::uniform_real_distribution<Real>(lo, hi)(engine); }
    int index(int n) { return std::uniform_int_distribution<int>(0, n - 1)(engine); }
    Vec3 vec(Real lo, Real hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }
    Aabb box(Real world, Real max_half) {
        return Aabb::from_center_extents(vec(-world, world), vec(Real(0.05), max_half));
    }
};

// Slack over the AVL bound (1.44 log2 n) for small trees and SAH rotations.
inline int height_limit(std::int32_t n) { return static_cast<int>(2.5 * std::log2(std::max(n, 2))) + 3; }

inline std::vector<std::int32_t> query_sorted(const DynamicAabbTree& tree, const Aabb& box) {
    std::vector<std::int32_t> ids;
    tree.query(box, [&](std::int32_t id) {
        ids.push_back(id);
        return true;
    });
    std::sort(ids.begin(), ids.end());
    return ids;
}

inline std::vector<std::int32_t> brute_sorted(const DynamicAabbTree& tree, const std::vector<std::int32_t>& live,
                                              const Aabb& box) {
    std::vector<std::int32_t> ids;
    for (const std::int32_t id : live) {
        if (tree.fat_aabb(id).overlaps(box)) ids.push_back(id);
    }
    std::sort(ids.begin(), ids.end());
    return ids;
}

// Every proxy in the order the tree's query walks them.
inline std::vector<std::int32_t> walk_order(const DynamicAabbTree& tree) {
    std::vector<std::int32_t> order;
    tree.query(Aabb::from_center_extents(Vec3::Zero(), Vec3::Constant(1e9)), [&](std::int32_t id) {
        order.push_back(id);
        return true;
    });
    return order;
}

}  // namespace spindle::test
