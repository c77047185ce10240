// Buffering stages: ApplyWrites (write buffer -> live state) and FlipReadBuffers
// (live state -> published buffer, swapped under the motion-state lock).
#include <algorithm>

#include "query/query_scene.hpp"
#include "solver/speed_limit.hpp"
#include "stages/body_changes.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"

namespace spindle {

// The physics side of MotionStateManager, private to everything but these two stages.
class MotionStatePublisher {
public:
    explicit MotionStatePublisher(MotionStateManager& manager) : m_manager(manager) {}
    PublishedBuffer& back() noexcept { return m_manager.back(); }
    int back_index() const noexcept { return m_manager.back_index(); }
    PublishedBuffer& buffer_locked(int k) noexcept { return m_manager.buffer_locked(k); }
    MotionStateLock& lock() const noexcept { return m_manager.lock(); }
    void lock_for_publishing() { m_manager.lock_for_publishing(); }
    void set_published_generation(std::uint32_t slot, std::uint32_t generation) {
        m_manager.set_published_generation(slot, generation);
    }
    void set_published_kind(std::uint32_t slot, MotionType type, bool static_only_shape) {
        m_manager.set_published_kind(slot, type, static_only_shape);
    }
    double flip(const PublishedTime& time, const std::shared_ptr<QueryScene>& queries) {
        return m_manager.flip(time, queries);
    }
    void set_query_scene_locked(std::shared_ptr<const QueryScene> queries) {
        m_manager.set_query_scene_locked(std::move(queries));
    }

private:
    MotionStateManager& m_manager;
};

namespace {

// MotionStateLock::Hold for the physics side: while it waits, it says so, so that a first
// query holding the lock builds the query scenes meanwhile instead of waiting for it
// (query/query_lease.cpp).
class PublishingHold {
public:
    explicit PublishingHold(MotionStatePublisher& manager)
        : m_lock(manager.lock()), m_took(!m_lock.held_by_this_thread()) {
        if (m_took) manager.lock_for_publishing();
    }
    ~PublishingHold() {
        if (m_took) m_lock.unlock();
    }
    PublishingHold(const PublishingHold&) = delete;
    PublishingHold& operator=(const PublishingHold&) = delete;

private:
    MotionStateLock& m_lock;
    bool m_took;
};

}  // namespace

// Each written body once, whatever the number of writes made to it (WriteBuffer
// coalesces them): pose, then velocities, then impulses, then forces for the next step.
void apply_writes(World& world) {
    apply_joint_targets(world);  // free while no motor target was written
    std::uint32_t superseded = 0;
    world.writes.drain(world.drained, superseded);
    world.stats.writes_rejected += static_cast<int>(superseded);
    Bodies& b = world.bodies;
    const Real max_linear = world.settings.solver.max_linear_speed;
    const Real max_angular = world.settings.solver.max_angular_speed;
    std::vector<std::uint32_t> refiltered;    // bodies whose filter changed (rare: no allocation otherwise)
    std::vector<std::uint32_t> rematerialed;  // bodies whose material changed (as rare)
    for (const PendingWrites& write : world.drained) {
        if (!b.is_live(write.body)) {
            world.stats.writes_rejected += static_cast<int>(write.writes);  // destroyed after the writes were made
            continue;
        }
        const std::uint32_t i = write.body.index;
        // Motion type, shape and material first: what follows is applied to the body as changed.
        world.stats.writes_rejected += apply_body_changes(world, write, rematerialed);
        const bool moves = b.type[i] != MotionType::Static;
        const bool pose = (write.bits & kPendingPose) != 0;
        if (pose) {
            // A static body too: what rests on it must not hang where it was. Before the
            // proxy moves, so the contacts are found where the body was.
            wake_touching(world, i);
            const Vec3 origin = (write.bits & kPendingPosition) != 0 ? write.position : b.origin(i);
            if ((write.bits & kPendingOrientation) != 0) b.q[i] = write.orientation.normalized();
            b.x[i] = origin + b.q[i] * b.local_com[i];
            b.reset_history(i);  // the body jumps: an interpolated read does not slide it there
        } else if (moves && write.bits != kPendingUserData) {
            wake_body(world, i);  // not for user data alone: a game may tag sleeping bodies every frame
        }
        if (moves) {
            if ((write.bits & kPendingLinearVelocity) != 0) b.v[i] = write.linear_velocity;
            if ((write.bits & kPendingAngularVelocity) != 0) b.w[i] = write.angular_velocity;
            if ((write.bits & kPendingImpulse) != 0) b.v[i] += b.inv_mass[i] * write.impulse;
            if ((write.bits & kPendingAngularImpulse) != 0) {
                b.w[i] = add_angular(b.w[i], 1, b.inv_inertia_world(i), write.angular_impulse, max_angular);
            }
            if ((write.bits & kPendingForce) != 0) b.force[i] = saturate(b.force[i] + write.force);
            if ((write.bits & kPendingTorque) != 0) b.torque[i] = saturate(b.torque[i] + write.torque);
            // Forces and impulses at points turn the body about its centre of mass as it is now.
            if ((write.bits & kPendingForceAt) != 0) {
                b.torque[i] = saturate(b.torque[i] + write.force_moment - saturated_cross(b.x[i], write.force_at));
            }
            if ((write.bits & kPendingImpulseAt) != 0) {
                const Vec3 angular = saturate(write.impulse_moment - saturated_cross(b.x[i], write.impulse_at));
                b.w[i] = add_angular(b.w[i], 1, b.inv_inertia_world(i), angular, max_angular);
            }
            if (b.locks[i] != 0) {
                // Written velocities and impulses lose their locked components (the
                // angular impulse already went through the locked inverse inertia).
                b.v[i] = project_linear(b.v[i], b.locks[i]);
                b.w[i] = project_angular(b.w[i], b.locks[i]);
            }
            b.v[i] = limit_speed(b.v[i], max_linear);
            b.w[i] = limit_speed(b.w[i], max_angular);
        }
        if ((write.bits & (kPendingPose | kPendingVelocity)) != 0) {
            b.bounds[i] = b.traits[i].shape.bounds(b.transform(i));
            refresh_proxy(world, i);
            world.changed_now.push_back(i);
        }
        if ((write.bits & kPendingKinematicMove) != 0) {
            if (b.type[i] == MotionType::Kinematic) {
                add_kinematic_move(world, i, write.target_position, write.target_orientation);
            } else {
                world.stats.writes_rejected += 1;  // made static or dynamic since the move was written
            }
        }
        if ((write.bits & kPendingFilter) != 0 && (b.layer[i] != write.layer || b.group[i] != write.group)) {
            b.layer[i] = static_cast<std::uint8_t>(write.layer);
            b.group[i] = write.group;
            b.traits[i].layer = write.layer;
            b.traits[i].group = write.group;
            refiltered.push_back(i);
            world.changed_now.push_back(i);  // the query scenes publish the filter
        }
        world.stats.writes_applied += static_cast<int>(write.writes);
        world.stats.bodies_written += 1;
    }
    if (!rematerialed.empty()) recombine_materials(world, rematerialed);  // slots ascending, as drained
    if (!refiltered.empty()) {
        std::sort(refiltered.begin(), refiltered.end());
        refilter_bodies(world, refiltered);
    }
    settle_awake(world);
}

// Fills slot i of a published buffer from the live state. A static body never blends
// (its history is its pose: a blend would only add rounding).
static void fill(const World& world, std::uint32_t i, PublishedBuffer& p, bool interpolating) {
    const Bodies& b = world.bodies;
    if (!b.alive[i]) {
        p.generation[i] = 0;
        return;
    }
    p.generation[i] = b.generation[i];
    MotionState& s = p.current[i];
    s.orientation = b.q[i];
    s.position = b.origin(i);
    s.center_of_mass = b.x[i];
    s.linear_velocity = b.v[i];
    s.angular_velocity = b.w[i];
    p.interpolate[i] = interpolating && b.interpolate[i] && b.type[i] != MotionType::Static;
    if (p.interpolate[i]) {
        // Bodies without the flag skip this: interpolation costs them nothing.
        const std::uint32_t h = b.history_place[i];  // a body that can move has one
        p.history_place[i] = h;
        PublishedHistory& before = p.previous[h];
        before.position = b.history_position[0][h];
        before.orientation = b.history_orientation[0][h];
        before.center_of_mass = before.position + before.orientation * b.local_com[i];
    }
}

// Room in a published buffer for every body slot and history entry, before fill().
static void fit_published(const Bodies& b, PublishedBuffer& p) {
    // The histories' room, not a doubling of its own (Bodies::make_history_room).
    if (p.previous.capacity() < b.history_count()) p.previous.reserve(b.history_position[0].capacity());
    if (p.size() < b.capacity() || p.previous.size() < b.history_count()) p.resize(b.capacity(), b.history_count());
}

// A body's user data, published apart from its state: it lives in the cold description
// and changes only by creation or a write, so only changed bodies are written.
static void publish_user_data(const World& world, std::uint32_t i, PublishedBuffer& p) {
    p.user_data[i] = world.bodies.alive[i] ? world.bodies.traits[i].user_data : 0;
}

void reserve_published(World& world, std::size_t slots) {
    MotionStatePublisher manager(world.motion_states);
    const PublishingHold guard(manager);  // a read may be copying the front buffer
    for (int k = 0; k < 2; ++k) manager.buffer_locked(k).reserve(slots);
}

void publish_now(World& world, std::uint32_t slot) {
    MotionStatePublisher manager(world.motion_states);
    const bool interpolating = world.settings.time_step.use_internal_time_stepping;
    // The back query scene first, outside the lock: no query can take it (it is not
    // published), so a copy of one an old query still holds costs the lock nothing.
    // Before the space's first query there is none (query/query_lease.cpp).
    const int back = manager.back_index();
    if (world.query_scenes[back]) writable_query_scene(world, back).refresh(world, slot, interpolating);
    // The update thread may hold the lock itself (a posted function reading one step
    // while it creates bodies); then publishing goes ahead under its hold.
    const PublishingHold guard(manager);
    for (int k = 0; k < 2; ++k) {
        PublishedBuffer& buffer = manager.buffer_locked(k);
        fit_published(world.bodies, buffer);
        fill(world, slot, buffer, interpolating);
        publish_user_data(world, slot, buffer);
    }
    // Creation and destruction are the only changes of a slot's generation, and both
    // publish here, so the lock-free copy buffered writes check stays exact.
    manager.set_published_generation(slot, manager.buffer_locked(0).generation[slot]);
    publish_kind(world, slot);
    // Queries see the body at once too, as reads do, unless a query is walking the
    // published scene now: copying a whole scene under the lock for each body made would
    // stall every reader, so then the next flip brings the body to queries (the front
    // scene is refreshed there for it, as a changed body; WorkCounters::query_publishes_deferred).
    // Read under the lock: a first query holding it may have built the scenes while this
    // thread waited for it (and holds the front one: then the body is deferred).
    // Otherwise both buffers and both scenes hold the slot now, so the flips need not
    // publish it again: a million bodies created before the first step would otherwise be
    // copied twice more, at the first two flips.
    QueryScene* front = world.query_scenes[1 - back].get();
    if (front && front->holders.load(std::memory_order_acquire) == 0) {
        front->refresh(world, slot, interpolating);
    } else if (front) {
        world.counters.query_publishes_deferred += 1;
        world.changed_now.push_back(slot);
    }
    manager.set_query_scene_locked(world.query_scenes[1 - back]);
}

void publish_kind(World& world, std::uint32_t slot) {
    const Bodies& b = world.bodies;
    MotionStatePublisher(world.motion_states)
        .set_published_kind(slot, b.type[slot], b.alive[slot] != 0 && b.traits[slot].shape.static_only());
}

void flip_read_buffers(World& world) {
    Bodies& b = world.bodies;
    MotionStatePublisher manager(world.motion_states);
    PublishedBuffer& back = manager.back();
    fit_published(b, back);
    const bool interpolating = world.settings.time_step.use_internal_time_stepping;

    auto publish = [&](std::uint32_t i) {
        fill(world, i, back, interpolating);
        world.counters.interpolated_publishes += back.interpolate[i];
    };
    // The back buffer is two flips old: refresh what moved in either of the two
    // updates (awake bodies, and bodies changed by writes, creation or sleep). The
    // awake ones in parallel (each entry is its own), counted per worker; and only when
    // the back buffer has not already got them: an update that took no step and applied
    // no write leaves the awake bodies as they were at its last fill (the async runner
    // updates many times per step, and would otherwise copy every awake body each time).
    // Anything that may have changed an awake body since the last flip: a step, a write,
    // or a direct change (set_internal_motion_state, creation) noted in changed_now.
    if (world.stats.steps > 0 || world.stats.writes_applied > 0 || !world.changed_now.empty()) {
        world.awake_version += 1;
    }
    const int k = manager.back_index();
    // The query scene that goes with the back buffer gets the same bodies refreshed; before
    // the space's first query there is none, and no query work is done.
    QueryScene* queries = world.query_scenes[k] ? &writable_query_scene(world, k) : nullptr;
    if (queries) queries->reserve(b.capacity());
    // Bodies changed by writes, creation, destruction or sleep first, awake or not: a
    // shape or filter changes here, and the awake poses below use the new shape's box.
    // User data too: it changes only by creation or a write, both noted in changed_now (it
    // lives in the cold description, which the awake refill below does not read). The
    // awake ones' states are refilled below with the rest of the awake bodies.
    for (const std::vector<std::uint32_t>* changed : {&world.changed_now, &world.changed_last}) {
        for (std::uint32_t i : *changed) {
            if (queries) queries->refresh(world, i, interpolating);
            publish_user_data(world, i, back);
            if (!b.alive[i] || b.awake_index[i] < 0) publish(i);
        }
        world.counters.changed_publishes += changed->size();
    }
    const bool awake_stale = world.published_version[k] != world.awake_version ||
                             world.published_interpolating[k] != interpolating;
    if (awake_stale) {
        std::vector<CacheLinePadded<std::uint64_t>>& interpolated = world.publish_counts;
        interpolated.assign(world.jobs->worker_count(), {});
        const auto n = static_cast<std::uint32_t>(world.awake.size());
        std::vector<Aabb>& query_bounds = world.scratch_query_bounds;
        if (queries) query_bounds.resize(n);
        world.jobs->parallel_for("Publish", 0, n, 256, [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
            std::uint64_t count = 0;
            for (std::uint32_t a = lo; a < hi; ++a) {
                const std::uint32_t i = world.awake[a];
                fill(world, i, back, interpolating);
                count += back.interpolate[i];
                if (queries) queries->refresh_pose(world, i, interpolating, query_bounds[a]);
            }
            interpolated[worker].value += count;
        });
        if (queries) {
            // The tree by one thread: most proxies are still inside their fat boxes, and
            // those that left are moved in place (their ancestors rebuilt once, below).
            const Real step = world.settings.time_step.duration;
            for (std::uint32_t a = 0; a < n; ++a) {
                const std::uint32_t i = world.awake[a];
                queries->move(i, query_bounds[a], b.v[i] * step);
            }
        }
        for (const CacheLinePadded<std::uint64_t>& c : interpolated) world.counters.interpolated_publishes += c.value;
        world.counters.awake_publishes += n;
        world.published_version[k] = world.awake_version;
        world.published_interpolating[k] = interpolating;
    }
    if (queries) {
        queries->rebuild_moved(*world.jobs);
    } else if (world.queries_wanted.load(std::memory_order_relaxed)) {
        // A query is waiting for a scene (query/query_lease.cpp): the buffer is complete now.
        world.query_scenes[k] = QueryScene::build(world, back);
    }
    std::swap(world.changed_last, world.changed_now);
    world.changed_now.clear();
    // Bodies awake last update but asleep now were recorded in changed_now by the
    // islands stage, so nothing is missed.

    const Real step = world.settings.time_step.duration;
    const PublishedTime time{world.steps,
                             interpolating ? world.accumulator / step : 1.0,
                             world.update_clock_ns,
                             step,
                             world.update_clock_rate,
                             world.read_blend};
    world.stats.flip_lock_seconds = manager.flip(time, world.query_scenes[k]);
    // After the swap the new back buffer may be shorter than the body slots.
    fit_published(b, manager.back());
    world.stats.awake_bodies = static_cast<std::uint32_t>(world.awake.size());
    publish_contact_events(world);  // under the events' own lock, not the motion-state lock
    publish_contact_points(world);
}

}  // namespace spindle
