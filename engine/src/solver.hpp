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
    // Push-out of deep overlap (split impulse): one row through the overlap's centre,
    // on the push-out velocities; the impulse is kept over the step's substeps.
    ContactRow push_row;
    Real push_impulse = 0;
};

using Vec2 = Eigen::Matrix<Real, 2, 1>;
using Mat2 = Eigen::Matrix<Real, 2, 2>;

// One joint as the solver sees it for a step (joint_solver.cpp): frames turned into
// world at the step's start (the substeps rotate them by each body's dq), and the
// accumulated impulses (warm started from Joint).
struct JointConstraint {
    std::uint32_t a = 0, b = 0;  // solver bodies, as for contacts
    std::uint32_t joint = 0;     // slot in world.joints
    JointType type = JointType::BallSocket;
    Vec3 ra = Vec3::Zero();      // anchors from each centre of mass, world
    Vec3 rb = Vec3::Zero();
    Vec3 delta_center = Vec3::Zero();  // B's centre of mass minus A's

    // Hinge: A's axis, two perpendiculars of B's axis (the alignment rows), angle references.
    Vec3 axis_a = Vec3::UnitZ();
    Vec3 perp_b[2] = {Vec3::UnitX(), Vec3::UnitY()};
    Vec3 ref_a = Vec3::UnitX(), ref_b = Vec3::UnitX();
    // Fixed: the rotation that takes B's target orientation to its actual one, world.
    Quat rotation_error = Quat::Identity();
    Mat3 rotation_mass = Mat3::Zero();
    // Effective masses of the other rows are computed as they are solved, from the
    // frames then: a light body can turn far within one step.
    Vec3 axis = Vec3::UnitX();  // distance: direction at the step's start (if the anchors meet)
    Softness spring;            // distance spring

    // Parameters, copied so the hot loop reads one struct.
    bool enable_limit = false, enable_motor = false, enable_spring = false;
    Real lower = 0, upper = 0;  // hinge angles or distance lengths
    Real rest_length = 0;
    Real motor_speed = 0, max_motor_impulse = 0;
    Real spring_hertz = 0;

    // Accumulated impulses.
    Vec3 linear_impulse = Vec3::Zero();
    Vec3 angular_impulse = Vec3::Zero();  // fixed
    Vec2 align_impulse = Vec2::Zero();    // hinge, along the two alignment rows
    Real axial_impulse = 0, motor_impulse = 0, lower_impulse = 0, upper_impulse = 0;
};

// How joints are solved in one pass: soft position correction with use_bias, none
// (relax) without.
struct JointSolveParams {
    Softness soft;
    Real inv_h = 0;
    bool use_bias = true;
};

inline constexpr int kColorCount = 24;

struct SolverScratch {
    std::vector<SolverBody> bodies;                 // awake bodies, then the static body
    std::vector<ContactConstraint> constraints;
    std::vector<std::uint32_t> colors[kColorCount];  // constraint indices per colour
    std::vector<std::uint32_t> overflow;             // constraints that fit no colour, solved serially
    std::vector<JointConstraint> joints;             // awake joints, in slot order
    std::vector<std::uint32_t> joint_colors[kColorCount];  // joint indices per colour (coloured first)
    std::vector<std::uint32_t> joint_overflow;
    std::vector<std::uint64_t> color_bits[kColorCount];  // per colour: which dynamic bodies it uses
};

// joint_solver.cpp. prepare_joints lists the awake joints (nothing when there are
// none) and prepares them from the bodies of scratch; the others run per joint from
// the colour loops, so a joint only touches its own two solver bodies.
Softness joint_softness(const SolverSettings& settings, Real h);  // joint_hertz, capped; 0: the cap
void prepare_joints(World& world, SolverScratch& scratch, Real h);
void warm_start_joint(JointConstraint& jc, SolverBody* bodies);
void solve_joint(JointConstraint& jc, SolverBody* bodies, const JointSolveParams& params);
void store_joint_impulses(World& world, SolverScratch& scratch);

}  // namespace spindle
