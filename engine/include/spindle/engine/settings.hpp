// Settings structs, with their defaults written in the struct.
#pragma once

#include <cstdint>

#include <spindle/engine/math.hpp>

namespace spindle {

// Internal time stepping (the seed, section 1.A; design.md section 3).
struct TimeStepSettings {
    Real duration = 1.0 / 60.0;    // seconds per step
    int max_steps_per_frame = 10;  // cap per update(); leftover beyond the cap's worth is dropped
    int min_steps_per_frame = 0;   // steps taken by every update(dt) even without elapsed time
    bool use_internal_time_stepping = false;
};

struct SolverSettings {
    int substeps = 4;
    int iterations = 1;        // solve iterations per substep
    int relax_iterations = 1;  // relax iterations per substep
    // Contact stiffness in hertz; against a static body twice that, with half the damping
    // ratio (Box3D's), so loads press less into the ground. 0 picks Box3D's default, an
    // eighth of the substep rate (30 Hz at 4 substeps of 1/60 s); any value is capped at a
    // quarter of it (60 Hz), the stiffest stable. Soft contacts compress in proportion to
    // the load they carry (a 100-row pyramid of cubes stands 0.7 m lower at 30 Hz);
    // stiffer ones settle more slowly with one iteration: at 60 Hz that pyramid stands
    // but never comes to rest (docs/accuracy.md). More substeps buy stiffness.
    Real contact_hertz = 0;
    Real damping_ratio = 10;  // contact damping ratio
    // Joint stiffness in hertz, capped like contacts at a quarter of the substep rate; 0
    // picks that cap, the stiffest stable (60 Hz at 4 substeps of 1/60 s). Soft joints
    // are springs for their effective mass: a load F stretches one by about
    // F / (m_eff (2 pi hz)^2), so a heavy body on light links wants more substeps.
    Real joint_hertz = 60;
    Real joint_damping_ratio = 2;
    Real push_out_speed = 3;  // m/s: most speed used to push overlapping bodies apart
    // m: overlap up to this depth, or as deep as a point's load compresses its soft
    // contact (a heavy body on a light one: several cm), is corrected by the soft contact
    // itself, which carries the load; deeper overlap is pushed out by a split impulse
    // that moves bodies without giving them speed, at most push_out_speed per body, so a
    // chain of overlapping bodies separates without launching.
    Real recovery_depth = 0.03;
    Real restitution_threshold = 1;    // m/s: slower approaches do not bounce
    Real speculative_distance = 0.04;  // m: contacts are made this far before touching
    Real linear_slop = 0.005;          // m: allowed penetration
    // Speed limits (Box2D's maximumLinearSpeed), applied wherever a velocity is integrated
    // or written, so that no finite input, however large, makes a body's state infinite.
    // Far above anything a scene means to do, so they change no result: 400 m/s is
    // Box2D's default (4 m per step at 100 Hz) and twice the fastest body of the built-in
    // scenes and tests; 60 pi rad/s (30 turns a second) is a quarter turn per substep at
    // the default 4 substeps of 1/60 s, where integrating rotations stops being accurate
    // (Box2D's B2_MAX_ROTATION per substep).
    Real max_linear_speed = 400;        // m/s
    Real max_angular_speed = 60 * kPi;  // rad/s
};

struct SleepSettings {
    bool enabled = true;
    Real time_to_sleep = 0.5;       // s a whole island must rest
    Real linear_threshold = 0.05;   // m/s
    Real angular_threshold = 0.05;  // rad/s
};

// Contact and sensor events (events.hpp, Space::read_contact_events).
struct EventSettings {
    Real hit_speed = 1;  // m/s: a reporting pair's hit needs an approach faster than this (Box2D's default)
    // Events kept for the game to read. Events beyond it are dropped, newest first, and
    // counted (Space::dropped_contact_events): the queue's memory is bounded.
    std::uint32_t max_queued = 1u << 16;
    // Publish every touching point of every contact at each flip, for
    // Space::read_contact_points (debug drawing). Off: no work. On: one pass over the
    // contacts per update on the physics thread, and a copy under the events' lock.
    bool publish_contact_points = false;
    // The most points one publication keeps (the rest are counted in
    // Space::read_contact_points's `left_out`): a huge scene's debug copy stays bounded.
    std::uint32_t max_contact_points = 1u << 16;
};

// What the game expects its level to hold (Box3D's b3Capacity). A hint: nothing is
// limited by it.
struct CapacitySettings {
    // The contacts the level's first step will make (Box3D's contactCount). The huge pages
    // that step writes are mapped as the level's dynamic bodies are made, for this many
    // contacts, and given back after it when it did not take them. 0: the space counts the
    // pairs of overlapping boxes its new bodies make as they are made (a tree query each).
    // At most kMaxContactCount (a contact's place is 32 bits).
    std::int64_t contact_count = 0;
    static constexpr std::int64_t kMaxContactCount = (std::int64_t{1} << 32) - 1;
};

struct SpaceSettings {
    Vec3 gravity{0, -9.81, 0};
    TimeStepSettings time_step;
    SolverSettings solver;
    SleepSettings sleep;
    EventSettings events;
    CapacitySettings capacity;
};

}  // namespace spindle
