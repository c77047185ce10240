// Contact and sensor events as the game reads them (Space::read_contact_events): what
// happened between two bodies, and in which step.
#pragma once

#include <cstdint>

#include <spindle/engine/body.hpp>
#include <spindle/engine/math.hpp>

namespace spindle {

enum class ContactEventKind : std::uint8_t {
    Begin,  // the bodies started touching (a point at zero separation or deeper)
    End,    // they stopped touching, or their contact was removed (destroyed, filtered, parted)
    Hit,    // they pushed on each other approaching faster than EventSettings::hit_speed
};

// A pair's event. body_a is the body with the lower slot (the same order every run).
// Reported for a pair when either body has BodyDesc::contact_events or is a sensor.
struct ContactEvent {
    ContactEventKind kind = ContactEventKind::Begin;
    BodyHandle body_a, body_b;
    // The number of the step it happened in, counting from 1 (Space::counters().steps after
    // that step); a contact removed between steps (destroy_body, a filter change) ends
    // in the next step's number.
    std::uint64_t step = 0;
    bool sensor = false;  // one of the bodies is a sensor (an overlap, not a push)
    // Hits only: where the fastest point touched (world), the contact normal (from body_a
    // towards body_b) and the speed it approached at (m/s, > 0).
    Vec3 point = Vec3::Zero();
    Vec3 normal = Vec3::Zero();
    Real speed = 0;
};

// A point where two bodies touch, as the newest published step left it
// (Space::read_contact_points; for drawing and debugging, off unless
// EventSettings::publish_contact_points). body_a is the body with the lower slot.
struct ContactPointInfo {
    BodyHandle body_a, body_b;
    Vec3 point = Vec3::Zero();   // world, midway between the surfaces at the step's poses
    Vec3 normal = Vec3::Zero();  // from body_a towards body_b
    Real separation = 0;         // along the normal when last collided; < 0: overlapping
    Real normal_impulse = 0;     // N s, what the point pushed with in the step's last substep
};

}  // namespace spindle
