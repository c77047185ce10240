// Contact bookkeeping: creation from pair keys, and removal that fills the removed places
// with the last contacts (in a fixed order, so the solver's order, and so its result, is
// deterministic).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

#include "collision/collide.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/capacity.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

// New contacts per job: each reads two bodies' descriptions and writes one record.
constexpr std::uint32_t kNewContactGrain = 256;
// Moved contacts per job when their index entries are updated (one lookup each).
constexpr std::uint32_t kMovedContactGrain = 1024;

// A new contact's record, from its bodies' descriptions (reads only: many jobs at once).
void init_contact(const World& world, std::uint64_t key, Contact& contact) {
    const auto a = static_cast<std::uint32_t>(key >> 32);
    const auto b = static_cast<std::uint32_t>(key & 0xffffffffu);
    const Bodies& bodies = world.bodies;
    contact.body_a = a;
    contact.body_b = b;
    // Mixing rules as most engines: geometric mean friction, largest restitution.
    contact.friction = std::sqrt(bodies.traits[a].friction * bodies.traits[b].friction);
    contact.restitution = std::max(bodies.traits[a].restitution, bodies.traits[b].restitution);
    contact.events = contact_event_flags(world, a, b);
}

// Takes the removed positions (ascending) out of an up-to-date awake list and renames the
// moved contacts as remove_contacts moved them: the ascending list a rebuild would give,
// without reading the records. Every position at or past `size` (the new count) was either
// removed or moved; the moves are in ascending order of both ends, so the awake ones among
// them are gathered in order of their new places and merged in.
void drop_from_awake_list(std::vector<std::uint32_t>& awake, const std::vector<std::uint32_t>& removed,
                          const std::vector<ContactMove>& moves, std::uint32_t size,
                          std::vector<std::uint32_t>& moved_awake) {
    moved_awake.clear();
    std::size_t write = 0, r = 0, m = 0;
    for (const std::uint32_t c : awake) {
        if (c >= size) {
            while (m < moves.size() && moves[m].from < c) ++m;
            if (m < moves.size() && moves[m].from == c) moved_awake.push_back(moves[m].to);
            continue;
        }
        while (r < removed.size() && removed[r] < c) ++r;
        if (r < removed.size() && removed[r] == c) continue;
        awake[write++] = c;
    }
    // Merged from the back, so no kept position is overwritten before it is read.
    awake.resize(write + moved_awake.size());
    std::size_t kept = write, from_moved = moved_awake.size(), out = awake.size();
    while (from_moved > 0) {
        if (kept > 0 && awake[kept - 1] > moved_awake[from_moved - 1]) {
            awake[--out] = awake[--kept];
        } else {
            awake[--out] = moved_awake[--from_moved];
        }
    }
}

}  // namespace

void fit_contacts(World& world) {
    if (!far_above_use(world.contacts.capacity(), world.contacts.size())) return;
    fit_capacity(world.contacts);
    fit_capacity(world.contact_keys);
    fit_capacity(world.contact_summaries);
}

void create_contacts(World& world, std::span<const std::uint64_t> keys) {
    if (keys.empty()) return;
    // Positions in list order, one index lookup per key; a key the index holds already is
    // a pair found again (one of its proxies grew). Room is made for the new ones only: a
    // step that finds many pairs again must not grow the arrays only to give them back.
    const std::size_t first = world.contacts.size();
    world.contact_index.reserve(first + keys.size());
    std::vector<std::uint64_t>& made = world.contact_keys;
    reserve_for(made, first + keys.size());  // 8 bytes a key: the pairs found again are not worth a second pass
    for (const std::uint64_t key : keys) {
        if (world.contact_index.insert(key, static_cast<std::uint32_t>(made.size()))) made.push_back(key);
    }
    const auto end = static_cast<std::uint32_t>(made.size());
    if (end == first) return;
    reserve_for(world.contacts, end);
    reserve_for(world.contact_summaries, end);
    map_room(*world.jobs, world.contacts, end);
    world.contacts.resize(end);  // in place, all at once: the record is large
    world.contact_summaries.resize(end);

    // The records read the bodies' descriptions (cold: a first step reads tens of
    // thousands) in parallel; each job writes only its own contacts.
    std::atomic<std::uint32_t> reporting{0};
    world.jobs->parallel_for("NewContacts", static_cast<std::uint32_t>(first), end, kNewContactGrain,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
                                 std::uint32_t reports = 0;
                                 for (std::uint32_t c = lo; c < hi; ++c) {
                                     Contact& contact = world.contacts[c];
                                     init_contact(world, made[c], contact);
                                     reports += contact.events != 0 ? 1u : 0u;
                                     world.contact_summaries[c] = contact_summary(contact);  // a sensor's has no points
                                 }
                                 reporting.fetch_add(reports, std::memory_order_relaxed);
                             });
    world.events->reporting += reporting.load(std::memory_order_relaxed);
    // New contacts are awake, and come after every other: a list that is up to date gets
    // their positions at its end instead of a rebuild that reads every contact's record.
    // Where every contact is new (a first step), the list is all of them, whatever it was.
    std::vector<std::uint32_t>& awake = world.awake_contact_list;
    if (first == 0) {
        awake.clear();
        world.awake_contacts_dirty = false;
    }
    if (!world.awake_contacts_dirty) {
        const std::size_t before = awake.size();
        awake.resize(before + (end - first));
        std::iota(awake.begin() + static_cast<std::ptrdiff_t>(before), awake.end(), static_cast<std::uint32_t>(first));
    }
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
    // The kept contacts past the new end fill the removed places below it, both taken in
    // ascending order (Box3D swaps the last contact into a removed one's place): each
    // record moves at most once and no more move than are removed, where keeping the
    // order moved every record after the first removed one.
    const auto size = static_cast<std::uint32_t>(world.contacts.size() - positions.size());
    const auto holes =
        static_cast<std::size_t>(std::lower_bound(positions.begin(), positions.end(), size) - positions.begin());
    std::vector<ContactMove>& moves = world.scratch_contact_moves;
    moves.clear();
    std::size_t tail_removed = holes;  // the first removed position at or past the new end not yet passed
    std::uint32_t from = size;
    for (std::size_t h = 0; h < holes; ++h, ++from) {
        for (; tail_removed < positions.size() && positions[tail_removed] == from; ++tail_removed) ++from;
        const std::uint32_t to = positions[h];
        world.contacts[to] = std::move(world.contacts[from]);
        world.contact_keys[to] = world.contact_keys[from];
        world.contact_summaries[to] = world.contact_summaries[from];
        moves.push_back({from, to});
    }
    // The index learns the moved contacts' positions: one lookup each, in parallel (each
    // writes only its own key's entry; no key is added or removed meanwhile).
    world.jobs->parallel_for("MovedContacts", 0, static_cast<std::uint32_t>(moves.size()), kMovedContactGrain,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
                                 for (std::uint32_t k = lo; k < hi; ++k) {
                                     *world.contact_index.find(world.contact_keys[moves[k].to]) = moves[k].to;
                                 }
                             });
    world.contacts.resize(size);
    world.contact_keys.resize(size);
    world.contact_summaries.resize(size);
    if (!world.awake_contacts_dirty) {
        drop_from_awake_list(world.awake_contact_list, positions, moves, size, world.scratch_moved_awake);
    }
}

void remove_contacts_of(World& world, std::uint32_t slot) {
    std::vector<std::uint32_t> positions;
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        if (world.contacts[c].body_a == slot || world.contacts[c].body_b == slot) positions.push_back(c);
    }
    remove_contacts(world, positions);
}

}  // namespace spindle
