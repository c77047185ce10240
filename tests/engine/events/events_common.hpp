// What the event suites share: a ground box whose top is y = 0, balls, and readers
// that count a space's events.
#pragma once

#include <spindle/engine/space.hpp>

#include <algorithm>
#include <vector>

#include "space_calls.hpp"
#include "static_bodies.hpp"

namespace spindle::test {

inline BodyHandle add_ground(Space& space, bool contact_events = false) {
    BodyDesc g = static_box(Vec3(10, 0.5, 10), Vec3(0, -0.5, 0));
    g.contact_events = contact_events;
    return space.create_body(g);
}

// A 0.5 m ball whose bottom is `drop` above y = 0 (at x, z).
inline BodyDesc ball(Real drop, bool contact_events = true, Real x = 0, Real z = 0) {
    BodyDesc d;
    d.shape = Shape::sphere(0.5);
    d.position = Vec3(x, 0.5 + drop, z);
    d.contact_events = contact_events;
    return d;
}

inline std::vector<ContactEvent> read_all(Space& space) {
    std::vector<ContactEvent> events;
    space.read_contact_events(events);
    return events;
}

inline std::size_t count(const std::vector<ContactEvent>& events, ContactEventKind kind) {
    return static_cast<std::size_t>(
        std::count_if(events.begin(), events.end(), [kind](const ContactEvent& e) { return e.kind == kind; }));
}

// Everything an event says, for comparing sequences bit for bit.
inline bool same_event(const ContactEvent& x, const ContactEvent& y) {
    return x.kind == y.kind && x.body_a == y.body_a && x.body_b == y.body_b && x.step == y.step &&
           x.sensor == y.sensor && x.point == y.point && x.normal == y.normal && x.speed == y.speed;
}

inline bool same_events(const std::vector<ContactEvent>& x, const std::vector<ContactEvent>& y) {
    return x.size() == y.size() && std::equal(x.begin(), x.end(), y.begin(), same_event);
}

}  // namespace spindle::test
