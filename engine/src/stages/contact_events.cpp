// Contact and sensor events: Begin and End when a reporting pair's touch changes (after
// the narrowphase, and when a touching contact is removed), Hit after the solver, each
// gathered in contact order (so the sequence does not depend on the worker count), and
// published at the flip. Only reporting contacts are ever looked at: a scene where no
// body asked does no event work.
#include "stages/contact_events.hpp"

#include <algorithm>

#include "stages/stages.hpp"

namespace spindle {
namespace {

ContactEvent make_event(const World& world, ContactEventKind kind, const Contact& contact) {
    const Bodies& b = world.bodies;
    ContactEvent event;
    event.kind = kind;
    event.body_a = BodyHandle{contact.body_a, b.generation[contact.body_a]};
    event.body_b = BodyHandle{contact.body_b, b.generation[contact.body_b]};
    // world.steps counts the steps finished: this one (or, between steps, the next) is one more.
    event.step = world.steps + 1;
    event.sensor = (contact.events & kContactSensor) != 0;
    return event;
}

// Kept while the pending events are below the cap; beyond, counted as dropped (the flip
// adds them to the total the game reads).
void emit(World& world, const ContactEvent& event) {
    ContactEvents& events = *world.events;
    if (events.pending.size() >= world.settings.events.max_queued) {
        events.pending_dropped += 1;
        return;
    }
    events.pending.push_back(event);
}

void note_touch(World& world, Contact& contact, bool touches) {
    if (touches == contact.touch_reported) return;
    contact.touch_reported = touches;
    emit(world, make_event(world, touches ? ContactEventKind::Begin : ContactEventKind::End, contact));
}

}  // namespace

bool contact_touches(const Contact& contact) {
    for (int m = 0; m < contact.manifold_count; ++m) {
        const ContactManifold& manifold = contact.manifold_at(m);
        for (int j = 0; j < manifold.point_count; ++j) {
            if (manifold.points[j].separation <= 0) return true;
        }
    }
    return false;
}

std::uint8_t contact_event_flags(const World& world, std::uint32_t a, std::uint32_t b) {
    const BodyTraits& da = world.bodies.traits[a];
    const BodyTraits& db = world.bodies.traits[b];
    const bool sensor = da.sensor || db.sensor;
    return static_cast<std::uint8_t>((da.contact_events || db.contact_events || sensor ? kContactReports : 0) |
                                     (sensor ? kContactSensor : 0));
}

void note_contact_removed(World& world, Contact& contact) {
    if (contact.events == 0) return;
    world.events->reporting -= 1;
    note_touch(world, contact, false);
}

void note_touch_changes(World& world) {
    ContactEvents& events = *world.events;
    std::vector<std::uint32_t>& candidates = events.hit_candidates;
    candidates.clear();
    for (std::vector<std::uint32_t>& found : events.found) {
        candidates.insert(candidates.end(), found.begin(), found.end());
        found.clear();
    }
    if (candidates.empty()) return;
    std::sort(candidates.begin(), candidates.end());
    // Each contact's Begin or End in contact order; those that may push stay candidates.
    std::erase_if(candidates, [&](std::uint32_t c) {
        Contact& contact = world.contacts[c];
        note_touch(world, contact, contact_touches(contact));
        return contact.manifold_count == 0 || (contact.events & kContactSensor) != 0;
    });
}

// A Hit is the first step of a push (a resting contact pushes every step and never hits
// again; one that bounces off and comes back hits anew), faster than the threshold. It
// may come a step before the Begin: a speculative contact stops a body before it touches.
void note_hits(World& world) {
    ContactEvents& events = *world.events;
    const Real threshold = world.settings.events.hit_speed;
    const Bodies& b = world.bodies;
    for (std::uint32_t c : events.hit_candidates) {
        Contact& contact = world.contacts[c];
        if (contact.sleeping) continue;  // put to sleep by the Islands stage: not solved this step
        world.counters.contact_event_checks += 1;
        // The point that approached fastest among those that pushed this step.
        const ContactManifold* hit_manifold = nullptr;
        const ContactPoint* hit_point = nullptr;
        Real fastest = threshold;
        const bool pushed_before = contact.pushed;
        contact.pushed = false;
        for (int m = 0; m < contact.manifold_count; ++m) {
            const ContactManifold& manifold = contact.manifold_at(m);
            if (manifold.pushed_point < 0) continue;
            contact.pushed = true;
            if (!pushed_before && manifold.pushed_speed > fastest) {
                fastest = manifold.pushed_speed;
                hit_manifold = &manifold;
                hit_point = &manifold.points[manifold.pushed_point];
            }
        }
        if (!hit_point) continue;
        ContactEvent event = make_event(world, ContactEventKind::Hit, contact);
        // Midway between the surfaces as the solver left them: each anchor moved with its body.
        event.point =
            (b.x[contact.body_a] + contact.anchor_a(*hit_point) + b.x[contact.body_b] + contact.anchor_b(*hit_point)) /
            2;
        event.normal = hit_manifold->normal;
        event.speed = fastest;
        emit(world, event);
    }
    events.hit_candidates.clear();
}

void publish_contact_points(World& world) {
    ContactEvents& events = *world.events;
    const EventSettings& settings = world.settings.events;
    if (!settings.publish_contact_points && !events.points_shown) return;  // off: no work, no lock
    events.points_shown = settings.publish_contact_points;
    std::vector<ContactPointInfo>& gathered = events.points_pending;
    gathered.clear();
    std::size_t left_out = 0;
    if (settings.publish_contact_points) {
        const Bodies& b = world.bodies;
        for (const Contact& contact : world.contacts) {
            if ((contact.events & kContactSensor) != 0) continue;
            const BodyHandle body_a{contact.body_a, b.generation[contact.body_a]};
            const BodyHandle body_b{contact.body_b, b.generation[contact.body_b]};
            for (int m = 0; m < contact.manifold_count; ++m) {
                const ContactManifold& manifold = contact.manifold_at(m);
                for (int j = 0; j < manifold.point_count; ++j) {
                    const ContactPoint& p = manifold.points[j];
                    // Speculative points that pushed nothing are not touching.
                    if (p.separation > 0 && p.normal_impulse <= 0) continue;
                    if (gathered.size() >= settings.max_contact_points) {
                        left_out += 1;
                        continue;
                    }
                    ContactPointInfo& info = gathered.emplace_back();
                    info.body_a = body_a;
                    info.body_b = body_b;
                    info.point =
                        (b.x[contact.body_a] + contact.anchor_a(p) + b.x[contact.body_b] + contact.anchor_b(p)) / 2;
                    info.normal = manifold.normal;
                    info.separation = p.separation;
                    info.normal_impulse = p.normal_impulse;
                }
            }
        }
        world.counters.contact_points_published += gathered.size();
    }
    const std::lock_guard<std::mutex> lock(events.mutex);
    events.points.swap(gathered);  // the old ones come back as the next gathering's buffer
    events.points_left_out = left_out;
    events.points_step = settings.publish_contact_points ? world.steps : 0;
}

void publish_contact_events(World& world) {
    ContactEvents& events = *world.events;
    if (events.pending.empty() && events.pending_dropped == 0) return;
    const std::size_t cap = world.settings.events.max_queued;
    {
        const std::lock_guard<std::mutex> lock(events.mutex);
        const std::size_t room = events.published.size() < cap ? cap - events.published.size() : 0;
        const std::size_t kept = std::min(room, events.pending.size());
        events.dropped += events.pending_dropped + (events.pending.size() - kept);
        if (events.published.empty() && kept == events.pending.size()) {
            events.published.swap(events.pending);  // the reader's last buffer comes back for reuse
        } else {
            events.published.insert(events.published.end(), events.pending.begin(),
                                    events.pending.begin() + static_cast<std::ptrdiff_t>(kept));
        }
    }
    events.pending.clear();
    events.pending_dropped = 0;
}

}  // namespace spindle
