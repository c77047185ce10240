// What an update did, and work counters that prove effects are paid for only when used.
#pragma once

#include <array>
#include <cstdint>

namespace spindle {

// The timed stages of Space::update, in the order they run (stages/update.cpp). Velocity
// and position integration run inside Solver, once per substep.
enum class Stage : std::uint8_t {
    ApplyWrites,
    Broadphase,
    Narrowphase,
    Islands,
    Solver,
    Continuous,  // fast bodies' start poses before the solver, swept tests after it
    Record,
    FlipReadBuffers,
    Count
};
const char* to_string(Stage stage) noexcept;

struct UpdateStats {
    int steps = 0;               // steps taken by this update
    double dropped_seconds = 0;  // time beyond the cap's worth, thrown away
    int writes_applied = 0;      // buffered writes (calls) that reached the live state
    int writes_rejected = 0;     // buffered writes to bodies destroyed since, or that could not apply (space.hpp)
    int bodies_written = 0;      // bodies ApplyWrites changed: its cost, however many writes each got
    std::array<double, static_cast<int>(Stage::Count)> stage_seconds{};  // summed over the steps
    double flip_lock_seconds = 0;  // how long FlipReadBuffers held the motion-state lock
    std::uint32_t awake_bodies = 0;
    std::uint32_t contacts = 0;  // touching manifolds after the last step
};

// Totals since the space was created. Each counts the work of one effect, so a test
// can show an effect costs nothing where a scene does not use it.
struct WorkCounters {
    std::uint64_t steps = 0;
    std::uint64_t bodies_integrated = 0;   // body-steps of velocity integration
    std::uint64_t gravity_applied = 0;     // body-substeps with gravity
    std::uint64_t damping_applied = 0;     // body-substeps with damping
    std::uint64_t gyroscopic_applied = 0;  // body-substeps with gyroscopic torque
    std::uint64_t contacts_updated = 0;    // contact-steps through the narrowphase
    std::uint64_t manifolds_reused = 0;    // of those, moved with the bodies instead of recomputed
    // A compound against a triangle mesh, in the contact-steps recomputed: its part-steps
    // collided with the mesh, and those whose part had moved so little that its manifolds
    // were moved with it instead (as a recycled contact's).
    std::uint64_t mesh_parts_collided = 0;
    std::uint64_t mesh_parts_recycled = 0;
    // Of those, pairs without points whose bounds were too far apart for any: no collision
    // test, and their contact records were not read.
    std::uint64_t contacts_out_of_reach = 0;
    // Pairs the broadphase reported and the collision filter dropped (layers or group): no
    // contact, no narrowphase work. A pair is reported again when one of its fat boxes grows.
    std::uint64_t pairs_filtered = 0;
    // The solver's counts are taken where the rows run. Contacts are solved four
    // manifolds at a time, so a point without friction or restitution is counted when
    // one solved with it has them (its lane ran too).
    std::uint64_t contact_points_solved = 0;  // point-iterations of the normal rows (solve and relax)
    std::uint64_t restitution_applied = 0;    // points checked for a bounce by the restitution pass
    std::uint64_t friction_applied = 0;       // manifold-iterations of the (central) friction rows
    std::uint64_t rolling_applied = 0;        // manifold-iterations of the rolling resistance rows
    std::uint64_t joints_solved = 0;          // joint-iterations (solve and relax)
    std::uint64_t constraint_colorings = 0;   // steps that coloured their constraints (the rest reused the last step's)
    std::uint64_t swept_tests = 0;            // continuous-collision sweeps
    std::uint64_t interpolated_publishes = 0;  // bodies published with a previous pose to blend
    std::uint64_t awake_publishes = 0;         // awake bodies' entries refilled by FlipReadBuffers
    // Entries refilled by FlipReadBuffers for changes outside a step (writes, sleep, waking,
    // set_internal_motion_state), each at two flips (both buffers). Creation and destruction
    // publish to both buffers at once and count here only while a query held the scene.
    std::uint64_t changed_publishes = 0;
    // Query scenes the physics thread copied because a query still held the one it was
    // about to update (query/query_scene.hpp): a query never holds up a step.
    std::uint64_t query_scene_copies = 0;
    // Bodies created or destroyed while a query walked the published scene: queries meet
    // (or stop meeting) them from the next update instead of at once (buffering.cpp).
    std::uint64_t query_publishes_deferred = 0;
    // Contact-steps checked for events (touch changes after the narrowphase, hits after
    // the solver): only pairs with a body that asked for events or is a sensor.
    std::uint64_t contact_event_checks = 0;
    // Points copied for Space::read_contact_points (EventSettings::publish_contact_points).
    std::uint64_t contact_points_published = 0;
};

}  // namespace spindle
