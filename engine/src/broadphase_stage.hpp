// The broadphase stage's state and the body/contact bookkeeping it owns.
#pragma once

#include <cstdint>
#include <vector>

#include "world.hpp"

namespace spindle {

struct BroadphaseState {
    std::vector<Aabb> fat;                   // per body slot: bounds grown by the margin and the motion
    std::vector<std::uint64_t> new_pairs;    // scratch: keys of pairs found this step
};

void add_proxy(World& world, std::uint32_t slot);
void remove_proxy(World& world, std::uint32_t slot);
// Removes every contact of a body (destroy_body).
void remove_contacts_of(World& world, std::uint32_t slot);
// Creates a contact for a pair key (min slot << 32 | max slot) if there is none.
void create_contact(World& world, std::uint64_t key);
// Removes contacts by their positions in world.contacts (ascending), keeping the order of the rest.
void remove_contacts(World& world, const std::vector<std::uint32_t>& positions);

}  // namespace spindle
