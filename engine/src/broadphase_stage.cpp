// Broadphase stage: bounds of awake bodies, new pairs -> contacts, contacts whose
// fat bounds separated -> removed. (Brute force over the fat bounds for now; the
// dynamic AABB tree replaces the pair search.)
#include <algorithm>

#include "broadphase_stage.hpp"
#include "stages.hpp"

namespace spindle {
namespace {

constexpr Real kAabbMargin = 0.1;  // m: fat bounds need not be refreshed for small moves

Aabb fat_bounds(const World& world, std::uint32_t i, Real dt) {
    const Bodies& b = world.bodies;
    Aabb box = b.bounds[i].fattened(kAabbMargin);
    // Enlarged along the motion so speculative contacts are found ahead of it.
    const Vec3 d = b.v[i] * dt;
    box.min += d.cwiseMin(Vec3::Zero());
    box.max += d.cwiseMax(Vec3::Zero());
    return box;
}

}  // namespace

void add_proxy(World& world, std::uint32_t slot) {
    BroadphaseState& bp = *world.broadphase;
    if (bp.fat.size() <= slot) bp.fat.resize(slot + 1);
    bp.fat[slot] = fat_bounds(world, slot, world.settings.time_step.duration);
    world.bodies.proxy[slot] = static_cast<std::int32_t>(slot);
}

void remove_proxy(World& world, std::uint32_t slot) { world.bodies.proxy[slot] = -1; }

void update_broadphase(World& world, Real dt) {
    Bodies& b = world.bodies;
    BroadphaseState& bp = *world.broadphase;
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    world.jobs->parallel_for("Bounds", 0, n, 128, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t k = lo; k < hi; ++k) {
            const std::uint32_t i = world.awake[k];
            b.bounds[i] = b.desc[i].shape.bounds(b.transform(i));
            bp.fat[i] = fat_bounds(world, i, dt);
        }
    });
    // New pairs: every awake body against every other live body, in slot order.
    bp.new_pairs.clear();
    for (std::uint32_t i : world.awake) {
        for (std::uint32_t j = 0; j < b.capacity(); ++j) {
            if (j == i || !b.alive[j]) continue;
            if (b.awake_index[j] >= 0 && j < i) continue;  // awake pairs once
            if (b.type[i] != MotionType::Dynamic && b.type[j] != MotionType::Dynamic) continue;
            if (!bp.fat[i].overlaps(bp.fat[j])) continue;
            const std::uint64_t key = (std::uint64_t{std::min(i, j)} << 32) | std::max(i, j);
            if (!world.contact_index.count(key)) bp.new_pairs.push_back(key);
        }
    }
    std::sort(bp.new_pairs.begin(), bp.new_pairs.end());
    bp.new_pairs.erase(std::unique(bp.new_pairs.begin(), bp.new_pairs.end()), bp.new_pairs.end());
    for (std::uint64_t key : bp.new_pairs) create_contact(world, key);

    // Lost pairs: awake contacts whose fat bounds no longer overlap.
    std::vector<std::uint32_t>& lost = world.scratch_lost;
    lost.clear();
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        const Contact& contact = world.contacts[c];
        if (contact.sleeping) continue;
        if (!bp.fat[contact.body_a].overlaps(bp.fat[contact.body_b])) lost.push_back(c);
    }
    remove_contacts(world, lost);
}

}  // namespace spindle
