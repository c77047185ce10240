// Space: construction, body creation (validated first) and destruction,
// settings and reports. The accessors are in accessors.cpp, update() in stages/update.cpp.
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <cmath>
#include <cstring>
#include <sstream>

#include "api/describe.hpp"
#include "solver/constraints.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {

std::string to_string(BodyHandle handle) {
    return "body " + std::to_string(handle.index) + " (generation " + std::to_string(handle.generation) + ")";
}

World::World() = default;
World::~World() = default;

namespace {

[[noreturn]] void reject(const std::string& what) { throw Error("create_body: " + what); }

void check_finite(const Vec3& v, const char* field) {
    if (!is_finite(v)) reject(std::string(field) + " must be finite, got " + vec(v));
}

void check_non_negative(Real value, const char* field) {
    if (!std::isfinite(value) || value < 0)
        reject(std::string(field) + " must be finite and >= 0, got " + number(value));
}

// Everything create_body needs to know is valid, checked before anything changes.
void validate(const BodyDesc& d) {
    check_finite(d.position, "position");
    if (!is_finite(d.orientation) || d.orientation.norm() < 1e-9) {
        reject("orientation must be a finite, non-zero quaternion, got (w " + number(d.orientation.w()) + ", " +
               vec(d.orientation.vec()) + ")");
    }
    check_finite(d.linear_velocity, "linear_velocity");
    check_finite(d.angular_velocity, "angular_velocity");
    if (d.shape.static_only() && d.type != MotionType::Static) {
        reject(std::string("a ") + to_string(d.shape.type) + " shape can only belong to a static body");
    }
    if (d.type == MotionType::Dynamic) {
        if (!std::isfinite(d.mass) || d.mass < 0) reject("mass must be positive, got " + number(d.mass));
        if (d.mass == 0 && (!std::isfinite(d.density) || d.density <= 0)) {
            reject("density must be positive when mass is 0, got " + number(d.density));
        }
    }
    check_non_negative(d.friction, "friction");
    check_non_negative(d.restitution, "restitution");
    check_non_negative(d.linear_damping, "linear_damping");
    check_non_negative(d.angular_damping, "angular_damping");
    if (!std::isfinite(d.gravity_scale)) reject("gravity_scale must be finite, got " + number(d.gravity_scale));
}

template <typename T>
void grow(std::vector<T>& v, std::size_t n) {
    if (v.size() < n) v.resize(n);
}

}  // namespace

Space::Space(const SpaceSettings& settings, JobSystem* jobs) : m_world(std::make_unique<World>()) {
    m_world->settings = settings;
    set_time_step(settings.time_step);
    if (!jobs) {
        m_world->own_jobs = std::make_unique<SingleThreadedJobSystem>();
        jobs = m_world->own_jobs.get();
    }
    m_world->jobs = jobs;
    m_world->broadphase = std::make_unique<BroadphaseState>();
    m_world->solver = std::make_unique<SolverScratch>();
}

Space::~Space() = default;

BodyHandle Space::create_body(const BodyDesc& input) {
    validate(input);
    World& w = *m_world;
    Bodies& b = w.bodies;
    BodyDesc desc = input;
    desc.orientation.normalize();

    // Mass first: it may throw (e.g. a degenerate shape), and nothing has changed yet.
    Real inv_mass = 0;
    Mat3 inv_inertia = Mat3::Zero();
    Mat3 inertia = Mat3::Zero();
    Vec3 local_com = Vec3::Zero();
    if (desc.type == MotionType::Dynamic) {
        MassProperties mp = desc.shape.mass_properties(desc.density);
        if (desc.mass > 0) {
            mp.inertia *= desc.mass / mp.mass;
            mp.mass = desc.mass;
        }
        if (!(mp.mass > 0) || !mp.inertia.allFinite()) reject("the shape has no volume (mass " + number(mp.mass) + ")");
        inv_mass = 1 / mp.mass;
        inv_inertia = mp.inertia.inverse();
        inertia = mp.inertia;
        local_com = mp.center_of_mass;
    } else if (desc.shape.type != ShapeType::Plane && desc.shape.type != ShapeType::TriangleMesh) {
        local_com = Vec3::Zero();
    }

    std::uint32_t slot;
    if (!b.free_slots.empty()) {
        slot = b.free_slots.back();
        b.free_slots.pop_back();
    } else {
        slot = b.capacity();
        const std::size_t n = slot + 1;
        b.generation.push_back(0);
        b.alive.push_back(0);
        grow(b.type, n), grow(b.x, n), grow(b.q, n), grow(b.v, n), grow(b.w, n), grow(b.inv_mass, n);
        grow(b.inv_inertia_local, n), grow(b.inertia_local, n), grow(b.local_com, n), grow(b.force, n),
            grow(b.torque, n), grow(b.bounds, n);
        grow(b.awake_index, n), grow(b.sleep_time, n), grow(b.island, n), grow(b.interpolate, n);
        grow(b.history_position[0], n), grow(b.history_position[1], n);
        grow(b.history_orientation[0], n), grow(b.history_orientation[1], n), grow(b.desc, n);
    }
    b.generation[slot] += 1;
    if (b.generation[slot] == 0) b.generation[slot] = 1;  // 2^32 reuses: skip the invalid generation
    b.alive[slot] = 1;
    b.live += 1;
    b.type[slot] = desc.type;
    b.q[slot] = desc.orientation;
    b.local_com[slot] = local_com;
    b.x[slot] = desc.position + desc.orientation * local_com;
    b.v[slot] = desc.type == MotionType::Static ? Vec3::Zero() : desc.linear_velocity;
    b.w[slot] = desc.type == MotionType::Static ? Vec3::Zero() : desc.angular_velocity;
    b.inv_mass[slot] = inv_mass;
    b.inv_inertia_local[slot] = inv_inertia;
    b.inertia_local[slot] = inertia;
    b.force[slot] = Vec3::Zero();
    b.torque[slot] = Vec3::Zero();
    b.awake_index[slot] = -1;
    b.sleep_time[slot] = 0;
    b.island[slot] = -1;
    b.interpolate[slot] = desc.allow_interpolation ? 1 : 0;
    for (int k = 0; k < 2; ++k) {
        b.history_position[k][slot] = desc.position;
        b.history_orientation[k][slot] = desc.orientation;
    }
    b.desc[slot] = std::move(desc);
    b.bounds[slot] = b.desc[slot].shape.bounds(b.transform(slot));
    add_proxy(w, slot);
    if (b.type[slot] != MotionType::Static) set_awake(w, slot, true);
    w.changed_now.push_back(slot);
    w.body_set_version += 1;
    publish_now(w, slot);
    return BodyHandle{slot, b.generation[slot]};
}

void Space::destroy_body(BodyHandle body) {
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
    w.bodies.alive[slot] = 0;
    w.bodies.live -= 1;
    w.bodies.desc[slot] = BodyDesc{};  // drop the shape's geometry now
    w.bodies.free_slots.push_back(slot);
    w.changed_now.push_back(slot);
    w.body_set_version += 1;
    publish_now(w, slot);
}

bool Space::contains(BodyHandle body) const noexcept { return m_world->bodies.is_live(body); }
std::size_t Space::body_count() const noexcept { return m_world->bodies.live; }

// ---- settings and reports ----

const SpaceSettings& Space::settings() const noexcept { return m_world->settings; }

void Space::set_time_step(const TimeStepSettings& s) {
    if (!std::isfinite(s.duration) || s.duration <= 0) {
        throw Error("time step: duration must be positive, got " + number(s.duration));
    }
    if (s.max_steps_per_frame < 1) {
        throw Error("time step: max_steps_per_frame must be at least 1, got " + std::to_string(s.max_steps_per_frame));
    }
    if (s.min_steps_per_frame < 0 || s.min_steps_per_frame > s.max_steps_per_frame) {
        throw Error("time step: min_steps_per_frame must be in [0, max_steps_per_frame], got " +
                    std::to_string(s.min_steps_per_frame));
    }
    m_world->settings.time_step = s;
}

void Space::set_solver(const SolverSettings& s) {
    if (s.substeps < 1) throw Error("solver: substeps must be at least 1, got " + std::to_string(s.substeps));
    if (s.iterations < 1) throw Error("solver: iterations must be at least 1, got " + std::to_string(s.iterations));
    if (s.relax_iterations < 0) {
        throw Error("solver: relax_iterations must be >= 0, got " + std::to_string(s.relax_iterations));
    }
    if (!(s.contact_hertz >= 0) || !(s.damping_ratio >= 0) || !(s.push_out_speed >= 0) || !(s.recovery_depth >= 0) ||
        !(s.speculative_distance >= 0) || !(s.restitution_threshold >= 0)) {
        throw Error("solver: contact_hertz, damping_ratio, push_out_speed, recovery_depth, speculative_distance and "
                    "restitution_threshold must be >= 0");
    }
    if (!(s.joint_hertz >= 0) || !std::isfinite(s.joint_hertz) || !(s.joint_damping_ratio >= 0)) {
        throw Error("solver: joint_hertz and joint_damping_ratio must be finite and >= 0");
    }
    m_world->settings.solver = s;
}

void Space::set_sleep(const SleepSettings& s) { m_world->settings.sleep = s; }

void Space::set_gravity(const Vec3& gravity) {
    if (!is_finite(gravity)) throw Error("gravity must be finite, got " + vec(gravity));
    m_world->settings.gravity = gravity;
}

const UpdateStats& Space::last_update() const noexcept { return m_world->stats; }
const WorkCounters& Space::counters() const noexcept { return m_world->counters; }
Real Space::accumulated_time() const noexcept { return m_world->accumulator; }
JobSystem& Space::jobs() noexcept { return *m_world->jobs; }
MotionStateManager& Space::motion_states() noexcept { return m_world->motion_states; }
const MotionStateManager& Space::motion_states() const noexcept { return m_world->motion_states; }

std::uint64_t Space::state_hash() const {
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
