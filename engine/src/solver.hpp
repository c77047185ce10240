// Solver data for one step: constraints built from the touching manifolds, and the
// colours that let each batch run in parallel without two jobs writing one body.
#pragma once

#include <cstdint>
#include <vector>

#include "solver_body.hpp"
#include "world.hpp"

namespace spindle {

// Soft constraint coefficients (Box2D v3's soft step): a spring of `hertz` with a
// damping ratio, expressed for a substep of length h.
struct Softness {
    Real bias_rate = 0;
    Real mass_scale = 1;
    Real impulse_scale = 0;
};
Softness make_softness(Real hertz, Real damping_ratio, Real h);

// One velocity row (normal or tangent) of a contact point, with its angular terms
// precomputed once per step: relative speed = dir.(vb - va) + rb_x.wb - ra_x.wa, and an
// impulse L changes wa by -L ia, wb by +L ib. Saves the cross and 3x3 products that
// every one of the substeps' passes would otherwise redo.
struct ContactRow {
    Vec3 ra_x = Vec3::Zero();  // ra x dir
    Vec3 rb_x = Vec3::Zero();  // rb x dir
    Vec3 ia = Vec3::Zero();    // Ia^-1 (ra x dir)
    Vec3 ib = Vec3::Zero();    // Ib^-1 (rb x dir)
};

struct ConstraintPoint {
    ContactRow normal_row;
    ContactRow tangent_row[2];
    Vec3 ra = Vec3::Zero();  // anchors from each centre of mass, world, fixed for the step
    Vec3 rb = Vec3::Zero();
    Real adjusted_separation = 0;  // separation minus n.(rb - ra): current separation = n.d + this
    Real normal_mass = 0;
    Real tangent_mass[2] = {0, 0};
    Real normal_impulse = 0;
    Real tangent_impulse[2] = {0, 0};
    Real max_normal_impulse = 0;
    Real relative_velocity = 0;
};

// One manifold as the solver sees it. a and b index the step's solver bodies; static
// and sleeping partners share one immovable body at the end of that array.
struct ContactConstraint {
    std::uint32_t a = 0, b = 0;
    std::uint32_t contact = 0;
    int manifold = 0;
    Vec3 normal = Vec3::UnitY();
    Vec3 tangent[2] = {Vec3::UnitX(), Vec3::UnitZ()};
    Real friction = 0, restitution = 0;
    Real gravity_normal = 0;  // relative acceleration of B from A along the normal, from gravity
    int point_count = 0;
    ConstraintPoint points[kMaxManifoldPoints];
};

inline constexpr int kColorCount = 24;

struct SolverScratch {
    std::vector<SolverBody> bodies;                 // awake bodies, then the static body
    std::vector<ContactConstraint> constraints;
    std::vector<std::uint32_t> colors[kColorCount];  // constraint indices per colour
    std::vector<std::uint32_t> overflow;             // constraints that fit no colour, solved serially
    std::vector<std::uint64_t> color_bits[kColorCount];  // per colour: which dynamic bodies it uses
};

}  // namespace spindle
