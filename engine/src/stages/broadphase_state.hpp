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
    std::vector<std::uint32_t> refit_slots;  // the slots marked in refit, to clear just them
    std::vector<std::uint8_t> moving;        // scratch, per awake body: its proxy must move this step
};

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
// Creates a contact for a pair key (min slot << 32 | max slot) if there is none.
void create_contact(World& world, std::uint64_t key);
// Makes room at once for the contacts the pairs would make (a first step finds tens of
// thousands of pairs: growing by push_back would move every contact again and again).
void reserve_contacts(World& world, const std::vector<Pair>& pairs);
// Gives back the contact arrays' room when it is far above their use (a pile came apart,
// or the pairs reserved for were mostly not made into contacts).
void fit_contacts(World& world);
// Removes contacts by their positions in world.contacts (ascending), keeping the order of the rest.
void remove_contacts(World& world, const std::vector<std::uint32_t>& positions);

}  // namespace spindle
