// Compounds in the narrowphase: each part whose bounds come within the speculative
// distance of the other shape (or its part) is collided through the pair table as if
// it were a body of its own, and its manifolds are labelled with the part indices.
#include <algorithm>
#include <array>

#include "collision/clipping.hpp"
#include "collision/compound.hpp"
#include "collision/pair_functions.hpp"

namespace spindle::detail {
namespace {

// Manifolds kept while walking part pairs; past this a deeper one replaces the shallowest.
constexpr int kMaxGathered = 64;
constexpr int kPerPair = 4;               // a mesh may give several manifolds per part
constexpr std::size_t kInlineParts = 32;  // parts posed on the stack; more go to the heap

struct Gathered {
    std::array<Manifold, kMaxGathered> list;
    int count = 0;
};

Real deepest(const Manifold& m) {
    Real d = kHuge;
    for (int i = 0; i < m.point_count; ++i) d = std::min(d, m.points[i].separation);
    return d;
}

void keep(Gathered& g, const Manifold& m) {
    if (g.count < kMaxGathered) {
        g.list[static_cast<std::size_t>(g.count++)] = m;
        return;
    }
    auto shallowest = g.list.begin();
    for (auto it = g.list.begin(); it != g.list.end(); ++it) {
        if (deepest(*it) > deepest(*shallowest)) shallowest = it;
    }
    if (deepest(m) >= deepest(*shallowest)) return;
    // Out of its place, and m at the end: the list stays in the order of the walk.
    std::move(shallowest + 1, g.list.end(), shallowest);
    g.list.back() = m;
}

// Compound b's parts posed in the world, with their world bounds: worked out once per
// pair, not once for every part of the other shape they are tested against.
struct PosedParts {
    explicit PosedParts(const Compound& parts, const Transform& x)
        : compound(parts), poses(parts.size()), bounds(parts.size()) {
        for (std::uint32_t i = 0; i < parts.size(); ++i) {
            poses[i] = x * parts.pose(i);
            bounds[i] = parts.shape(i).bounds(poses[i]);
            all = all.merged(bounds[i]);
        }
    }
    const Compound& compound;
    ScratchBuffer<Transform, kInlineParts> poses;
    ScratchBuffer<Aabb, kInlineParts> bounds;
    Aabb all;
};

// Shape a (part `part_a` of its body, 0 if it is whole) against every part of compound b
// near it.
void collide_parts(const Shape& a, const Transform& xa, std::uint32_t part_a, const Aabb& a_box, PosedParts& b,
                   Real speculative, Gathered& g) {
    Manifold found[kPerPair];
    for (std::uint32_t i = 0; i < b.compound.size(); ++i) {
        if (!a_box.overlaps(b.bounds[i])) continue;
        const int n = collide(a, xa, b.compound.shape(i), b.poses[i], speculative, found, kPerPair);
        for (int m = 0; m < n; ++m) {
            found[m].part_a = part_a;
            found[m].part_b = i;
            keep(g, found[m]);
        }
    }
}

// The deepest `capacity` manifolds, in part-pair order (the order of the walk), so the
// order does not depend on which were kept.
int emit(Gathered& g, Manifold* out, int capacity) {
    const auto end = g.list.begin() + g.count;
    if (g.count > capacity) {
        std::array<int, kMaxGathered> order;
        for (int i = 0; i < g.count; ++i) order[static_cast<std::size_t>(i)] = i;
        std::stable_sort(order.begin(), order.begin() + g.count, [&](int x, int y) {
            return deepest(g.list[static_cast<std::size_t>(x)]) < deepest(g.list[static_cast<std::size_t>(y)]);
        });
        std::sort(order.begin(), order.begin() + capacity);
        for (int i = 0; i < capacity; ++i)
            out[i] = g.list[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
        return capacity;
    }
    std::copy(g.list.begin(), end, out);
    return g.count;
}

}  // namespace

int collide_shape_compound(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                           Manifold* out, int capacity) {
    Gathered g;
    const Aabb a_box = a.bounds(xa).fattened(std::max(speculative, Real(0)));
    PosedParts parts(*b.parts, xb);
    collide_parts(a, xa, 0, a_box, parts, speculative, g);
    return emit(g, out, capacity);
}

int collide_compound_compound(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                              Real speculative, Manifold* out, int capacity) {
    Gathered g;
    const Compound& parts = *a.parts;
    PosedParts b_parts(*b.parts, xb);
    for (std::uint32_t j = 0; j < parts.size(); ++j) {
        const Transform x = xa * parts.pose(j);
        const Aabb part_box = parts.shape(j).bounds(x).fattened(std::max(speculative, Real(0)));
        if (!part_box.overlaps(b_parts.all)) continue;
        collide_parts(parts.shape(j), x, j, part_box, b_parts, speculative, g);
    }
    return emit(g, out, capacity);
}

}  // namespace spindle::detail
