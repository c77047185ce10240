// Space's contact and sensor events as the game reads them (any thread), and their settings.
#include <spindle/engine/space.hpp>

#include "api/validation.hpp"
#include "stages/contact_events.hpp"

namespace spindle {

std::size_t Space::read_contact_events(std::vector<ContactEvent>& out) {
    ContactEvents& events = *m_world->events;
    const std::lock_guard<std::mutex> lock(events.mutex);
    const std::size_t count = events.published.size();
    if (out.empty()) {
        out.swap(events.published);  // no copy; the queue keeps the caller's old buffer
    } else {
        out.insert(out.end(), events.published.begin(), events.published.end());
    }
    events.published.clear();
    return count;
}

std::uint64_t Space::dropped_contact_events() const {
    const ContactEvents& events = *m_world->events;
    const std::lock_guard<std::mutex> lock(events.mutex);
    return events.dropped;
}

std::uint64_t Space::read_contact_points(std::vector<ContactPointInfo>& out, std::size_t* left_out) const {
    const ContactEvents& events = *m_world->events;
    const std::lock_guard<std::mutex> lock(events.mutex);
    out.assign(events.points.begin(), events.points.end());
    if (left_out) *left_out = events.points_left_out;
    return events.points_step;
}

void Space::set_events(const EventSettings& settings) {
    const AccessGate::Structure access(m_world->gate, "set_events");
    validate(settings);
    m_world->settings.events = settings;
}

}  // namespace spindle
