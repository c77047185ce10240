// Scene building and measuring helpers for the stability tests.
#include "scene_util.hpp"

#include <spindle/platform/topology.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "collision/collide.hpp"

namespace spindle::stability {

MassProperties mass_of(const BodyDesc& d) {
    MassProperties mp = d.shape.mass_properties(d.density);
    if (d.mass > 0) {
        mp.inertia *= d.mass / mp.mass;
        mp.mass = d.mass;
    }
    return mp;
}

namespace {}  // namespace

std::unique_ptr<Space> make_space(const SpaceSettings& settings, JobSystem* jobs) {
    SpaceSettings s = settings;
    s.sleep.enabled = false;
    return std::make_unique<Space>(s, jobs);
}

std::unique_ptr<JobSystem> two_workers() {
    const Topology machine = Topology::from_system();
    WorkStealingJobSystem::Options options;
    for (unsigned i = 0; i < 2; ++i) options.worker_pus.push_back(machine.pus()[i % machine.pus().size()].os_index);
    options.pin = machine.pus().size() >= 2;
    return std::make_unique<WorkStealingJobSystem>(options);
}

BodyHandle add_box(Space& space, const Vec3& half_extents, const Vec3& position, double mass, double friction) {
    BodyDesc d;
    d.shape = Shape::box(half_extents);
    d.position = position;
    d.mass = mass;
    d.friction = friction;
    return space.create_body(d);
}

std::vector<BodyHandle> add_cube_stack(Space& space, int count, const Vec3& base, double spacing) {
    std::vector<BodyHandle> boxes;
    for (int i = 0; i < count; ++i)
        boxes.push_back(add_box(space, Vec3::Constant(0.5), base + Vec3(0, 0.5 + i * spacing, 0)));
    return boxes;
}

std::vector<Vec3> positions(const Space& space, const std::vector<BodyHandle>& bodies) {
    std::vector<Vec3> out;
    out.reserve(bodies.size());
    for (BodyHandle b : bodies) out.push_back(space.internal_position(b));
    return out;
}

double max_displacement(const Space& space, const std::vector<BodyHandle>& bodies, const std::vector<Vec3>& reference) {
    double worst = 0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        worst = std::max(worst, (space.internal_position(bodies[i]) - reference[i]).norm());
    }
    return worst;
}

double max_speed(const Space& space, const std::vector<BodyHandle>& bodies) {
    double worst = 0;
    for (BodyHandle b : bodies) worst = std::max(worst, space.internal_linear_velocity(b).norm());
    return worst;
}

bool all_finite(const Space& space, const std::vector<BodyHandle>& bodies) {
    for (BodyHandle b : bodies) {
        const MotionState s = space.internal_motion_state(b);
        if (!is_finite(s.position) || !is_finite(s.orientation) || !is_finite(s.linear_velocity) ||
            !is_finite(s.angular_velocity)) {
            return false;
        }
    }
    return true;
}

double rotational_energy(const Space& space, BodyHandle body) {
    const MassProperties mp = mass_of(space.internal_desc(body));
    const Mat3 r = space.internal_orientation(body).toRotationMatrix();
    const Vec3 w = space.internal_angular_velocity(body);
    return 0.5 * w.dot(r * mp.inertia * r.transpose() * w);
}

EnergyMeter::EnergyMeter(const Space& space, std::vector<BodyHandle> bodies, double floor_y, double g)
    : m_bodies(std::move(bodies)), m_floor_y(floor_y), m_g(g) {
    for (BodyHandle b : m_bodies) m_mass.push_back(mass_of(space.internal_desc(b)));
}

double EnergyMeter::operator()(const Space& space) const {
    double total = 0;
    for (std::size_t i = 0; i < m_bodies.size(); ++i) {
        const MotionState s = space.internal_motion_state(m_bodies[i]);
        const Mat3 r = s.orientation.toRotationMatrix();
        total += 0.5 * m_mass[i].mass * s.linear_velocity.squaredNorm() +
                 0.5 * s.angular_velocity.dot(r * m_mass[i].inertia * r.transpose() * s.angular_velocity) +
                 m_mass[i].mass * m_g * (s.center_of_mass.y() - m_floor_y);
    }
    return total;
}

double deepest_penetration(const Space& space, const std::vector<BodyHandle>& bodies) {
    std::vector<Transform> poses;
    std::vector<Aabb> bounds;
    for (BodyHandle b : bodies) {
        poses.push_back({space.internal_position(b), space.internal_orientation(b)});
        bounds.push_back(space.internal_desc(b).shape.bounds(poses.back()));
    }
    double deepest = 0;
    Manifold found[4];
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        for (std::size_t j = i + 1; j < bodies.size(); ++j) {
            if (!bounds[i].overlaps(bounds[j])) continue;
            const int n = collide(space.internal_desc(bodies[i]).shape, poses[i], space.internal_desc(bodies[j]).shape,
                                  poses[j], 0, found, 4);
            for (int m = 0; m < n; ++m) {
                for (int k = 0; k < found[m].point_count; ++k)
                    deepest = std::max(deepest, -found[m].points[k].separation);
            }
        }
    }
    return deepest;
}

OverlapRun run_overlap_recovery(const char* scene, Space& space, const std::vector<BodyHandle>& bodies,
                                BodyHandle floor, int steps) {
    const double push_out = space.settings().solver.push_out_speed;
    const double dt = space.settings().time_step.duration;
    OverlapRun run;
    const std::vector<Vec3> start = positions(space, bodies);
    std::vector<Vec3> before = start;
    for (int step = 1; step <= steps; ++step) {
        space.update();
        const double allowed = push_out + kGravity * step * dt;
        for (std::size_t i = 0; i < bodies.size(); ++i) {
            const Vec3 p = space.internal_position(bodies[i]);
            const double v = space.internal_linear_velocity(bodies[i]).norm();
            const double moved = (p - before[i]).norm() / dt;
            run.worst_speed = std::max(run.worst_speed, v);
            run.worst_step_speed = std::max(run.worst_step_speed, moved);
            run.worst_speed_excess = std::max(run.worst_speed_excess, std::max(v, moved) - allowed);
            before[i] = p;
        }
    }
    std::vector<BodyHandle> all = bodies;
    all.push_back(floor);
    run.final_overlap = deepest_penetration(space, all);
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        const Vec3 d = space.internal_position(bodies[i]) - start[i];
        run.final_sideways = std::max(run.final_sideways, std::hypot(d.x(), d.z()));
    }
    std::printf("[ measure  ] %s (%zu boxes): worst end-of-step speed %.3f m/s, from position change %.3f m/s, worst "
                "excess over push-out + g t %.3f m/s; deepest overlap at the end %.4f m; most moved sideways %.4f m\n",
                scene, bodies.size(), run.worst_speed, run.worst_step_speed, run.worst_speed_excess, run.final_overlap,
                run.final_sideways);
    return run;
}

}  // namespace spindle::stability
