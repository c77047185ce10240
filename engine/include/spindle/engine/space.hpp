// Space: the simulated world. update() runs the pipeline of design.md section 2:
// ApplyWrites, k steps (collide, islands, solve, integrate, record), FlipReadBuffers.
//
// Threads. Three kinds of access, each with its own rule:
//  - buffered accessors (position(), set_position(), motion_state(), add_force() ...):
//    any thread, any time, concurrently with update(). Reads see the last published
//    step (interpolated where asked), never a mix of two; writes take effect at the
//    next update's ApplyWrites, the last write to a property winning.
//  - internal accessors (internal_*): the live state. Only the thread that calls
//    update(), and never during update().
//  - structure (create_body, destroy_body, joints, settings, internal_*) and update():
//    one thread at a time, normally the physics loop thread (AsyncRunner::post runs a
//    function there). A structural call from another thread while an update runs, or
//    while an AsyncRunner's loop runs this space, throws spindle::Error instead of
//    racing; structural calls from several threads outside updates take turns.
//    contains(BodyHandle) and body_count() are any thread, any time.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/engine/events.hpp>
#include <spindle/engine/joint.hpp>
#include <spindle/engine/settings.hpp>
#include <spindle/engine/stats.hpp>

namespace spindle {

class JobSystem;
class MotionStateManager;
struct World;

class Space {
public:
    // jobs: the scheduler that runs the parallel stages; null runs everything on the
    // caller of update(). The JobSystem must outlive the Space. Every setting is checked
    // as its setter checks it (spindle::Error naming the struct and field).
    explicit Space(const SpaceSettings& settings = {}, JobSystem* jobs = nullptr);
    ~Space();
    Space(const Space&) = delete;
    Space& operator=(const Space&) = delete;

    // ---- structure (update thread, or any thread while no update runs) ----
    // Validates everything first; a rejected body leaves the space unchanged and the
    // spindle::Error names the field and value.
    BodyHandle create_body(const BodyDesc& desc);
    void destroy_body(BodyHandle body);
    bool contains(BodyHandle body) const noexcept;  // any thread: as published
    std::size_t body_count() const noexcept;        // any thread

    // Joints (same thread rule as bodies). create_joint validates first (bodies live
    // and different, at least one dynamic, finite anchors, non-zero axes, ordered
    // limits); a rejected joint leaves the space unchanged and the spindle::Error names
    // the field. Creating or destroying a joint wakes both bodies. Destroying a body
    // destroys its joints.
    JointHandle create_joint(const JointDesc& desc);
    void destroy_joint(JointHandle joint);
    bool contains(JointHandle joint) const noexcept;
    std::size_t joint_count() const noexcept;
    JointDesc joint_desc(JointHandle joint) const;  // as created (a copy)
    // Changes a hinge's motor (between updates); max_torque >= 0.
    void set_hinge_motor(JointHandle joint, bool enable, Real speed, Real max_torque);

    // Collision filtering: the layer table. Whether bodies on layers a and b collide
    // (symmetric; every pair collides by default). a, b < kLayerCount, else spindle::Error
    // naming the value. A change re-checks every pair at the next step: contacts it
    // filters out are removed (waking their bodies), overlaps it allows are found again.
    void set_layers_collide(std::uint32_t a, std::uint32_t b, bool collide);
    bool layers_collide(std::uint32_t a, std::uint32_t b) const;

    // ---- update (one thread at a time) ----
    // With internal time stepping: adds dt to the accumulator and takes the steps it
    // holds (at least min, at most max_steps_per_frame). Without: exactly one step of
    // TimeStepSettings::duration whatever dt is. Negative, NaN or infinite dt throws
    // before anything changes; any finite dt is fine: a huge one takes max_steps_per_frame
    // steps, keeps that many steps' worth and drops the rest (last_update().dropped_seconds).
    void update(Real dt);
    // One step of TimeStepSettings::duration (after ApplyWrites, before the flip).
    void update();
    // ApplyWrites and FlipReadBuffers without a step: makes every buffered write so
    // far live and visible (AsyncRunner::stop uses it so no write is lost).
    void flush();

    // ---- buffered accessors (any thread, concurrently with update) ----
    MotionState motion_state(BodyHandle body) const;  // interpolated where allowed
    Vec3 position(BodyHandle body) const;
    Quat orientation(BodyHandle body) const;
    Vec3 center_of_mass(BodyHandle body) const;
    Vec3 linear_velocity(BodyHandle body) const;
    Vec3 angular_velocity(BodyHandle body) const;
    void set_position(BodyHandle body, const Vec3& position);        // a teleport
    void set_orientation(BodyHandle body, const Quat& orientation);  // a teleport
    void set_linear_velocity(BodyHandle body, const Vec3& velocity);
    void set_angular_velocity(BodyHandle body, const Vec3& velocity);
    void set_motion_state(BodyHandle body, const MotionState& state);  // all of it; a teleport
    // Accumulate until a step consumes them (an update that takes no step loses nothing).
    void add_force(BodyHandle body, const Vec3& force);    // at the centre of mass, for one step
    void add_torque(BodyHandle body, const Vec3& torque);  // for one step
    void apply_impulse(BodyHandle body, const Vec3& impulse);
    void apply_angular_impulse(BodyHandle body, const Vec3& impulse);
    void wake(BodyHandle body);
    // A body's collision layer and group (BodyDesc::layer, group); layer < kLayerCount,
    // checked here. At the next update's ApplyWrites its contacts that the filter now
    // rejects are removed (waking what they touched) and its overlaps are found again.
    void set_collision_filter(BodyHandle body, std::uint32_t layer, std::uint32_t group);

    // ---- contact and sensor events (any thread, any time, concurrently with update) ----
    // Hands over every event published since the last read (FlipReadBuffers publishes
    // each update's steps' events), appended to `out` in the order they happened, and
    // returns how many: none lost however many steps ran or how seldom the game reads, none
    // given twice. Holds the events' own small lock, which the physics thread takes only to
    // append at the flip: a read never waits for a step. Readers on several threads each get
    // a disjoint part of the sequence.
    std::size_t read_contact_events(std::vector<ContactEvent>& out);
    // Events thrown away since creation because EventSettings::max_queued were waiting
    // unread (never silent). Any thread.
    std::uint64_t dropped_contact_events() const;

    // ---- internal accessors (update thread, between updates) ----
    MotionState internal_motion_state(BodyHandle body) const;
    Vec3 internal_position(BodyHandle body) const;
    Quat internal_orientation(BodyHandle body) const;
    Vec3 internal_linear_velocity(BodyHandle body) const;
    Vec3 internal_angular_velocity(BodyHandle body) const;
    void set_internal_motion_state(BodyHandle body, const MotionState& state);
    bool internal_is_awake(BodyHandle body) const;
    BodyDesc internal_desc(BodyHandle body) const;  // as created (shape, material, flags; a copy), filter as last set
    // How far a joint is from satisfied now, from the live poses.
    JointError internal_joint_error(JointHandle joint) const;
    // A hinge's angle (rad): B's rotation relative to A about the axis since creation.
    Real internal_hinge_angle(JointHandle joint) const;

    MotionStateManager& motion_states() noexcept;
    const MotionStateManager& motion_states() const noexcept;

    // Settings: read any time from the update thread; change between updates. Each setter
    // checks every field (finite, in range) and throws spindle::Error naming the first bad
    // one ("solver: damping_ratio must be finite and >= 0, got inf") before anything changes.
    const SpaceSettings& settings() const noexcept;
    void set_time_step(const TimeStepSettings& settings);
    void set_solver(const SolverSettings& settings);
    void set_sleep(const SleepSettings& settings);
    void set_gravity(const Vec3& gravity);
    void set_events(const EventSettings& settings);  // "events: max_queued must be >= 1, got 0"

    // What the last update did (update thread).
    const UpdateStats& last_update() const noexcept;
    // Totals since creation (update thread).
    const WorkCounters& counters() const noexcept;
    // Time banked toward the next step, in seconds (internal time stepping).
    Real accumulated_time() const noexcept;
    // FNV-1a over every live body's position and orientation bits, in handle order.
    std::uint64_t state_hash() const;

    JobSystem& jobs() noexcept;

private:
    friend class AsyncRunner;      // claims the space for its loop thread (api/access_gate.hpp)
    friend struct SpaceInternals;  // engine/src/api/space_internals.hpp: the engine's own tests reach World
    std::unique_ptr<World> m_world;
};

}  // namespace spindle
