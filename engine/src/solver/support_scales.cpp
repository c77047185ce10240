// Support mass scaling: which contacts have a light body carrying a heavier one, and
// how much lighter each solves it (SolverScratch::support_scales).
//
// A soft contact row is a spring whose stiffness is its effective mass times omega^2,
// and a light body dominates the effective mass: a 1 kg cube holding up 10,100 kg at
// the default 30 Hz would have to sink 2.8 m into the box it carries (and 0.7 m into the
// floor) before its rows pushed back hard enough, so it is squeezed out. Stiffer rows do
// not help: one Gauss-Seidel pass over two near-rigid rows on a 1 kg body launches it.
//
// So, as shock propagation (Guendelman et al. 2003; Erleben 2004) and the inverse mass
// scales of PhysX and Jolt (ContactSettings::mInvMassScale) do, the lower body of a
// support contact is made heavier, for that contact alone, when it is lighter than the
// body it carries: its inverse mass and inertia are scaled by m_upper^-1 / m_lower^-1, so
// the pair is solved as two equal masses. A column of any mass ratios then carries its
// loads as a column of equal cubes does, which the soft rows hold (each body feels its
// own weight plus the loads above scaled down to its own mass: no ratio compounds). The
// lower body's other contacts see it at its real mass, and the scaling is consistent
// for all rows of the pair (normal, friction, twist, restitution, warm start, push-out),
// so a static friction cone still holds what it holds unscaled. The price: momentum is
// not conserved between the pair (the light body answers the heavy one's pushes less),
// which is why only supported bodies get it: a body resting, through support contacts,
// on a static or kinematic body (or a sleeping one). A heavy body hitting a light body
// in the air exchanges momentum at the real masses.
//
// A contact supports when its normal is within 45 degrees of up (against gravity);
// without gravity nothing is supported. Pairs of equal masses, and scenes without a
// lighter body under a heavier one, are solved exactly as before (all scales are 1, and
// the search stops after one scan of the manifolds, or before it when every awake dynamic
// body has the same mass). Serial, over the manifold list in
// its order: the same for any number of workers.
#include <algorithm>

#include "solver/constraints.hpp"

namespace spindle {
namespace {

constexpr Real kSupportCos = 0.70710678118654752;  // cos 45 degrees

}  // namespace

void find_support_scales(const World& world, SolverScratch& scratch) {
    scratch.support_scales.clear();
    if (scratch.one_dynamic_mass) return;  // no body lighter than another: skip the scan below
    const Vec3 gravity = world.settings.gravity;
    const Real g = gravity.norm();
    if (!(g > 0)) return;
    const Vec3 up = -gravity / g;
    const RawRoomVector<SolverBody>& bodies = scratch.bodies;
    const RawRoomVector<ManifoldRef>& refs = scratch.manifolds;
    // The manifold's normal points from A to B: B rests on A when it points up.
    auto up_component = [&](const ManifoldRef& ref) {
        return world.contacts[ref.contact].manifold_at(static_cast<int>(ref.manifold)).normal.dot(up);
    };
    auto light_under_heavy = [&](const ManifoldRef& ref) {
        const SolverBody& a = bodies[ref.a];
        const SolverBody& b = bodies[ref.b];
        if (!a.dynamic || !b.dynamic || a.inv_mass == b.inv_mass) return false;
        const Real n = up_component(ref);
        return (n > kSupportCos && a.inv_mass > b.inv_mass) || (n < -kSupportCos && b.inv_mass > a.inv_mass);
    };
    if (std::none_of(refs.begin(), refs.end(), light_under_heavy)) return;

    // The support graph: an edge from each support contact's lower body to its upper one,
    // grouped by lower body (a stable counting sort: deterministic).
    std::vector<SupportEdge>& edges = scratch.support_edges;
    edges.clear();
    for (std::uint32_t k = 0; k < refs.size(); ++k) {
        const Real n = up_component(refs[k]);
        if (n > kSupportCos) edges.push_back({k, refs[k].a, refs[k].b});
        if (n < -kSupportCos) edges.push_back({k, refs[k].b, refs[k].a});
    }
    const std::size_t body_count = bodies.size();
    std::vector<std::uint32_t>& first = scratch.support_first;
    first.assign(body_count + 1, 0);
    for (const SupportEdge& e : edges) ++first[e.lower + 1];
    for (std::size_t i = 0; i < body_count; ++i) first[i + 1] += first[i];
    std::vector<std::uint32_t>& by_lower = scratch.support_by_lower;
    by_lower.resize(edges.size());
    {
        std::vector<std::uint32_t>& next = scratch.support_queue;  // borrowed as the fill cursors
        next.assign(first.begin(), first.end() - 1);
        for (std::uint32_t k = 0; k < edges.size(); ++k) by_lower[next[edges[k].lower]++] = k;
    }
    // Breadth first from the bodies resting on something that does not move.
    std::vector<std::uint8_t>& supported = scratch.supported;
    supported.assign(body_count, 0);
    std::vector<std::uint32_t>& queue = scratch.support_queue;
    queue.clear();
    auto reach = [&](std::uint32_t body) {
        if (!bodies[body].dynamic || supported[body]) return;
        supported[body] = 1;
        queue.push_back(body);
    };
    for (const SupportEdge& e : edges) {
        if (!bodies[e.lower].dynamic) reach(e.upper);
    }
    for (std::size_t head = 0; head < queue.size(); ++head) {
        const std::uint32_t lower = queue[head];
        for (std::uint32_t k = first[lower]; k < first[lower + 1]; ++k) reach(edges[by_lower[k]].upper);
    }

    scratch.support_scales.assign(refs.size(), SupportScale{});
    for (const SupportEdge& e : edges) {
        const SolverBody& lower = bodies[e.lower];
        const SolverBody& upper = bodies[e.upper];
        if (!lower.dynamic || !upper.dynamic || !supported[e.lower] || lower.inv_mass <= upper.inv_mass) continue;
        SupportScale& scale = scratch.support_scales[e.ref];
        (e.lower == refs[e.ref].a ? scale.a : scale.b) = upper.inv_mass / lower.inv_mass;
    }
}

}  // namespace spindle
