// The stages of Space::update (design.md section 2), one file each in this folder, and
// the bookkeeping they share. Every stage runs on the update thread and splits its work
// through world.jobs; update.cpp calls them in order.
#pragma once

#include <cstdint>
#include <span>

#include "world.hpp"

namespace spindle {

// buffering.cpp
void apply_writes(World& world);       // buffered writes since the last update -> live state
void flip_read_buffers(World& world);  // publish the newest states under the motion-state lock

// broadphase.cpp: bounds, new pairs -> contacts, lost pairs dropped.
void update_broadphase(World& world, Real dt);
// narrowphase.cpp: manifolds for every awake contact, impulses carried by feature id.
void update_narrowphase(World& world);
// islands.cpp: wake islands touched by awake bodies; put resting islands to sleep.
void update_islands(World& world, Real dt);
// solver.cpp: substeps of integrate velocities, warm start, solve, integrate positions, relax.
void solve(World& world, Real dt);
// continuous.cpp: the bodies the solver listed in World::fast_lists swept against static
// geometry (step() runs the stage only when bodies_to_sweep()).
bool bodies_to_sweep(const World& world);
void sweep_fast_bodies(World& world);
// integrator.cpp (called by the solver once per substep, in blocks of the awake
// bodies [lo, hi), or on lists of them `ks` where the solver folds the passes into its
// colours; effects used are counted into `counts`).
struct SolverBody;
struct PushVelocity;
void integrate_velocities(World& world, SolverBody* bodies, const Real* gravity_scales, Real h, std::uint32_t lo,
                          std::uint32_t hi, EffectCounts& counts);
// With `warm`, each body's warm start row added after and cleared (SolverScratch::warm_velocities).
void integrate_velocities(World& world, SolverBody* bodies, const Real* gravity_scales, Real h,
                          std::span<const std::uint32_t> ks, EffectCounts& counts, PushVelocity* warm = nullptr);
void integrate_positions(World& world, SolverBody* bodies, PushVelocity* push, Real h, std::uint32_t lo,
                         std::uint32_t hi);
void integrate_positions(World& world, SolverBody* bodies, PushVelocity* push, Real h,
                         std::span<const std::uint32_t> ks);
// record.cpp: previous <- current for interpolating bodies; bounds of moved bodies.
void record(World& world);

// One step of dt: collide, islands, solve, record (update.cpp).
void step(World& world, Real dt);
// Throws spindle::Error naming the first awake body whose pose or velocity is not finite
// and the stage just run. Built with SPINDLE_VALIDATE_STATE, run_stage calls it after
// every stage (update.cpp).
void check_state(const World& world, Stage stage);
// The positions of the awake contacts, ascending (contact_list.cpp).
const std::vector<std::uint32_t>& awake_contacts(World& world);
// The awake list (islands.cpp). set_awake notes a body woken or put to sleep; world.awake
// and the awake positions are brought up to date by settle_awake, which ApplyWrites and the
// Islands stage call before anything reads them. awake_index >= 0 tells awake at any time.
void set_awake(World& world, std::uint32_t slot, bool awake);
void settle_awake(World& world);
// Wakes a body and, if it sleeps, its whole island (islands.cpp).
void wake_body(World& world, std::uint32_t slot);
// Wakes a body (unless static) and the island of every body it has a contact or a joint
// with: for a change that can take away what rests on it (destroying it, moving it by a
// write, changing its shape or motion type). Call before its proxy moves (islands.cpp).
void wake_touching(World& world, std::uint32_t slot);
// Writes a body's current state into both published buffers at once (create/destroy
// between updates), so buffered reads see it before the next flip (buffering.cpp).
void publish_now(World& world, std::uint32_t slot);
// Room in both published buffers for `slots` body slots (Space::reserve_bodies), under the
// motion-state lock (buffering.cpp).
void reserve_published(World& world, std::size_t slots);
// Records a body's motion type and shape kind where buffered writes check them lock-free
// (MotionStateManager::published_motion_type), at once (buffering.cpp).
void publish_kind(World& world, std::uint32_t slot);

}  // namespace spindle
