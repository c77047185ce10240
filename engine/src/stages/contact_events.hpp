// Contact and sensor events between the steps that find them and the game that reads
// them (contact_events.cpp). The physics thread gathers into `pending`; the flip moves
// them under `mutex` into `published`, which read_contact_events hands over.
#pragma once

#include <spindle/engine/events.hpp>

#include <mutex>
#include <span>
#include <vector>

#include "world.hpp"

namespace spindle {

struct ContactEvents {
    // Update thread only.
    std::vector<ContactEvent> pending;  // since the last flip, at most EventSettings::max_queued
    std::uint64_t pending_dropped = 0;
    std::uint32_t reporting = 0;  // live contacts with kContactReports: while 0, no event work at all
    // Per worker: positions of the reporting contacts the narrowphase found changed or
    // pushing (merged and sorted after it, so the order does not depend on the workers).
    std::vector<std::vector<std::uint32_t>> found;
    std::vector<std::uint32_t> hit_candidates;  // positions, ascending, for the check after the solver

    // Shared with readers on any thread; the physics thread holds it only to append at the flip.
    mutable std::mutex mutex;
    std::vector<ContactEvent> published;  // guarded by mutex
    std::uint64_t dropped = 0;            // guarded by mutex

    // Touching points for read_contact_points (EventSettings::publish_contact_points):
    // gathered into `points_pending` by the physics thread, swapped in at the flip.
    std::vector<ContactPointInfo> points_pending;
    bool points_shown = false;             // update thread: `points` holds a publication
    std::vector<ContactPointInfo> points;  // guarded by mutex
    std::size_t points_left_out = 0;       // guarded by mutex
    std::uint64_t points_step = 0;         // guarded by mutex
};

// Whether any point of the contact's manifolds is at zero separation or deeper.
bool contact_touches(const Contact& contact);
// Whether the narrowphase must hand the contact to note_touch_changes: its touch changed,
// or it may push (a hit candidate). Only for reporting contacts.
inline bool contact_event_candidate(const Contact& contact) {
    return contact_touches(contact) != contact.touch_reported ||
           (contact.manifold_count > 0 && (contact.events & kContactSensor) == 0);
}

// create_contacts and remove_contacts (contact_list.cpp): a new pair's flags (Contact::events,
// which ContactEvents::reporting counts; reads the descriptions only, so any number of jobs
// may call it at once), and the End of a touching contact removed in any way (lost,
// filtered, its body destroyed).
std::uint8_t contact_event_flags(const World& world, std::uint32_t a, std::uint32_t b);
void note_contact_removed(World& world, Contact& contact);
// After the narrowphase: Begin and End for the candidates found, in contact order.
void note_touch_changes(World& world);
// After the solver: a Hit for each candidate that pushed faster than EventSettings::hit_speed.
void note_hits(World& world);
// FlipReadBuffers: pending -> published, under the events' lock.
void publish_contact_events(World& world);
// FlipReadBuffers: every touching point of the live contacts, replacing the last ones
// published, when EventSettings::publish_contact_points (else clears them once).
void publish_contact_points(World& world);

}  // namespace spindle
