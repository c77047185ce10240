// World: the live simulation state behind a Space, shared by the stages (stages/: one
// file per stage, called in order by update.cpp) and the API (api/). Not thread safe by itself:
// only the update thread touches it, and stages split work through the JobSystem.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/settings.hpp>
#include <spindle/engine/stats.hpp>
#include <spindle/platform/spin.hpp>
#include <spindle/scheduler/job_system.hpp>

#include "api/access_gate.hpp"
#include "api/joint_store.hpp"
#include "api/joint_targets.hpp"
#include "api/write_buffer.hpp"
#include "collision/collide.hpp"
#include "collision/convex_core.hpp"
#include "memory/huge_page_vector.hpp"
#include "solver/motion_locks.hpp"
#include "stages/contact_index.hpp"

namespace spindle {

struct BroadphaseState;  // stages/broadphase_state.hpp
struct ContactEvents;    // stages/contact_events.hpp
struct SolverScratch;    // solver/constraints.hpp
class QueryScene;        // query/query_scene.hpp

// awake_index of a body woken since World::awake was last settled (settle_awake, islands.cpp):
// awake, but not yet at a position in the list.
inline constexpr std::int32_t kAwakePending = std::numeric_limits<std::int32_t>::max();
inline constexpr std::size_t kNoPosition = std::numeric_limits<std::size_t>::max();
// Bodies::history_place of a slot that never held a body that can move.
inline constexpr std::uint32_t kNoHistory = std::numeric_limits<std::uint32_t>::max();

// The number of fields of an aggregate: the most initialisers T{...} accepts.
namespace detail {
struct AnyField {
    template <typename T>
    operator T() const;  // declared only: named in unevaluated contexts
};
template <typename T, typename... Fields>
consteval std::size_t field_count() {
    if constexpr (requires { T{Fields{}..., AnyField{}}; }) {
        return field_count<T, Fields..., AnyField>();
    } else {
        return sizeof...(Fields);
    }
}
}  // namespace detail

// What a body keeps of its description: BodyDesc but for the pose and velocities it was
// made with (the live arrays hold those; a level's static geometry would otherwise keep
// copies no stage reads). Each field means what BodyDesc's does; a field added
// to BodyDesc is added here, to both conversions and to the test that round-trips them
// (Setters.InternalDescKeepsEveryFieldItWasMadeWith); the assertion below the struct fails
// the build until it is.
struct BodyTraits {
    MotionType type = MotionType::Dynamic;
    Shape shape;  // empty in a free slot: its geometry is let go
    Real density = 0, mass = 0, friction = 0, restitution = 0, rolling_resistance = 0, gravity_scale = 0;
    Real linear_damping = 0, angular_damping = 0;
    bool gyroscopic = false;
    MotionLocks locks;
    bool allow_interpolation = false, allow_sleep = false, fast = false;
    std::uint32_t layer = 0, group = 0;
    bool contact_events = false, sensor = false;
    std::uint64_t user_data = 0;

    BodyTraits() = default;
    explicit BodyTraits(const BodyDesc& d)
        : type(d.type),
          shape(d.shape),
          density(d.density),
          mass(d.mass),
          friction(d.friction),
          restitution(d.restitution),
          rolling_resistance(d.rolling_resistance),
          gravity_scale(d.gravity_scale),
          linear_damping(d.linear_damping),
          angular_damping(d.angular_damping),
          gyroscopic(d.gyroscopic),
          locks(d.locks),
          allow_interpolation(d.allow_interpolation),
          allow_sleep(d.allow_sleep),
          fast(d.fast),
          layer(d.layer),
          group(d.group),
          contact_events(d.contact_events),
          sensor(d.sensor),
          user_data(d.user_data) {}
    // The description with the given pose and velocities.
    BodyDesc described(const Vec3& position, const Quat& orientation, const Vec3& linear_velocity,
                       const Vec3& angular_velocity) const {
        BodyDesc d;
        d.type = type, d.shape = shape, d.position = position, d.orientation = orientation;
        d.linear_velocity = linear_velocity, d.angular_velocity = angular_velocity;
        d.density = density, d.mass = mass, d.friction = friction, d.restitution = restitution;
        d.rolling_resistance = rolling_resistance;
        d.gravity_scale = gravity_scale, d.linear_damping = linear_damping, d.angular_damping = angular_damping;
        d.gyroscopic = gyroscopic, d.locks = locks, d.allow_interpolation = allow_interpolation;
        d.allow_sleep = allow_sleep, d.fast = fast, d.layer = layer, d.group = group;
        d.contact_events = contact_events, d.sensor = sensor, d.user_data = user_data;
        return d;
    }
};
// BodyTraits' 20 fields and the pose and velocities (4): a field added to BodyDesc and not
// here would be lost by every body made (the round-trip test only sets the fields it knows).
static_assert(detail::field_count<BodyDesc>() == 20 + 4,
              "BodyDesc's fields changed: carry the new one in BodyTraits (both conversions, the round-trip test), "
              "then count it here");

// Bodies, indexed by handle slot (holes where bodies were destroyed). Hot per-step
// data (pose, velocity, mass) sits in its own arrays; the description (shape,
// material, flags) is cold and read only when contacts are made or on demand.
struct Bodies {
    // Handle table.
    std::vector<std::uint32_t> generation;  // current generation of each slot (odd history, never 0 when live)
    std::vector<std::uint8_t> alive;
    std::vector<std::uint32_t> free_slots;  // LIFO; reused slots get a new generation
    std::uint32_t live = 0;

    // Hot.
    std::vector<MotionType> type;
    std::vector<Vec3> x;  // centre of mass, world
    std::vector<Quat> q;  // orientation
    std::vector<Vec3> v;  // linear velocity
    std::vector<Vec3> w;  // angular velocity, world
    std::vector<Real> inv_mass;
    std::vector<Mat3> inv_inertia_local;  // about the centre of mass, body frame
    std::vector<Mat3> inertia_local;      // the same, not inverted (gyroscopic bodies read it)
    std::vector<std::uint8_t> elongated;  // turns keeping its momentum whatever it asks (BodyMass::elongated)
    std::vector<Vec3> local_com;          // centre of mass in the shape's frame
    std::vector<std::uint8_t> locks;      // BodyDesc::locks as bits (solver/motion_locks.hpp)
    std::vector<Vec3> force;              // accumulated, consumed by the next step
    std::vector<Vec3> torque;
    std::vector<Aabb> bounds;  // tight, world
    // How far the shape reaches along the body's axes and its thinnest half-size, for the
    // solver's check of whether a step moved the body far enough to be swept (made at
    // creation and by attach(), so a new shape or motion type remakes it).
    std::vector<SweepExtent> extents;
    std::vector<std::int32_t> awake_index;  // position in World::awake, kAwakePending, or -1 if static or asleep
    std::vector<Real> sleep_time;
    std::vector<std::int32_t> island;  // sleeping island id, -1 when awake
    // Collision filter (BodyDesc::layer, group), here so that the broadphase's test of
    // every new pair reads two small arrays, not the descriptions.
    std::vector<std::uint8_t> layer;
    std::vector<std::uint32_t> group;

    // Interpolation history (the last two recorded steps, origin pose) of the bodies that
    // can move: a static body never blends, so it keeps none (a level's static geometry
    // would otherwise carry two poses a body). history_place[i] is slot i's entry in the
    // history arrays, given when the slot first holds a body that can move and kept for the
    // slot from then on (kNoHistory: none yet).
    std::vector<std::uint32_t> history_place;
    std::vector<Vec3> history_position[2];  // by entry
    std::vector<Quat> history_orientation[2];
    std::vector<std::uint8_t> interpolate;  // allow_interpolation

    // Cold.
    std::vector<BodyTraits> traits;

    std::uint32_t capacity() const noexcept { return static_cast<std::uint32_t>(generation.size()); }
    // Calls f on each per-slot array of `b` (all but free_slots), so that growing,
    // reserving and counting them name each once. Self: Bodies or const Bodies.
    template <typename Self, typename F>
    static void for_each_slot_array(Self& b, F&& f) {
        f(b.generation), f(b.alive);
        f(b.type), f(b.x), f(b.q), f(b.v), f(b.w), f(b.inv_mass), f(b.inv_inertia_local), f(b.inertia_local);
        f(b.elongated);
        f(b.local_com), f(b.locks), f(b.force), f(b.torque), f(b.bounds), f(b.extents), f(b.awake_index);
        f(b.sleep_time);
        f(b.island), f(b.layer), f(b.group), f(b.interpolate), f(b.history_place);
        f(b.traits);
    }
    // Slot i's history holds the origin pose p, q in both steps, so an interpolated read
    // shows the body there instead of sliding to it (a creation, a teleport, sleep). Gives
    // the slot its entry if it has none: for a body that can move only.
    void hold_history(std::uint32_t i, const Vec3& p, const Quat& r) {
        if (history_place[i] == kNoHistory) {
            make_history_room();
            history_place[i] = history_count();
            for (int k = 0; k < 2; ++k) history_position[k].emplace_back(), history_orientation[k].emplace_back();
        }
        const std::uint32_t h = history_place[i];
        for (int k = 0; k < 2; ++k) history_position[k][h] = p, history_orientation[k][h] = r;
    }
    // hold_history at the body's pose now, if slot i has a history (a static body has none:
    // it never blends).
    void reset_history(std::uint32_t i) {
        if (history_place[i] != kNoHistory) hold_history(i, origin(i), q[i]);
    }
    std::uint32_t history_count() const noexcept { return static_cast<std::uint32_t>(history_position[0].size()); }
    // Room for one more history entry. An entry is a slot's at most, so the room doubles
    // but never past the slots' own: a level whose bodies were reserved (1,240 for the
    // pyramid) keeps no room for 2,048 entries, as doubling gave it.
    void make_history_room() {
        const std::size_t entries = history_count();
        if (entries < history_position[0].capacity()) return;
        const std::size_t room = std::max(entries + 1, std::min(2 * entries, generation.capacity()));
        for (int k = 0; k < 2; ++k) history_position[k].reserve(room), history_orientation[k].reserve(room);
    }
    bool is_live(BodyHandle h) const noexcept {
        return h.index < generation.size() && alive[h.index] && generation[h.index] == h.generation &&
               h.generation != 0;
    }
    Vec3 origin(std::uint32_t i) const { return x[i] - q[i] * local_com[i]; }
    Transform transform(std::uint32_t i) const { return {origin(i), q[i]}; }
    // extents[i] for the body's shape, motion type and centre of mass as they are now: a
    // static body is never swept.
    void remake_extent(std::uint32_t i) {
        extents[i] = type[i] == MotionType::Static ? SweepExtent{} : sweep_extent(traits[i].shape, local_com[i]);
    }
    // Whether the Continuous stage sweeps the body every step: dynamic and flagged fast
    // (others are swept in the steps that move them far for their size).
    bool is_fast(std::uint32_t i) const { return type[i] == MotionType::Dynamic && traits[i].fast; }
    Mat3 inv_inertia_world(std::uint32_t i) const {
        const Mat3 r = q[i].toRotationMatrix();
        if ((locks[i] & kLockRotation) != 0)
            return locked_inverse_inertia(r * inertia_local[i] * r.transpose(), locks[i]);
        return r * inv_inertia_local[i] * r.transpose();
    }
};

// One touching manifold with what the solver keeps between steps (impulses, for
// warm starting, matched by feature id). The solver computes impulses and approach speeds
// in float lanes (solver/wide.hpp), so they are kept as floats here: the same values, in
// half the bytes. What the narrowphase computes in double (points, separations, the
// normal, the friction impulse it carries over to a new normal) stays double.
struct ContactPoint {
    Vec3 point = Vec3::Zero();  // world, midway between the surfaces when collided (ManifoldPoint::point)
    Real separation = 0;        // as collided, or as a recycled manifold has moved it
    Real base_separation = 0;   // the separation when collided
    float normal_impulse = 0;
    std::uint32_t id = 0;  // feature id (ManifoldPoint::id)
};

struct ContactManifold {
    Vec3 normal = Vec3::UnitY();           // world; fixed while the manifold is recycled
    std::uint32_t part_a = 0, part_b = 0;  // the compound parts that touch (Manifold::part_a, part_b)
    std::uint8_t point_count = 0;
    // The last solved step's push, for hit events (contact_events.cpp): of the points whose
    // normal impulse pushed, the one that approached fastest (-1: none pushed), and its
    // approach speed before solving. Per manifold, not per point: a pile's contacts are
    // most of the memory it holds, and only reporting contacts read it.
    std::int8_t pushed_point = -1;
    float pushed_speed = 0;
    // Friction acts on the manifold as a whole, at the centre of its points (Box3D's
    // central friction): the twist impulse about the normal, and (below) the tangential
    // impulse there (world, in the contact plane), kept for warm starting.
    float twist_impulse = 0;
    // Rolling resistance's angular impulse (world), kept for warm starting; zero unless the
    // contact has rolling resistance.
    float rolling_impulse[3] = {};
    // The factor the last solved step scaled the lower body's inverse mass by in this
    // manifold's rows (support_scales.cpp; 1: none): the impulses above and the points' were
    // solved with it, and are warm started as their push on that body (prepare_wide).
    float support_scale = 1;
    // The round part (sphere, capsule radius; else 0) of each touching shape or part, set
    // when collided, so that recycling and the solver stay off the cold descriptions.
    Real radius_a = 0, radius_b = 0;
    ContactPoint points[kMaxManifoldPoints];
    Vec3 friction_impulse = Vec3::Zero();
};

// What only mesh and compound pairs keep, apart from the record: a pile of convex
// pairs, most of the memory a scene holds, carries one pointer for it per contact.
struct ContactExtra {
    std::vector<ContactManifold> manifolds;  // the manifolds after Contact::manifold
    // A box, hull or compound against a triangle mesh: each triangle's feature, as
    // Contact::feature is for a convex pair (collide_cached).
    TriangleFeatures triangle_features;
    // The same pairs' mesh queries, each part's kept while it stays near where it was, and
    // a compound's parts' manifolds, recycled part by part.
    MeshQueries mesh_queries;
};

// Contact::events: the pair reports events (a body asked, or is a sensor); a body is a
// sensor (the pair exerts no force: no solver rows, no island link).
inline constexpr std::uint8_t kContactReports = 1u << 0;
inline constexpr std::uint8_t kContactSensor = 1u << 1;

// A pair of bodies whose fat bounds overlap. Most of the memory a pile holds: the fields are ordered so that the
// record has no padding, the flags are bits, nothing is kept that the rest gives exactly (B's centre in A's frame
// when collided: cached_position()). Every field has its initializer: create_contacts default-initializes records.
struct Contact {
    std::uint32_t body_a = 0, body_b = 0;  // slots: body_a is the lower (World::contact_keys holds the pair key)
    Real friction = 0, restitution = 0;
    FeatureCache feature;  // the feature that last kept a box or hull pair apart or made its manifold (collide_cached)
    std::uint8_t manifold_count = 0;
    std::uint8_t events = 0;          // kContactReports, kContactSensor (set at creation)
    bool sleeping : 1 = false;        // written by one thread at a time, as every field of a contact
    bool touch_reported : 1 = false;  // touching as last reported by a Begin (an End clears it)
    bool pushed : 1 = false;          // a reporting contact pushed in its last solved step (a Hit starts a push)
    // A shape of the pair is a mesh or a compound as the contact is made (init_contact):
    // recycling asks such pairs whether a turn brought a point into touch
    // (holds_its_features). A shape changed since only makes the question asked or skipped.
    bool meshy : 1 = false;
    // Whether the poses below are those the manifolds were last collided at (both
    // rotations and centres of mass): while the bodies stay close to them the manifolds
    // are recycled, not collided again (narrowphase.cpp).
    bool cached : 1 = false;
    // The larger of the bodies' BodyDesc::rolling_resistance (0: the solver adds no rolling
    // row); in the record's padding before the quaternions, so it costs no bytes.
    float rolling_resistance = 0;
    Quat cached_qa = Quat::Identity(), cached_qb = Quat::Identity();
    // A point's anchors (Box3D's) are its offsets from the centres of mass, world axes: they
    // stay attached to their bodies while the manifolds are recycled, and the solver pushes
    // each body at its own anchor. Kept once per contact rather than twice per point.
    Vec3 cached_xa = Vec3::Zero(), cached_xb = Vec3::Zero();
    ContactManifold manifold;             // the first (and for convex pairs only) manifold
    std::unique_ptr<ContactExtra> extra;  // made by the first collide that needs it (mesh and compound pairs)

    Vec3 anchor_a(const ContactPoint& p) const { return p.point - cached_xa; }
    Vec3 anchor_b(const ContactPoint& p) const { return p.point - cached_xb; }
    // The same expression the narrowphase measures the pair's pose with, on the same
    // values: the same bits it had when collided.
    Vec3 cached_position() const { return cached_qa.conjugate() * (cached_xb - cached_xa); }

    ContactManifold& manifold_at(int i) {
        return i == 0 ? manifold : extra->manifolds[static_cast<std::size_t>(i - 1)];
    }
    const ContactManifold& manifold_at(int i) const {
        return i == 0 ? manifold : extra->manifolds[static_cast<std::size_t>(i - 1)];
    }
    ContactExtra& made_extra() {
        if (!extra) extra = std::make_unique<ContactExtra>();
        return *extra;
    }
};

// A contact's material from its bodies' (when made, and when a body's changes): geometric
// mean friction and the larger restitution, as most engines; the larger rolling
// resistance, as Box3D.
// A pair's coefficients at most this: the solver keeps them in floats, where a coefficient of
// 1e300 is infinite and infinity times a zero impulse is NaN. Beyond 1e9 nothing slides or
// rolls anyway, and a bounce is held to the speed limit (restitution_wide).
inline constexpr Real kMaxMixedMaterial = 1e9;
inline void mix_materials(const BodyTraits& a, const BodyTraits& b, Contact& contact) {
    contact.friction = std::min(std::sqrt(a.friction * b.friction), kMaxMixedMaterial);
    contact.restitution = std::min(std::max(a.restitution, b.restitution), kMaxMixedMaterial);
    contact.rolling_resistance =
        static_cast<float>(std::min(std::max(a.rolling_resistance, b.rolling_resistance), kMaxMixedMaterial));
}

// A contact moved to a removed one's place (remove_contacts).
struct ContactMove {
    std::uint32_t from = 0, to = 0;
};

// The most manifolds one contact keeps: a compound's touching part pairs (a triangle
// mesh keeps fewer, collide_mesh.cpp).
inline constexpr int kMaxContactManifolds = 8;

// A contact's manifolds packed for the solver's listing: the point count of manifold m
// in bits [3m, 3m + 3), whether the contact has restitution (the top bit) and whether it
// has rolling resistance (the bit below).
inline constexpr int kSummaryBitsPerManifold = 3;
inline constexpr std::uint32_t kSummaryRestitution = 1u << 31;
inline constexpr std::uint32_t kSummaryRolls = 1u << 30;
inline constexpr std::uint32_t kSummaryPointCounts = kSummaryRolls - 1;
inline std::uint32_t contact_summary(const Contact& contact) {
    static_assert(kMaxManifoldPoints < (1 << kSummaryBitsPerManifold), "a point count in 3 bits");
    static_assert(kMaxContactManifolds * kSummaryBitsPerManifold < 30, "the point counts below the material bits");
    if ((contact.events & kContactSensor) != 0) return 0;  // a sensor's manifolds push nothing
    std::uint32_t summary = contact.restitution > 0 ? kSummaryRestitution : 0u;
    if (contact.rolling_resistance > 0) summary |= kSummaryRolls;
    for (int m = 0; m < contact.manifold_count; ++m) {
        summary |= static_cast<std::uint32_t>(contact.manifold_at(m).point_count) << (kSummaryBitsPerManifold * m);
    }
    return summary;
}

// Effect counts of one worker in the solver, summed after the step (a sum of counts,
// so the total does not depend on who counted what). Each is bumped in the code that
// does the work, so a count shows what ran, not what a flag promised. A cache line
// each: the workers bump theirs per body and per constraint.
struct alignas(64) EffectCounts {
    std::uint64_t gravity = 0, damping = 0, gyro = 0;  // body-substeps (integrator.cpp)
    std::uint64_t contact_points = 0;                  // point-passes of the normal rows
    std::uint64_t friction = 0;                        // manifold-passes of the central friction rows
    std::uint64_t rolling = 0;                         // manifold-passes of the rolling resistance rows
    std::uint64_t restitution = 0;                     // points checked for a bounce
    std::uint64_t joints = 0;                          // joint-passes
};

// Contacts of one worker in the narrowphase, summed after the stage.
struct alignas(64) ContactCounts {
    std::uint32_t touching = 0, reused = 0, out_of_reach = 0;
    std::uint32_t event_checks = 0;                        // reporting contacts checked for a touch change
    std::uint32_t parts_collided = 0, parts_recycled = 0;  // a compound's parts against a mesh
};

// A sleeping island: its bodies, contacts and joints, kept so one touch wakes them together.
struct SleepingIsland {
    std::vector<std::uint32_t> bodies;
    std::vector<std::uint64_t> contacts;
    std::vector<JointHandle> joints;  // handles: a joint destroyed while asleep is skipped on waking
};

// A body to sweep: its pose when the step began, for the swept test after the solver.
struct FastStart {
    std::uint32_t slot = 0;
    Vec3 x0 = Vec3::Zero();
    Quat q0 = Quat::Identity();
};

// One worker's room in the Continuous stage: the static bodies and mesh triangles a sweep
// meets (kept from its first distance query for the later ones), and the swept tests it
// counted. A cache line apart from the next worker's.
struct alignas(64) SweepScratch {
    std::vector<std::uint32_t> statics;
    std::vector<std::array<Vec3, 4>> triangles;  // a mesh's, in its frame: the corners, then the unit normal
    std::vector<Real> heights;                   // a part's height above each triangle's plane
    std::uint64_t tests = 0;
};

// A kinematic body's target pose (Space::move_kinematic), for the next step to reach.
struct KinematicMove {
    BodyHandle body;
    Vec3 center_of_mass = Vec3::Zero();
    Quat orientation = Quat::Identity();
};

struct World {
    SpaceSettings settings;
    JobSystem* jobs = nullptr;
    std::unique_ptr<JobSystem> own_jobs;  // single-threaded, when none was given

    Bodies bodies;
    std::vector<std::uint32_t> awake;  // awake dynamic and kinematic bodies, ascending slot order
    // Changes to `awake` not yet settled (settle_awake): the bodies woken since, and the
    // lowest position whose body left. Waking or sleeping an island merges them in once
    // instead of shifting the list per body; the stages read `awake` only when settled.
    std::vector<std::uint32_t> awake_pending;
    std::size_t awake_left_from = kNoPosition;

    // Collision: contacts in a deterministic order (creation order from canonical pair
    // lists; removed places taken by the last contacts, remove_contacts).
    std::unique_ptr<BroadphaseState> broadphase;
    // Grown only by create_contacts, whose jobs construct the new records in place.
    std::vector<Contact, PlacedByCallerAllocator<Contact>> contacts;
    ContactIndex contact_index;  // key -> position in contacts
    // contacts[i]'s pair key (body_a << 32 | body_b), packed: a scan reads 8 bytes per contact.
    // Raw room, as the next: create_contacts' jobs write every new element (a first step's
    // were value-initialised by one thread, into fresh pages faulted one by one).
    RawRoomVector<std::uint64_t> contact_keys;
    // contacts[i]'s manifolds in 4 bytes (contact_summary()): what the solver's list of
    // manifolds needs, without reading the contact (the narrowphase writes it).
    RawRoomVector<std::uint32_t> contact_summaries;
    // Positions of the contacts that are not asleep, ascending; rebuilt only after a
    // contact is made, removed, or changes sleep, so sleeping contacts cost nothing per step.
    std::vector<std::uint32_t> awake_contact_list;
    bool awake_contacts_dirty = true;
    std::unique_ptr<SolverScratch> solver;
    // Huge pages stocked for the first step of the level's bodies made since the last update
    // (memory/page_stock.hpp, api/space.cpp), and what sizes them: those dynamic bodies,
    // and the pairs of overlapping fat boxes they made as they were added (the contacts
    // that step makes). A level is built before the first step, or after reserve_bodies
    // until the next (building_level). The update gives back the pages its step did not
    // take, and starts the counts again.
    bool building_level = true;
    std::size_t stocked_pages = 0;
    std::size_t first_step_bodies = 0;
    std::size_t first_step_contacts = 0;
    bool first_step_rolls = false;  // one of those bodies has rolling resistance
    // The game's count of its level's first contacts (SpaceSettings::capacity), before the
    // space's first step; else 0.
    std::size_t told_first_step_contacts() const {
        return steps == 0 ? static_cast<std::size_t>(settings.capacity.contact_count) : 0;
    }
    // The contacts that first step is expected to make: the game's count where it gave one,
    // else the pairs counted.
    std::size_t first_step_contact_count() const {
        const std::size_t told = told_first_step_contacts();
        return told > 0 ? told : first_step_contacts;
    }

    // The layer table: bit b of layer_masks[a] is set when layers a and b collide
    // (symmetric; all set by default, so filtering changes nothing until asked).
    std::array<std::uint32_t, kLayerCount> layer_masks = [] {
        std::array<std::uint32_t, kLayerCount> all{};
        all.fill(~std::uint32_t{0});
        return all;
    }();

    // Contact and sensor events: gathered by the steps, published at the flip, read by the
    // game (stages/contact_events.cpp).
    std::unique_ptr<ContactEvents> events;

    // Joints (api/joint_api.cpp); solved with the contacts, coloured first.
    Joints joints;
    JointTargets joint_targets;                         // motor targets written since the last ApplyWrites
    std::vector<JointTargetWrite> joint_target_writes;  // drained at ApplyWrites (reused)

    // Buffering.
    AccessGate gate;                         // structural calls and updates (api/access_gate.hpp)
    std::atomic<std::size_t> body_count{0};  // bodies.live, for Space::body_count from any thread
    WriteBuffer writes;
    std::vector<PendingWrites> drained;  // reused by ApplyWrites
    MotionStateManager motion_states;
    std::vector<std::uint32_t> changed_now;   // slots whose published state changed outside a step
    std::vector<std::uint32_t> changed_last;  // the same, one flip ago (the back buffer is two flips old)
    // The query scene that goes with published buffer k, updated with it (buffering.cpp);
    // null until the space's first query (query/query_lease.cpp): a space that never
    // queries keeps none. Replaced by a copy while a query holds it.
    std::shared_ptr<QueryScene> query_scenes[2];
    // Set by the first query that found no published scene: from then on each flip builds
    // the scene it publishes if it has none. Any thread.
    std::atomic<bool> queries_wanted{false};
    std::vector<Aabb> scratch_query_bounds;  // per awake body, the flip's tight query boxes

    // Time stepping.
    Real accumulator = 0;
    std::uint64_t steps = 0;
    // now_nanoseconds() at the instant the accumulator was measured up to, when updates
    // follow the real clock (an AsyncRunner's loop sets it); 0 when they do not; the
    // simulated seconds per real second it runs at (the runner's time scale). And the
    // clock that reads naming none blend by (the runner's options).
    std::int64_t update_clock_ns = 0;
    double update_clock_rate = 1;
    BlendClock read_blend = BlendClock::Update;
    // The awake bodies' state version (bumped by every flip after a step, a write or a
    // direct change) and the version each published buffer's awake entries were filled at
    // (buffering.cpp; ~0: never): a flip with nothing new since skips refilling them.
    std::uint64_t awake_version = 0;
    std::uint64_t published_version[2] = {~std::uint64_t{0}, ~std::uint64_t{0}};
    bool published_interpolating[2] = {false, false};
    std::uint64_t body_set_version =
        0;  // bumped when a body is made or destroyed (solver.cpp reuses colours until then)

    UpdateStats stats;
    WorkCounters counters;
    std::vector<EffectCounts> scratch_counts;   // per worker
    std::vector<ContactCounts> contact_counts;  // per worker (narrowphase.cpp)
    // The narrowphase's mesh and compound pairs put aside per worker in its first pass, and
    // all of them for its second (narrowphase.cpp).
    std::vector<std::vector<std::uint32_t>> heavy_contacts;
    std::vector<std::uint32_t> heavy_positions;
    std::vector<CacheLinePadded<std::uint64_t>> publish_counts;  // per worker: interpolated publishes (buffering.cpp)
    RawRoomVector<std::uint32_t> scratch_lost;                   // raw room: a first step's search writes what it keeps
    std::vector<ContactMove> scratch_contact_moves;              // remove_contacts (contact_list.cpp)
    std::vector<std::uint32_t> scratch_moved_awake;              // the same: the moved contacts that are awake
    // Bodies to sweep, listed by the solver's FinalizeBodies jobs, one list per worker
    // (a sweep reads only static bodies and writes only its own, so the lists' order
    // changes nothing); the Continuous stage runs only when one is not empty.
    std::vector<std::vector<FastStart>> fast_lists;
    std::vector<FastStart> fast_starts;  // the lists joined (continuous.cpp)
    // Live bodies flagged fast (create_body, destroy_body): while there are any, the
    // narrowphase collides their pairs every step instead of recycling manifolds.
    std::uint32_t fast_bodies = 0;
    std::vector<SweepScratch> sweep_scratch;     // per worker
    std::vector<KinematicMove> kinematic_moves;  // taken by the next step (stages/body_changes.cpp)

    // Islands.
    std::vector<SleepingIsland> sleeping_islands;
    std::vector<std::int32_t> free_islands;
    std::vector<std::uint32_t> scratch_parent, scratch_sleepers, scratch_awake_tail;
    // Awake positions of (dynamic, kinematic) bodies touching or jointed: the dynamic one's
    // island sleeps only with the kinematic body (islands.cpp).
    std::vector<std::pair<std::uint32_t, std::uint32_t>> scratch_kinematic_links;
    std::vector<std::int32_t> scratch_island_of_root;
    std::vector<Real> scratch_rest;

    World();
    ~World();
};

}  // namespace spindle
