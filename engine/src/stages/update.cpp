// Space::update, the stage list of design.md section 2: ApplyWrites, k steps (Broadphase,
// Narrowphase, Islands, Solver, Continuous, Record), FlipReadBuffers. Each stage runs
// under its trace name and its time is added to the update's stats.
#include <spindle/engine/space.hpp>
#include <spindle/platform/assert.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

#include "api/describe.hpp"
#include "memory/page_stock.hpp"
#include "stages/body_changes.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"

namespace spindle {

const char* to_string(Stage stage) noexcept {
    switch (stage) {
        case Stage::ApplyWrites: return "ApplyWrites";
        case Stage::Broadphase: return "Broadphase";
        case Stage::Narrowphase: return "Narrowphase";
        case Stage::Islands: return "Islands";
        case Stage::Solver: return "Solver";
        case Stage::Continuous: return "Continuous";
        case Stage::Record: return "Record";
        case Stage::FlipReadBuffers: return "FlipReadBuffers";
        case Stage::Count: break;
    }
    return "?";
}

void check_state(const World& world, Stage stage) {
    const Bodies& b = world.bodies;
    auto fail = [&](std::uint32_t i, const char* field, const std::string& value) {
        throw Error("state check: " + to_string(BodyHandle{i, b.generation[i]}) + " has a non-finite " + field + " " +
                    value + " after stage " + to_string(stage));
    };
    for (const std::uint32_t i : world.awake) {
        if (!is_finite(b.x[i])) fail(i, "center_of_mass", vec(b.x[i]));
        if (!is_finite(b.q[i])) fail(i, "orientation", "(w " + number(b.q[i].w()) + ", " + vec(b.q[i].vec()) + ")");
        if (!is_finite(b.v[i])) fail(i, "linear_velocity", vec(b.v[i]));
        if (!is_finite(b.w[i])) fail(i, "angular_velocity", vec(b.w[i]));
    }
}

namespace {

#ifdef SPINDLE_VALIDATE_STATE
constexpr bool kValidateState = true;
#else
constexpr bool kValidateState = false;
#endif

// Runs one stage under its trace name and adds its time to the update's stats. With
// SPINDLE_VALIDATE_STATE, then checks every awake body's state, so the first stage that
// makes a value non-finite is the one named.
template <typename F>
void run_stage(World& world, Stage stage, F&& body) {
    StageScope scope(*world.jobs, to_string(stage));
    const std::int64_t start = now_nanoseconds();
    body();
    world.stats.stage_seconds[static_cast<int>(stage)] += static_cast<double>(now_nanoseconds() - start) * 1e-9;
    if constexpr (kValidateState) check_state(world, stage);
}

// The flip waits for the motion-state lock; a thread holding it would wait for itself.
void check_not_holding_motion_state_lock(const World& world, const char* what) {
    if (world.motion_states.lock().held_by_this_thread()) {
        throw Error(std::string(what) +
                    ": this thread holds the motion-state lock, which the flip would wait for forever");
    }
}

// The huge pages stocked for the step just taken (api/space.cpp) that it did not take.
void give_back_stock(World& world) {
    world.building_level = false;
    world.first_step_bodies = 0;
    world.first_step_contacts = 0;
    world.first_step_rolls = false;
    if (world.stocked_pages != 0) give_back_stocked_huge_pages(std::exchange(world.stocked_pages, 0));
}

}  // namespace

void Space::update(Real dt) {
    const AccessGate::Update access(m_world->gate, "update");
    World& w = *m_world;
    check_not_holding_motion_state_lock(w, "update");
    if (!std::isfinite(dt) || dt < 0) {
        throw Error("update: dt must be a finite, non-negative number of seconds, got " + number(dt));
    }
    const TimeStepSettings& ts = w.settings.time_step;
    w.stats = UpdateStats{};
    run_stage(w, Stage::ApplyWrites, [&] { apply_writes(w); });

    int steps = 1;
    if (ts.use_internal_time_stepping) {
        // Saturates instead of overflowing: a dt near the largest double is just "too much".
        w.accumulator = std::min<Real>(w.accumulator + dt, kHuge);
        // Counted in floating point and clamped before the cast, so any finite dt is fine
        // (the quotient can be far beyond an int). The small tolerance makes 1/30 s hold
        // exactly two 1/60 s steps.
        const Real held = std::floor(w.accumulator / ts.duration + 1e-9);
        steps = static_cast<int>(std::clamp<Real>(held, ts.min_steps_per_frame, ts.max_steps_per_frame));
        w.accumulator = std::max<Real>(0, w.accumulator - steps * ts.duration);
        // Carry at most the cap's worth, so a slow machine cannot spiral.
        const Real carry_limit = ts.max_steps_per_frame * ts.duration;
        if (w.accumulator > carry_limit) {
            w.stats.dropped_seconds = w.accumulator - carry_limit;
            w.accumulator = carry_limit;
        }
    }
    for (int i = 0; i < steps; ++i) step(w, ts.duration);
    w.stats.steps = steps;
    if (steps > 0) give_back_stock(w);

    run_stage(w, Stage::FlipReadBuffers, [&] { flip_read_buffers(w); });
}

void Space::update() {
    const AccessGate::Update access(m_world->gate, "update");
    World& w = *m_world;
    check_not_holding_motion_state_lock(w, "update");
    w.stats = UpdateStats{};
    run_stage(w, Stage::ApplyWrites, [&] { apply_writes(w); });
    step(w, w.settings.time_step.duration);
    w.stats.steps = 1;
    give_back_stock(w);
    run_stage(w, Stage::FlipReadBuffers, [&] { flip_read_buffers(w); });
}

void Space::flush() {
    const AccessGate::Update access(m_world->gate, "flush");
    World& w = *m_world;
    check_not_holding_motion_state_lock(w, "flush");
    w.stats = UpdateStats{};
    run_stage(w, Stage::ApplyWrites, [&] { apply_writes(w); });
    run_stage(w, Stage::FlipReadBuffers, [&] { flip_read_buffers(w); });
}

void step(World& w, Real dt) {
    SPINDLE_ASSERT(w.awake_pending.empty() && w.awake_left_from == kNoPosition,
                   "step: the awake list has changes not settled (settle_awake after waking or sleeping)");
    // Kinematic moves (Space::move_kinematic) set the velocities that reach their targets in
    // this step, so the broadphase sweeps and the contacts push with them.
    if (!w.kinematic_moves.empty()) start_kinematic_moves(w, dt);
    run_stage(w, Stage::Broadphase, [&] { update_broadphase(w, dt); });
    run_stage(w, Stage::Narrowphase, [&] { update_narrowphase(w); });
    run_stage(w, Stage::Islands, [&] { update_islands(w, dt); });
    run_stage(w, Stage::Solver, [&] { solve(w, dt); });  // substeps integrate velocities and positions
    note_hits(w);  // from the impulses just solved; nothing to do unless a pair reports events
    // The bodies the solver found moving far for their size, or flagged fast; no stage at
    // all in a step without any.
    if (bodies_to_sweep(w)) run_stage(w, Stage::Continuous, [&] { sweep_fast_bodies(w); });
    if (!w.kinematic_moves.empty()) finish_kinematic_moves(w);  // exactly on target, then at rest
    run_stage(w, Stage::Record, [&] { record(w); });
    w.steps += 1;
    w.counters.steps += 1;
}

}  // namespace spindle
