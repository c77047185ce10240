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
#include <optional>
#include <span>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/engine/events.hpp>
#include <spindle/engine/joint.hpp>
#include <spindle/engine/query.hpp>
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
    // spindle::Error names the field and value. While a level is built (before the first
    // update, or after reserve_bodies until the next update) a body's fat box is looked up
    // among the others' for the contacts it will make, and the huge pages the level's first
    // step will write for its new dynamic bodies and their contacts are mapped here, as they
    // add up to whole pages, rather than in that step (SpaceSettings::capacity); the next
    // update gives back what its step did not take. A body made otherwise (one spawned in a
    // running game) is not looked up: its step grows its arrays as it always did.
    BodyHandle create_body(const BodyDesc& desc);
    void destroy_body(BodyHandle body);
    bool contains(BodyHandle body) const noexcept;  // any thread: as published
    std::size_t body_count() const noexcept;        // any thread
    // Room for `count` bodies alive at once, for a level about to be made: creating bodies
    // up to that many then moves none of the space's per-body arrays (scene build() asks
    // for its bodies), and the bodies made until the next update stock their first step's
    // pages as a level's (create_body). Never shrinks. A count past the body handles' 32-bit index, or one
    // the memory cannot hold, throws spindle::Error naming it and changes nothing else.
    void reserve_bodies(std::size_t count);

    // Joints (same thread rule as bodies). create_joint validates first (bodies live
    // and different, at least one dynamic, anchors within 1e9 m, non-zero axes, ordered
    // limits, lengths and translations within 2e9 m and motor speeds within 1e9); a
    // rejected joint leaves the space unchanged and the spindle::Error names the field. Creating or destroying a joint
    // wakes both bodies. Destroying a body destroys its joints.
    JointHandle create_joint(const JointDesc& desc);
    void destroy_joint(JointHandle joint);
    bool contains(JointHandle joint) const noexcept;
    std::size_t joint_count() const noexcept;
    JointDesc joint_desc(JointHandle joint) const;  // as created (a copy)
    // Changes a hinge's motor (between updates); max_torque >= 0.
    void set_hinge_motor(JointHandle joint, bool enable, Real speed, Real max_torque);
    // A motor joint's target (MotorParams::linear_offset, angular_offset), or a mouse
    // joint's world target point (the angular offset stays). Buffered: any thread, any
    // time, concurrently with update(); the last write wins, applied at the next
    // update's ApplyWrites, waking the joint's bodies. Values are checked first, then the
    // handle (a live motor joint) under the joint targets' own small lock, which update()
    // takes only to drain them: a rejected call throws spindle::Error and changes nothing.
    // A joint destroyed before ApplyWrites drops its write (last_update().writes_rejected).
    void set_motor_target(JointHandle joint, const Vec3& linear_offset, const Quat& angular_offset);
    void set_mouse_target(JointHandle joint, const Vec3& world_target);

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

    // Changes after creation (issue 17), buffered like the writes above: any thread, any
    // time, concurrently with update(); the last write of each wins; live at the next
    // update's ApplyWrites. Each checks its values first (spindle::Error naming the field
    // and value: "set_friction: friction must be finite and >= 0, got nan"), then the
    // handle, lock-free (a stale one is named); a rejected call changes nothing. None takes
    // the motion-state lock, so none can deadlock with a flip.
    // The body's contacts mix the new friction, restitution or rolling resistance from the
    // next step on.
    void set_friction(BodyHandle body, Real friction);                      // >= 0
    void set_restitution(BodyHandle body, Real restitution);                // >= 0
    void set_rolling_resistance(BodyHandle body, Real rolling_resistance);  // >= 0 (BodyDesc's)
    void set_gravity_scale(BodyHandle body, Real scale);                    // finite
    void set_damping(BodyHandle body, Real linear, Real angular);           // 1/s, >= 0 each
    // Static, kinematic or dynamic. Wakes the body and what it touches, removes its
    // contacts (found again at the next step, none between two bodies that are not
    // dynamic) and rebuilds its mass (none unless dynamic). A static body made moving
    // starts at rest; a kinematic one keeps its velocity. A body with a plane or mesh
    // shape cannot be made moving: spindle::Error. A body whose density and mass are both 0
    // (allowed unless dynamic) cannot be made dynamic: that write is dropped at ApplyWrites
    // and counted in last_update().writes_rejected. The motion type and shape these checks
    // read are the body's as of the last ApplyWrites (lock-free).
    void set_motion_type(BodyHandle body, MotionType type);
    // A new shape (validated as create_body's). Unless keep_mass, mass, inertia and centre
    // of mass are rebuilt from it and the body's density or mass (its origin stays put).
    // Wakes what it touches; its contacts are found again at the next step. A plane or mesh
    // only for a static body, and a shape with no volume not for a dynamic one (the type as
    // of the last ApplyWrites): spindle::Error.
    void set_shape(BodyHandle body, const Shape& shape, bool keep_mass = false);
    // BodyDesc::user_data. user_data() reads it as published at the last FlipReadBuffers
    // (any thread; takes the motion-state lock as motion_state() does). Unlike the other
    // writes, setting it does not wake a sleeping body.
    void set_user_data(BodyHandle body, std::uint64_t user_data);
    std::uint64_t user_data(BodyHandle body) const;
    // A force (for one step) or an impulse at a world point: as add_force/apply_impulse,
    // plus the torque (point - centre of mass) x force about the centre of mass as it is
    // at ApplyWrites. Accumulated like add_force and apply_impulse.
    void add_force_at(BodyHandle body, const Vec3& force, const Vec3& point);
    void apply_impulse_at(BodyHandle body, const Vec3& impulse, const Vec3& point);
    // A kinematic body's next step takes it exactly to this pose (origin and orientation)
    // with the velocities that reach it in one step (contacts push with them); after that
    // step it is at rest unless moved again. Kept until a step takes it (an update that
    // takes no step loses nothing). The body must be kinematic as of the last ApplyWrites
    // (else spindle::Error); if a set_motion_type made it otherwise before the move applies, the
    // move is dropped and counted in last_update().writes_rejected.
    void move_kinematic(BodyHandle body, const Vec3& position, const Quat& orientation);

    // ---- scene queries (any thread, any time, concurrently with update) ----
    // Each meets the bodies where the published step puts them: where motion_state() and
    // get_motion_states() say they are (blended where those are), so a ray hits what the
    // game renders; exact against the shapes (sphere, capsule, box, hull, plane, mesh).
    // Bodies created since are met, destroyed ones are not (both publish at once), except
    // while a query walks the published scene: then from the next update (no copy of a
    // whole scene under the lock per body; WorkCounters::query_publishes_deferred). A query
    // takes the motion-state lock only to pick up the published scene (a few loads; a
    // thread that holds the lock queries the step it holds) and walks it unlocked: it
    // never waits for a step, and a step never waits for it (the physics thread copies a
    // scene a query still holds, WorkCounters::query_scene_copies). It may deadlock only
    // through filter.accept (which must not wait for an update). Non-finite arguments, or
    // a plane or mesh as the query's own shape, throw spindle::Error naming the argument.
    // A space keeps no query structure until its first query (one that never queries pays
    // nothing for them). That query builds it where the space may be read (no update runs,
    // or a posted function); else it waits for the next update's flip, or, made while
    // holding the motion-state lock, for the physics thread to wait for that lock, and it
    // throws spindle::Error after 10 s of that (the physics thread waits for something
    // the holder holds: make the first query without the lock).
    //
    // The nearest body the segment from -> to enters (a segment starting inside a solid
    // does not hit it); none for a zero-length segment.
    std::optional<QueryHit> cast_ray(const Vec3& from, const Vec3& to, const QueryFilter& filter = {}) const;
    // Whether the segment enters any body (stops at the first found: cheaper).
    bool ray_hits_any(const Vec3& from, const Vec3& to, const QueryFilter& filter = {}) const;
    // Every body the segment enters, nearest first (equal fractions by slot), into `hits`
    // (cleared first). Returns the count.
    std::size_t cast_ray_all(const Vec3& from, const Vec3& to, std::vector<QueryHit>& hits,
                             const QueryFilter& filter = {}) const;
    // The first body met by `shape` (sphere, capsule, box or hull) at `start`, moved
    // (not turned) by `translation`: fraction of the translation, point on the body,
    // normal toward the caster. Overlapping at the start: fraction 0.
    std::optional<QueryHit> cast_shape(const Shape& shape, const Transform& start, const Vec3& translation,
                                       const QueryFilter& filter = {}) const;
    // Every body that `shape` (sphere, capsule, box or hull) at `pose` touches or
    // overlaps, by slot, into `bodies` (cleared first). Returns the count.
    std::size_t overlap_shape(const Shape& shape, const Transform& pose, std::vector<BodyHandle>& bodies,
                              const QueryFilter& filter = {}) const;
    // Every body whose shape (not only its bounds) meets the box, by slot, into `bodies`
    // (cleared first); box.min <= box.max. Returns the count.
    std::size_t overlap_box(const Aabb& box, std::vector<BodyHandle>& bodies, const QueryFilter& filter = {}) const;

    // ---- contact and sensor events (any thread, any time, concurrently with update) ----
    // Hands over every event published since the last read (FlipReadBuffers publishes
    // each update's steps' events), appended to `out` in the order they happened, and
    // returns how many: none lost however many steps ran or how seldom the game reads (up
    // to EventSettings::max_queued unread; beyond it they are dropped and counted), none
    // given twice. An event's bodies may be destroyed by the time it is read: check
    // contains() before reading their state. Holds the events' own small lock, which the physics thread takes only to
    // append at the flip: a read never waits for a step. Readers on several threads each get
    // a disjoint part of the sequence.
    std::size_t read_contact_events(std::vector<ContactEvent>& out);
    // Events thrown away since creation because EventSettings::max_queued were waiting
    // unread (never silent). Any thread.
    std::uint64_t dropped_contact_events() const;
    // The touching points of the newest published step (EventSettings::publish_contact_points;
    // none while it is off), replacing `out`'s contents: pairs in contact order, the points
    // of each manifold, sensors left out. Returns the number of the step they belong to
    // (as ContactEvent::step; 0: none published yet); points beyond
    // EventSettings::max_contact_points are counted in `left_out` when given. Any thread,
    // any time: holds the events' small lock, never waits for a step.
    std::uint64_t read_contact_points(std::vector<ContactPointInfo>& out, std::size_t* left_out = nullptr) const;

    // ---- internal accessors (update thread, between updates) ----
    MotionState internal_motion_state(BodyHandle body) const;
    Vec3 internal_position(BodyHandle body) const;
    Quat internal_orientation(BodyHandle body) const;
    Vec3 internal_linear_velocity(BodyHandle body) const;
    Vec3 internal_angular_velocity(BodyHandle body) const;
    void set_internal_motion_state(BodyHandle body, const MotionState& state);
    bool internal_is_awake(BodyHandle body) const;
    // As created (shape, material, flags; a copy), with the changes made since (filter,
    // material, gravity scale, damping, motion type, shape, user data) as last applied;
    // position, orientation and velocities as they are now (the space keeps no copy of
    // those it was made with).
    BodyDesc internal_desc(BodyHandle body) const;
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
