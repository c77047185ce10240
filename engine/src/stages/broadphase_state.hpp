// The broadphase stage's state and the body/contact bookkeeping it owns.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "spatial/proxy_trees.hpp"
#include "world.hpp"

namespace spindle {

struct BroadphaseState {
    ProxyTrees tree;             // moving and static AABB trees; proxy user value = body slot
    std::vector<ProxyId> proxy;  // per body slot
    std::vector<Pair> pairs;     // scratch: pairs found this step (kept: no allocation per step)
    // Per body slot: 1 when its fat box changed since the last broadphase stage. A contact
    // can only lose its overlap when one of its bodies' fat boxes changed.
    std::vector<std::uint8_t> refit;
    std::vector<std::uint32_t> refit_slots;   // the slots marked in refit, to clear just them
    std::vector<std::uint8_t> moving;         // scratch, per awake body: its proxy must move this step
    std::vector<std::uint64_t> new_keys;      // scratch: keys of the new pairs that may make contacts
    std::vector<std::uint32_t> range_counts;  // scratch: values kept per job range (broadphase.cpp)
    // Per body slot: a compound's parts' world boxes, made with its bounds by this step's
    // Bounds jobs, and the step they were made in plus one (0: never). The narrowphase
    // reads them in that step only: a body asleep or moved since has others.
    std::vector<std::vector<Aabb>> part_boxes;
    std::vector<std::uint64_t> part_boxes_step;
};

// Body i's part boxes when the broadphase made them this step, else empty.
inline std::span<const Aabb> step_part_boxes(const BroadphaseState& bp, std::uint32_t i, std::uint64_t step) {
    if (i >= bp.part_boxes_step.size() || bp.part_boxes_step[i] != step + 1) return {};
    return bp.part_boxes[i];
}

// Whether bodies on layers a and b collide, per the space's layer table.
inline bool layers_collide(const World& world, std::uint32_t a, std::uint32_t b) {
    return ((world.layer_masks[a] >> b) & 1u) != 0;
}
// Whether the collision filter keeps two bodies apart: their layers do not collide, or
// they share a non-zero group. Reads the hot filter arrays only.
inline bool filter_blocks_pair(const World& world, std::uint32_t i, std::uint32_t j) {
    const Bodies& b = world.bodies;
    if (b.group[i] != 0 && b.group[i] == b.group[j]) return true;
    return !layers_collide(world, b.layer[i], b.layer[j]);
}
// These bodies' filters changed (their layers and groups are already set; slots
// ascending): their contacts the filters now reject are removed, waking both bodies, and
// their proxies marked so that the next broadphase reports their overlaps again (pairs
// the filters now allow become contacts). One pass over the contacts for all of them.
void refilter_bodies(World& world, std::span<const std::uint32_t> slots);
// The layer table changed: the same for every body. Wakes every moving body (a newly
// allowed pair of two sleepers must not start as an awake contact between sleepers).
void refilter_all(World& world);

void add_proxy(World& world, std::uint32_t slot);
void remove_proxy(World& world, std::uint32_t slot);
// Re-fits a proxy to the body's current bounds (a teleport, or a static body moved).
void refresh_proxy(World& world, std::uint32_t slot);
// Removes every contact of a body (destroy_body).
void remove_contacts_of(World& world, std::uint32_t slot);
// Creates a contact for each pair key (min slot << 32 | max slot) that has none, at the
// end of World::contacts in the keys' order, the records filled in parallel jobs. Room is
// made once for all of them: a first step makes tens of thousands, and growing by
// push_back would move every contact again and again.
void create_contacts(World& world, std::span<const std::uint64_t> keys);
// Gives back the contact arrays' room when it is far above their use (a pile came apart).
void fit_contacts(World& world);
// Removes contacts by their positions in world.contacts (ascending); the kept contacts
// past the new end take the removed places below it, in order (the rest stay in place).
void remove_contacts(World& world, const std::vector<std::uint32_t>& positions);

}  // namespace spindle
