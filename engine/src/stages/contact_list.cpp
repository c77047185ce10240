// Contact bookkeeping: creation from pair keys, and removal that fills the removed places
// with the last contacts (in a fixed order, so the solver's order, and so its result, is
// deterministic).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <new>
#include <numeric>
#include <span>
#include <utility>

#include "collision/collide.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/capacity.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

// New contacts per job: each reads two bodies' descriptions and writes one record.
constexpr std::uint32_t kNewContactGrain = 256;
// Moved contacts per job: a record moved and its index entry updated (one lookup) each.
constexpr std::uint32_t kMovedContactGrain = 256;
// New pair keys per job when the index claims their slots (one probe each).
constexpr std::uint32_t kClaimGrain = 1024;

// A new contact's record, from its bodies' descriptions (reads only: many jobs at once).
void init_contact(const World& world, std::uint64_t key, Contact& contact) {
    const auto a = static_cast<std::uint32_t>(key >> 32);
    const auto b = static_cast<std::uint32_t>(key & 0xffffffffu);
    const Bodies& bodies = world.bodies;
    contact.body_a = a;
    contact.body_b = b;
    mix_materials(bodies.traits[a], bodies.traits[b], contact);
    contact.events = contact_event_flags(world, a, b);
    const auto meshy = [](const Shape& s) {
        return s.type == ShapeType::TriangleMesh || s.type == ShapeType::Compound;
    };
    contact.meshy = meshy(bodies.traits[a].shape) || meshy(bodies.traits[b].shape);
}

// Takes the removed positions (ascending) out of an up-to-date awake list and renames the
// moved contacts as remove_contacts moved them: the ascending list a rebuild would give,
// without reading the records. Every position at or past `size` (the new count) was either
// removed or moved; the moves are in ascending order of both ends, so the awake ones among
// them are gathered in order of their new places and merged in.
void drop_from_awake_list(std::vector<std::uint32_t>& awake, std::span<const std::uint32_t> removed,
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
    // Positions in list order; a key the index holds already is a pair found again (one of
    // its proxies grew). The index claims the keys' slots in jobs, then each range places
    // its new keys from its first position on, so the order is the keys' order on any
    // worker count. Room is made for the new ones only: a step that finds many pairs again
    // must not grow the arrays only to give them back.
    const std::size_t first = world.contacts.size();
    ContactIndex& index = world.contact_index;
    index.reserve(first + keys.size(), world.jobs);
    BroadphaseState& bp = *world.broadphase;
    const auto n = static_cast<std::uint32_t>(keys.size());
    RawRoomVector<std::uint32_t>& claimed = bp.claimed_slots;  // raw room: every key's claim is written below
    std::vector<std::uint32_t>& offsets = bp.range_counts;
    claimed.resize(n);
    offsets.assign((n + kClaimGrain - 1) / kClaimGrain, 0);
    world.jobs->parallel_for("ClaimKeys", 0, n, kClaimGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        std::uint32_t count = 0;
        for (std::uint32_t k = lo; k < hi; ++k) {
            claimed[k] = index.claim(keys[k]);
            count += claimed[k] != ContactIndex::kNotClaimed ? 1u : 0u;
        }
        offsets[lo / kClaimGrain] = count;
    });
    std::uint32_t made_count = 0;
    for (std::uint32_t& offset : offsets) made_count += std::exchange(offset, made_count);
    if (made_count == 0) return;
    index.add_claimed(made_count);
    RawRoomVector<std::uint64_t>& made = world.contact_keys;
    reserve_for(made, first + keys.size());  // 8 bytes a key: the pairs found again are not worth a second pass
    made.resize(first + made_count);         // raw room: each new key is written by PlaceKeys
    world.jobs->parallel_for("PlaceKeys", 0, n, kClaimGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        auto position = static_cast<std::uint32_t>(first + offsets[lo / kClaimGrain]);
        for (std::uint32_t k = lo; k < hi; ++k) {
            if (claimed[k] == ContactIndex::kNotClaimed) continue;
            made[position] = keys[k];
            index.set_position_at(claimed[k], position++);
        }
    });
    const auto end = static_cast<std::uint32_t>(made.size());
    reserve_for(world.contacts, end);
    reserve_for(world.contact_summaries, end);
    map_room(*world.jobs, world.contacts, end);
    world.contacts.resize(end);           // in place, all at once, constructed by the jobs below: the record is large
    world.contact_summaries.resize(end);  // raw room, as the records: written by the jobs below

    // The records are constructed and filled from the bodies' descriptions (cold: a first
    // step reads tens of thousands) in parallel; each job writes only its own contacts.
    // Default-initialized, not value-initialized (`Contact()`): every field has its
    // initializer, and value-initialization would first zero the whole record, then write
    // the initialized fields over it again.
    std::atomic<std::uint32_t> reporting{0};
    world.jobs->parallel_for("NewContacts", static_cast<std::uint32_t>(first), end, kNewContactGrain,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
                                 std::uint32_t reports = 0;
                                 for (std::uint32_t c = lo; c < hi; ++c) {
                                     Contact& contact = *::new (&world.contacts[c]) Contact;
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

void remove_contacts(World& world, std::span<const std::uint32_t> positions) {
    if (positions.empty()) return;
    // Only a reporting contact has a touch to end: while none reports, no record is read.
    if (world.events->reporting != 0) {
        for (std::uint32_t p : positions) note_contact_removed(world, world.contacts[p]);
    }
    world.contact_index.erase_at(*world.jobs, positions, world.contact_keys);
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
        moves.push_back({from, positions[h]});
    }
    // The records move in jobs (no two moves share a place), each telling the index its
    // key's new position (no key is added or removed meanwhile). The removed records past
    // the new end drop their extras there too, so the resize below only reads them.
    const auto moved = static_cast<std::uint32_t>(moves.size());
    const auto dropped = static_cast<std::uint32_t>(positions.size() - holes);
    world.jobs->parallel_for("MovedContacts", 0, moved + dropped, kMovedContactGrain,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
                                 for (std::uint32_t k = lo; k < hi; ++k) {
                                     if (k >= moved) {
                                         world.contacts[positions[holes + (k - moved)]].extra.reset();
                                         continue;
                                     }
                                     const auto [source, to] = moves[k];
                                     world.contacts[to] = std::move(world.contacts[source]);
                                     world.contact_keys[to] = world.contact_keys[source];
                                     world.contact_summaries[to] = world.contact_summaries[source];
                                     *world.contact_index.find(world.contact_keys[to]) = to;
                                 }
                             });
    world.contacts.resize(size);
    world.contact_keys.resize(size);
    world.contact_summaries.resize(size);
    if (world.awake_contacts_dirty) return;
    std::vector<std::uint32_t>& awake = world.awake_contact_list;
    if (awake.size() == world.contacts.size() + positions.size()) {
        // Every contact was awake, so the list was 0, 1, 2, ...: so is every one kept.
        awake.resize(size);
        return;
    }
    drop_from_awake_list(awake, positions, moves, size, world.scratch_moved_awake);
}

void remove_contacts_of(World& world, std::uint32_t slot) {
    std::vector<std::uint32_t> positions;
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        if (world.contacts[c].body_a == slot || world.contacts[c].body_b == slot) positions.push_back(c);
    }
    remove_contacts(world, positions);
}

}  // namespace spindle
