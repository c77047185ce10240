// Scene building and measuring helpers shared by the hard-case stability tests:
// stacks, energies, and the worst-of-many measurements the pass criteria are written
// in. The static floors and walls are tests/support's, shared with the engine suites.
#pragma once

#include <spindle/engine/space.hpp>
#include <spindle/scheduler/job_system.hpp>

#include "static_bodies.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

namespace spindle::stability {

inline constexpr double kGravity = 9.81;
inline constexpr double kStep = 1.0 / 60.0;

// A space with sleeping off, so every case is solved on every step it claims to run.
std::unique_ptr<Space> make_space(const SpaceSettings& settings = {}, JobSystem* jobs = nullptr);
// A job system with two workers (the suite's budget machine has two cores).
std::unique_ptr<JobSystem> two_workers();

// The ground planes, floors and walls, shared with the engine suites.
using test::add_ground_plane;
using test::add_static_box;
BodyHandle add_box(Space& space, const Vec3& half_extents, const Vec3& position, double mass = 0,
                   double friction = 0.6);
// Unit cubes (half extent 0.5) stacked on a floor whose top is at base.y(), exactly
// touching: box i at base + (0, 0.5 + i, 0). Bottom first.
std::vector<BodyHandle> add_cube_stack(Space& space, int count, const Vec3& base, double spacing = 1.0);

std::vector<Vec3> positions(const Space& space, const std::vector<BodyHandle>& bodies);
// Largest |now - reference| over the bodies.
double max_displacement(const Space& space, const std::vector<BodyHandle>& bodies, const std::vector<Vec3>& reference);
double max_speed(const Space& space, const std::vector<BodyHandle>& bodies);
bool all_finite(const Space& space, const std::vector<BodyHandle>& bodies);

// As create_body computes it: the shape's at the density, scaled to the mass if given.
MassProperties mass_of(const BodyDesc& d);
// Rotational kinetic energy of a dynamic body, from its shape's mass properties.
double rotational_energy(const Space& space, BodyHandle body);

// Kinetic plus potential energy of some dynamic bodies above a floor height, for
// gravity -g along y. Mass properties are taken once.
class EnergyMeter {
public:
    EnergyMeter(const Space& space, std::vector<BodyHandle> bodies, double floor_y, double g = kGravity);
    double operator()(const Space& space) const;

private:
    std::vector<BodyHandle> m_bodies;
    std::vector<MassProperties> m_mass;
    double m_floor_y;
    double m_g;
};

// The deepest penetration between any two of the bodies (static ones included), from
// the narrowphase's own collide(); 0 when nothing overlaps. Pairs are found by bounds.
double deepest_penetration(const Space& space, const std::vector<BodyHandle>& bodies);

struct OverlapRun {
    double worst_speed = 0;              // max over steps and bodies of the end-of-step speed, m/s
    double worst_step_speed = 0;         // max over steps and bodies of |position change| / dt, m/s
    double worst_speed_excess = -kHuge;  // max over steps and bodies of either speed - allowed, m/s
    double final_overlap = 0;            // deepest penetration left at the end, m
    double final_sideways = 0;           // most any body ended up moved sideways (x, z) from its start, m
};
// Steps a scene started overlapping; the speed allowed at time t is the push-out speed
// plus the free-fall speed g t. bodies: the dynamic ones; floor: the static one under them.
// Prints the measurements under the scene's name.
OverlapRun run_overlap_recovery(const char* scene, Space& space, const std::vector<BodyHandle>& bodies,
                                BodyHandle floor, int steps);

}  // namespace spindle::stability
