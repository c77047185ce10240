// Space: construction, body creation (validated first) and destruction,
// settings and reports. The accessors are in accessors.cpp, update() in stages/update.cpp.
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <sstream>
#include <string>

#include "api/describe.hpp"
#include "api/validation.hpp"
#include "memory/page_stock.hpp"
#include "solver/constraints.hpp"
#include "solver/speed_limit.hpp"
#include "stages/body_changes.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/capacity.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"

namespace spindle {

std::string to_string(BodyHandle handle) {
    return "body " + std::to_string(handle.index) + " (generation " + std::to_string(handle.generation) + ")";
}

World::World() = default;
World::~World() { give_back_stocked_huge_pages(stocked_pages); }

namespace {

// At most this many pages are held ahead of an update.
constexpr std::size_t kMostStockedPages = 64;

// The contacts body `slot`'s new proxy will make at the next step: the pairs its fat box
// makes with those already in the trees, which the filter keeps, of which one body is
// dynamic (each pair counted once, by the later of its two bodies). A static body looks
// in the moving tree only: a level of a million static bodies makes no pair among them.
std::size_t new_pairs_of(const World& w, std::uint32_t slot) {
    const BroadphaseState& bp = *w.broadphase;
    const Bodies& b = w.bodies;
    const bool dynamic = b.type[slot] == MotionType::Dynamic;
    std::size_t pairs = 0;
    const auto count = [&](std::uint64_t other) {
        const auto j = static_cast<std::uint32_t>(other);
        if (j != slot && (dynamic || b.type[j] == MotionType::Dynamic) && !filter_blocks_pair(w, slot, j)) pairs += 1;
        return true;
    };
    const Aabb& box = bp.tree.fat_aabb(bp.proxy[slot]);
    if (b.type[slot] == MotionType::Static) {
        const DynamicAabbTree& moving = bp.tree.moving_tree();
        moving.query(box, [&](std::int32_t id) { return count(moving.user(id)); });
    } else {
        bp.tree.query(box, [&](ProxyId id) { return count(bp.tree.user(id)); });
    }
    return pairs;
}

// Stocks the pages the first step of the bodies made since the last update will write
// (first_step_pages, stages/capacity.hpp): here, where the game builds its level, a page at a time, rather
// than in that step. The contacts are the game's count for its level's first step where
// it gave one (SpaceSettings::capacity), else the pairs the new proxies made. A hint: without memory for a page the
// step maps its own.
void stock_first_step_pages(World& w) {
    const std::size_t pages = std::min(
        first_step_pages(w.first_step_bodies, w.first_step_contact_count(), w.first_step_rolls), kMostStockedPages);
    while (w.stocked_pages < pages) {
        try {
            stock_huge_page();
        } catch (const std::bad_alloc&) {
            return;
        }
        w.stocked_pages += 1;
    }
}

// Counts a level's new body `slot` into its first step and stocks that step's pages.
// The game's count of contacts, where it gave one, stands for the level's first: no query.
void count_first_step(World& w, std::uint32_t slot) {
    const std::size_t pairs = w.told_first_step_contacts() > 0 ? 0 : new_pairs_of(w, slot);
    w.first_step_contacts += pairs;
    const bool dynamic = w.bodies.type[slot] == MotionType::Dynamic;
    if (dynamic) w.first_step_bodies += 1;
    w.first_step_rolls = w.first_step_rolls || w.bodies.traits[slot].rolling_resistance > 0;
    // A static floor made after the bodies resting on it brings their contacts.
    if (dynamic || pairs != 0) stock_first_step_pages(w);
}

// By a quarter at a time (stages/capacity.hpp), not doubled: a scene built body by body
// keeps its per-slot arrays near its body count.
template <typename T>
void grow(std::vector<T>& v, std::size_t n) {
    reserve_for(v, n);
    if (v.size() < n) v.resize(n);
}

}  // namespace

Space::Space(const SpaceSettings& settings, JobSystem* jobs) : m_world(std::make_unique<World>()) {
    validate(settings);  // the same checks as each setter's
    m_world->settings = settings;
    if (!jobs) {
        m_world->own_jobs = std::make_unique<SingleThreadedJobSystem>();
        jobs = m_world->own_jobs.get();
    }
    m_world->jobs = jobs;
    m_world->broadphase = std::make_unique<BroadphaseState>();
    m_world->solver = std::make_unique<SolverScratch>();
    m_world->events = std::make_unique<ContactEvents>();
}

Space::~Space() = default;

BodyHandle Space::create_body(const BodyDesc& desc) {
    const AccessGate::Structure access(m_world->gate, "create_body");
    validate(desc);
    World& w = *m_world;
    Bodies& b = w.bodies;
    const Quat orientation = desc.orientation.normalized();
    BodyTraits traits(desc);

    // Mass first: it may throw (e.g. a degenerate shape), and nothing has changed yet.
    const BodyMass mass = body_mass(traits, desc.type, desc.shape, "create_body");
    const Real inv_mass = mass.inv_mass;
    const Mat3& inv_inertia = mass.inv_inertia;
    const Mat3& inertia = mass.inertia;
    const Vec3& local_com = mass.local_com;

    std::uint32_t slot;
    if (!b.free_slots.empty()) {
        slot = b.free_slots.back();
        b.free_slots.pop_back();
    } else {
        slot = b.capacity();
        Bodies::for_each_slot_array(b, [n = std::size_t{slot} + 1](auto& array) { grow(array, n); });
        b.history_place[slot] = kNoHistory;
    }
    b.generation[slot] += 1;
    if (b.generation[slot] == 0) b.generation[slot] = 1;  // 2^32 reuses: skip the invalid generation
    b.alive[slot] = 1;
    b.live += 1;
    b.type[slot] = desc.type;
    b.q[slot] = orientation;
    b.local_com[slot] = local_com;
    b.x[slot] = desc.position + orientation * local_com;
    const SolverSettings& limits = w.settings.solver;
    b.locks[slot] = desc.type == MotionType::Static ? 0 : lock_bits(desc.locks);
    b.v[slot] = desc.type == MotionType::Static
                    ? Vec3::Zero()
                    : limit_speed(project_linear(desc.linear_velocity, b.locks[slot]), limits.max_linear_speed);
    b.w[slot] = desc.type == MotionType::Static
                    ? Vec3::Zero()
                    : limit_speed(project_angular(desc.angular_velocity, b.locks[slot]), limits.max_angular_speed);
    b.inv_mass[slot] = inv_mass;
    b.inv_inertia_local[slot] = inv_inertia;
    b.inertia_local[slot] = inertia;
    b.elongated[slot] = mass.elongated ? 1 : 0;
    b.force[slot] = Vec3::Zero();
    b.torque[slot] = Vec3::Zero();
    b.awake_index[slot] = -1;
    b.sleep_time[slot] = 0;
    b.island[slot] = -1;
    b.interpolate[slot] = desc.allow_interpolation ? 1 : 0;
    b.layer[slot] = static_cast<std::uint8_t>(desc.layer);
    b.group[slot] = desc.group;
    if (desc.type != MotionType::Static) b.hold_history(slot, desc.position, orientation);
    b.traits[slot] = std::move(traits);
    b.bounds[slot] = b.traits[slot].shape.bounds(b.transform(slot));
    b.remake_extent(slot);
    if (b.is_fast(slot)) w.fast_bodies += 1;
    add_proxy(w, slot);
    if (b.type[slot] != MotionType::Static) set_awake(w, slot, true);
    w.body_set_version += 1;
    w.body_count.store(b.live, std::memory_order_release);
    publish_now(w, slot);
    if (w.building_level) count_first_step(w, slot);
    return BodyHandle{slot, b.generation[slot]};
}

void Space::reserve_bodies(std::size_t count) {
    const AccessGate::Structure access(m_world->gate, "reserve_bodies");
    // A body handle's slot index is 32 bits.
    constexpr std::size_t kMostBodies = std::numeric_limits<std::uint32_t>::max();
    if (count > kMostBodies) {
        throw Error("reserve_bodies: count " + std::to_string(count) + " is more than a space can hold (" +
                    std::to_string(kMostBodies) + ")");
    }
    World& w = *m_world;
    const auto room = [count](auto& array) {
        if (array.capacity() < count) array.reserve(count);
    };
    try {
        Bodies::for_each_slot_array(w.bodies, room);
        room(w.awake);
        room(w.awake_pending);
        room(w.broadphase->proxy);
        room(w.broadphase->refit);
        room(w.broadphase->last_velocity);
        reserve_published(w, count);
    } catch (const std::bad_alloc&) {
        // Only capacities changed: every body, handle and published state is as it was.
        throw Error("reserve_bodies: no memory for " + std::to_string(count) + " bodies");
    }
    w.building_level = true;
}

void Space::destroy_body(BodyHandle body) {
    const AccessGate::Structure access(m_world->gate, "destroy_body");
    World& w = *m_world;
    if (!w.bodies.is_live(body))
        throw Error("destroy_body: " + to_string(body) + " is not a live body (stale or foreign handle)");
    const std::uint32_t slot = body.index;
    // Wake the body's island (its member list must not keep a dead slot) and every island
    // it touches, even if the body is static: what rested on it may fall.
    wake_touching(w, slot);
    destroy_joints_of(w, slot);
    remove_contacts_of(w, slot);
    remove_proxy(w, slot);
    if (w.bodies.awake_index[slot] >= 0) set_awake(w, slot, false);
    if (w.bodies.is_fast(slot)) w.fast_bodies -= 1;
    w.bodies.alive[slot] = 0;
    w.bodies.live -= 1;
    w.bodies.traits[slot] = BodyTraits{};  // drop the shape's geometry now
    w.bodies.free_slots.push_back(slot);
    w.body_set_version += 1;
    w.body_count.store(w.bodies.live, std::memory_order_release);
    publish_now(w, slot);
}

// Lock-free: a slot's published generation is exact (creation and destruction publish
// at once), so these are safe from any thread while the physics thread updates.
bool Space::contains(BodyHandle body) const noexcept {
    return body.generation != 0 && m_world->motion_states.published_generation(body.index) == body.generation;
}
std::size_t Space::body_count() const noexcept { return m_world->body_count.load(std::memory_order_acquire); }

// ---- settings and reports ----

const SpaceSettings& Space::settings() const noexcept { return m_world->settings; }

// Each setter checks with the constructor's function for its struct (api/validation.cpp).
void Space::set_time_step(const TimeStepSettings& s) {
    const AccessGate::Structure access(m_world->gate, "set_time_step");
    validate(s);
    m_world->settings.time_step = s;
}

void Space::set_solver(const SolverSettings& s) {
    const AccessGate::Structure access(m_world->gate, "set_solver");
    validate(s);
    m_world->settings.solver = s;
}

void Space::set_sleep(const SleepSettings& s) {
    const AccessGate::Structure access(m_world->gate, "set_sleep");
    validate(s);
    m_world->settings.sleep = s;
}

void Space::set_gravity(const Vec3& gravity) {
    const AccessGate::Structure access(m_world->gate, "set_gravity");
    validate_gravity(gravity);
    m_world->settings.gravity = gravity;
}

void Space::set_layers_collide(std::uint32_t a, std::uint32_t b, bool collide) {
    const AccessGate::Structure access(m_world->gate, "set_layers_collide");
    check_layer(a, "set_layers_collide", "a");
    check_layer(b, "set_layers_collide", "b");
    World& w = *m_world;
    if (spindle::layers_collide(w, a, b) == collide) return;
    const std::uint32_t bit_a = 1u << a, bit_b = 1u << b;
    w.layer_masks[a] = collide ? (w.layer_masks[a] | bit_b) : (w.layer_masks[a] & ~bit_b);
    w.layer_masks[b] = collide ? (w.layer_masks[b] | bit_a) : (w.layer_masks[b] & ~bit_a);
    refilter_all(w);
}

bool Space::layers_collide(std::uint32_t a, std::uint32_t b) const {
    const AccessGate::Structure access(m_world->gate, "layers_collide");
    check_layer(a, "layers_collide", "a");
    check_layer(b, "layers_collide", "b");
    return spindle::layers_collide(*m_world, a, b);
}

const UpdateStats& Space::last_update() const noexcept { return m_world->stats; }
const WorkCounters& Space::counters() const noexcept { return m_world->counters; }
Real Space::accumulated_time() const noexcept { return m_world->accumulator; }
JobSystem& Space::jobs() noexcept { return *m_world->jobs; }
MotionStateManager& Space::motion_states() noexcept { return m_world->motion_states; }
const MotionStateManager& Space::motion_states() const noexcept { return m_world->motion_states; }

std::uint64_t Space::state_hash() const {
    const AccessGate::Structure access(m_world->gate, "state_hash");
    const Bodies& b = m_world->bodies;
    std::uint64_t hash = 1469598103934665603ull;
    auto mix = [&hash](const void* data, std::size_t size) {
        const auto* bytes = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 1099511628211ull;
    };
    for (std::uint32_t i = 0; i < b.capacity(); ++i) {
        if (!b.alive[i]) continue;
        mix(b.x[i].data(), sizeof(Real) * 3);
        mix(b.q[i].coeffs().data(), sizeof(Real) * 4);
    }
    return hash;
}

}  // namespace spindle
