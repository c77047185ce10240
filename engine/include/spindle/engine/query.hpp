// Scene queries: what a ray, a swept shape or a shape at rest meets among a space's
// bodies. Space::cast_ray and the others (space.hpp) run on any thread, at any time,
// against the published step: the poses buffered reads and get_motion_states return.
#pragma once

#include <cstdint>
#include <functional>

#include <spindle/engine/body.hpp>
#include <spindle/engine/math.hpp>

namespace spindle {

// Which bodies a query may report. A body passes when its layer is in layer_mask, it
// does not share a non-zero group with the query, it is not `ignore`, it is not a sensor
// (unless sensors is set: a trigger volume is usually not what a ray should stop at),
// and accept (when set) returns true for it. accept runs on the querying thread, with the query's
// published step held: it must not wait for an update (that update's flip would wait
// for nothing, but a query held for long makes the physics thread copy its structure).
struct QueryFilter {
    std::uint32_t layer_mask = ~std::uint32_t{0};  // bit l: bodies on layer l are met
    std::uint32_t group = 0;                       // non-zero: bodies of this group are skipped
    BodyHandle ignore{};                           // a body to skip (the caster's own)
    bool sensors = false;                          // also meet sensor bodies (BodyDesc::sensor)
    std::function<bool(BodyHandle)> accept;        // optional, after the three tests above
};

// Where a ray or a swept shape first meets a body.
struct QueryHit {
    BodyHandle body;
    Real fraction = 0;            // of the segment or translation, in [0, 1]
    Vec3 point = Vec3::Zero();    // world, on the hit body's surface
    Vec3 normal = Vec3::UnitY();  // world, unit, from the hit body toward the caster
    std::uint32_t part = 0;       // triangle index for a mesh, part index for a compound, else 0
};

}  // namespace spindle
