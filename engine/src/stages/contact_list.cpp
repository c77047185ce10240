// Contact bookkeeping: creation from pair keys, removal that keeps the order of the
// remaining contacts (so the solver's order, and so its result, is deterministic).
#include <algorithm>

#include "collision/collide.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/capacity.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"

namespace spindle {

void reserve_contacts(World& world, const std::vector<Pair>& pairs) {
    std::size_t needed = world.contacts.size() + pairs.size();
    // A proxy that moved finds its pairs again, contacts already: room for all of them
    // would hold the arrays at the pairs' high-water mark, not the contacts'. Counted only
    // when they could not all fit, so a step that makes few contacts looks up none.
    if (needed > world.contacts.capacity()) {
        needed = world.contacts.size();
        for (const Pair& pair : pairs) {
            const auto i = static_cast<std::uint32_t>(pair.user_a), j = static_cast<std::uint32_t>(pair.user_b);
            if (!world.contact_index.find((std::uint64_t{std::min(i, j)} << 32) | std::max(i, j))) ++needed;
        }
    }
    reserve_for(world.contacts, needed);
    reserve_for(world.contact_keys, needed);
    reserve_for(world.contact_summaries, needed);
    world.contact_index.reserve(needed);
}

void fit_contacts(World& world) {
    if (!far_above_use(world.contacts.capacity(), world.contacts.size())) return;
    fit_capacity(world.contacts);
    fit_capacity(world.contact_keys);
    fit_capacity(world.contact_summaries);
}

void create_contact(World& world, std::uint64_t key) {
    // One lookup: a first step makes tens of thousands of contacts.
    if (!world.contact_index.insert(key, static_cast<std::uint32_t>(world.contacts.size()))) return;
    const auto a = static_cast<std::uint32_t>(key >> 32);
    const auto b = static_cast<std::uint32_t>(key & 0xffffffffu);
    const Bodies& bodies = world.bodies;
    Contact& contact = world.contacts.emplace_back();  // in place: the record is large
    contact.body_a = a;
    contact.body_b = b;
    // Mixing rules as most engines: geometric mean friction, largest restitution.
    contact.friction = std::sqrt(bodies.desc[a].friction * bodies.desc[b].friction);
    contact.restitution = std::max(bodies.desc[a].restitution, bodies.desc[b].restitution);
    note_contact_created(world, contact);  // before the summary: a sensor's has no points
    world.contact_summaries.push_back(contact_summary(contact));
    world.contact_keys.push_back(key);
    world.awake_contacts_dirty = true;
}

const std::vector<std::uint32_t>& awake_contacts(World& world) {
    if (world.awake_contacts_dirty) {
        world.awake_contact_list.clear();
        for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
            if (!world.contacts[c].sleeping) world.awake_contact_list.push_back(c);
        }
        world.awake_contacts_dirty = false;
    }
    return world.awake_contact_list;
}

void remove_contacts(World& world, const std::vector<std::uint32_t>& positions) {
    if (positions.empty()) return;
    for (std::uint32_t p : positions) {
        note_contact_removed(world, world.contacts[p]);  // a touching one ends its touch
        world.contact_index.erase(world.contact_keys[p]);
    }
    // The contacts before the first removed one keep their places (and their index entries).
    std::size_t next = 0, write = positions[0];
    for (std::size_t read = positions[0]; read < world.contacts.size(); ++read) {
        if (next < positions.size() && positions[next] == read) {
            ++next;
            continue;
        }
        world.contacts[write] = std::move(world.contacts[read]);
        world.contact_keys[write] = world.contact_keys[read];
        world.contact_summaries[write] = world.contact_summaries[read];
        *world.contact_index.find(world.contact_keys[write]) = static_cast<std::uint32_t>(write);
        ++write;
    }
    world.contacts.resize(write);
    world.contact_keys.resize(write);
    world.contact_summaries.resize(write);
    world.awake_contacts_dirty = true;
}

void remove_contacts_of(World& world, std::uint32_t slot) {
    std::vector<std::uint32_t> positions;
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        if (world.contacts[c].body_a == slot || world.contacts[c].body_b == slot) positions.push_back(c);
    }
    remove_contacts(world, positions);
}

}  // namespace spindle
