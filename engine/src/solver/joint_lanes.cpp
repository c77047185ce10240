// Joints eight at a time: each colour's ball-socket, swing-twist and hinge joints are
// packed kLanes to a WideJoint, one type to a block, and solved together in floats
// (wide.hpp), gathering their bodies as the contact solver does (body_lanes.hpp). Every
// block has the point row of solve_point (joint_solver.cpp): the anchors, turned by the
// substeps' rotations, coincide, as one soft 3x3 block with its effective mass from the
// anchors now; a swing-twist or hinge block solves its angular rows before it, as the
// scalar joints do. Joints of a body with motion locks stay in the colours' joint lists
// (their masses are pseudo-inverses), as do the other types.
#include <array>

#include "solver/joint_lanes.hpp"

namespace spindle {
namespace {

// The types solved in lanes.
constexpr std::array<JointType, 3> kLaneTypes = {JointType::BallSocket, JointType::SwingTwist, JointType::Hinge};

int lane_type(const JointConstraint& jc, const SolverBody* bodies) {
    if (has_locks(bodies[jc.a], bodies[jc.b])) return -1;
    for (std::size_t t = 0; t < kLaneTypes.size(); ++t) {
        if (jc.type == kLaneTypes[t]) return static_cast<int>(t);
    }
    return -1;
}

// r x (I (r x .)) as a matrix: skew(r) I skew(r)^T, symmetric for a symmetric I.
WideSym3 lever_term(const WideSym3& I, const Wide3& r) {
    const Wide x = r.x, y = r.y, z = r.z;
    // Rows of skew(r) I.
    const Wide s00 = y * I.xz - z * I.xy, s01 = y * I.yz - z * I.yy, s02 = y * I.zz - z * I.yz;
    const Wide s10 = z * I.xx - x * I.xz, s11 = z * I.xy - x * I.yz, s12 = z * I.xz - x * I.zz;
    const Wide s20 = x * I.xy - y * I.xx, s21 = x * I.yy - y * I.xy;
    return {y * s02 - z * s01, z * s00 - x * s02, x * s01 - y * s00,
            z * s10 - x * s12, x * s11 - y * s10, x * s21 - y * s20};
}

// K^-1 v for the lanes' symmetric positive definite K (0 where K is: an empty lane).
// Solved scaled by K's trace, so that the determinant of a heavy pair's tiny K stays
// far from float's smallest numbers.
Wide3 solve_symmetric(const WideSym3& k, const Wide3& v) {
    const Wide zero = splat(0);
    const Wide trace = k.xx + k.yy + k.zz;
    const Wide scale = select(trace > zero, splat(1) / trace, zero);
    const Wide xx = k.xx * scale, xy = k.xy * scale, xz = k.xz * scale;
    const Wide yy = k.yy * scale, yz = k.yz * scale, zz = k.zz * scale;
    const Wide c00 = yy * zz - yz * yz, c01 = xz * yz - xy * zz, c02 = xy * yz - xz * yy;
    const Wide c11 = xx * zz - xz * xz, c12 = xy * xz - xx * yz, c22 = xx * yy - xy * xy;
    const Wide det = xx * c00 + xy * c01 + xz * c02;
    const Wide inv = select(det > zero, scale / det, zero);
    return {inv * (c00 * v.x + c01 * v.y + c02 * v.z), inv * (c01 * v.x + c11 * v.y + c12 * v.z),
            inv * (c02 * v.x + c12 * v.y + c22 * v.z)};
}

// Room for a turned inverse inertia, written only where a lane's body turns it (a WideSym3
// starts at zero: filling two at every solve would cost more than most joints' turning).
union TurnedInertia {
    TurnedInertia() {}
    WideSym3 value;
};

// `turned_inertia` holds the inverse inertias turned by the lanes' rotations where the
// motion refers to them (it must outlive the motion).
[[gnu::always_inline]] inline WideMotion gather_motion(const WideJoint& wj, const SolverBody* bodies,
                                                       TurnedInertia (&turned_inertia)[2]) {
    Wide ma[kLanes], mb[kLanes];
    gather_rows(bodies, wj.a, kMotionRow, ma);
    gather_rows(bodies, wj.b, kMotionRow, mb);
    const WideQuat dqa{{ma[3], ma[4], ma[5]}, ma[6]}, dqb{{mb[3], mb[4], mb[5]}, mb[6]};
    if (wj.turns_a) turned_inertia[0].value = turned(wj.inv_inertia_a, dqa);
    if (wj.turns_b) turned_inertia[1].value = turned(wj.inv_inertia_b, dqb);
    return {{ma[0], ma[1], ma[2]},
            {mb[0], mb[1], mb[2]},
            dqa,
            dqb,
            wj.turns_a ? turned_inertia[0].value : wj.inv_inertia_a,
            wj.turns_b ? turned_inertia[1].value : wj.inv_inertia_b};
}

// An impulse at the anchors: -impulse on A, +impulse on B.
inline void apply(const WideJoint& wj, const WideMotion& m, WideVelocities& s, const Wide3& ra, const Wide3& rb,
                  const Wide3& impulse) {
    s.va -= wj.inv_mass_a * impulse;
    s.wa -= m.inv_inertia_a * cross(ra, impulse);
    s.vb += wj.inv_mass_b * impulse;
    s.wb += m.inv_inertia_b * cross(rb, impulse);
}

// The point row, after the type's angular rows.
void solve_point(WideJoint& wj, WideVelocities& s, const WideMotion& m, const JointSolveParams& params) {
    const Softness soft = pass_softness(params);
    const Wide3 ra = rotate(m.dqa, wj.ra), rb = rotate(m.dqb, wj.rb);
    // Current separation of the anchors, from small deltas (exact far from the origin).
    const Wide3 c = (m.dpb - m.dpa) + (rb - ra) + wj.delta_center;
    const Wide3 cdot = point_velocity(s, ra, rb);
    // K from the anchors now: a light link can turn far within a step, and a mass from
    // the step's start would then overshoot.
    WideSym3 k = lever_term(m.inv_inertia_a, ra);
    const WideSym3 kb = lever_term(m.inv_inertia_b, rb);
    const Wide linear = wj.inv_mass_a + wj.inv_mass_b;
    k.xx += linear + kb.xx;
    k.yy += linear + kb.yy;
    k.zz += linear + kb.zz;
    k.xy += kb.xy;
    k.xz += kb.xz;
    k.yz += kb.yz;
    const Wide3 x = solve_symmetric(k, cdot + splat(soft.bias_rate) * c);
    const Wide3 impulse = splat(-soft.mass_scale) * x - splat(soft.impulse_scale) * wj.impulse;
    wj.impulse += impulse;
    apply(wj, m, s, ra, rb, impulse);
}

}  // namespace

void pack_joint_lanes(SolverScratch& scratch) {
    const SolverBody* bodies = scratch.bodies.data();
    const auto immovable = static_cast<std::uint32_t>(scratch.bodies.size() - 1);
    // Capacity kept: no allocation once grown.
    scratch.wide_joints.clear();
    scratch.wide_swing_twists.clear();
    scratch.wide_hinges.clear();
    for (int c = 0; c < kColorCount; ++c) {
        scratch.wide_joint_begin[c] = static_cast<std::uint32_t>(scratch.wide_joints.size());
        std::vector<std::uint32_t>& list = scratch.joint_colors[c];
        std::array<std::size_t, kLaneTypes.size()> open;  // each type's block being filled
        open.fill(~std::size_t{0});
        std::size_t kept = 0;
        for (const std::uint32_t k : list) {
            const JointConstraint& jc = scratch.joints[k];
            const int t = lane_type(jc, bodies);
            if (t < 0) {
                list[kept++] = k;
                continue;
            }
            std::size_t& block = open[static_cast<std::size_t>(t)];
            if (block == ~std::size_t{0} || scratch.wide_joints[block].lanes == kLanes) {
                block = scratch.wide_joints.size();
                WideJoint& fresh = scratch.wide_joints.emplace_back();
                for (int l = 0; l < kLanes; ++l) fresh.a[l] = fresh.b[l] = immovable;
                fresh.type = jc.type;
                if (jc.type == JointType::SwingTwist) {
                    fresh.angular = static_cast<std::uint32_t>(scratch.wide_swing_twists.size());
                    scratch.wide_swing_twists.emplace_back();
                } else if (jc.type == JointType::Hinge) {
                    fresh.angular = static_cast<std::uint32_t>(scratch.wide_hinges.size());
                    scratch.wide_hinges.emplace_back();
                }
            }
            WideJoint& wj = scratch.wide_joints[block];
            wj.a[wj.lanes] = jc.a;
            wj.b[wj.lanes] = jc.b;
            wj.joint[wj.lanes] = k;
            ++wj.lanes;
        }
        list.resize(kept);
    }
    scratch.wide_joint_begin[kColorCount] = static_cast<std::uint32_t>(scratch.wide_joints.size());
}

void prepare_joint_lanes(SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi) {
    const SolverBody* bodies = scratch.bodies.data();
    for (std::uint32_t k = lo; k < hi; ++k) {
        WideJoint& wj = scratch.wide_joints[k];
        // Empty lanes keep the zeros they were packed with: no mass, no impulse.
        wj.turns_a = wj.turns_b = false;
        for (int l = 0; l < wj.lanes; ++l) {
            const JointConstraint& jc = scratch.joints[wj.joint[l]];
            const SolverBody& A = bodies[jc.a];
            const SolverBody& B = bodies[jc.b];
            wj.ra.set_lane(l, jc.ra);
            wj.rb.set_lane(l, jc.rb);
            wj.delta_center.set_lane(l, jc.delta_center);
            wj.inv_mass_a[l] = static_cast<float>(A.inv_mass);
            wj.inv_mass_b[l] = static_cast<float>(B.inv_mass);
            wj.inv_inertia_a.set_lane(l, A.inv_inertia);
            wj.inv_inertia_b.set_lane(l, B.inv_inertia);
            wj.turns_a = wj.turns_a || !A.isotropic;
            wj.turns_b = wj.turns_b || !B.isotropic;
            wj.impulse.set_lane(l, jc.linear_impulse);
            if (wj.type == JointType::SwingTwist)
                prepare_swing_twist_lane(scratch.wide_swing_twists[wj.angular], l, jc);
            if (wj.type == JointType::Hinge) prepare_hinge_lane(scratch.wide_hinges[wj.angular], l, jc);
        }
    }
}

namespace {

// The warm start's velocity changes: the impulses the lanes' joints have so far applied to `s`.
void apply_warm_start(const SolverScratch& scratch, const WideJoint& wj, const WideMotion& m, WideVelocities& s) {
    if (wj.type == JointType::SwingTwist) warm_start_swing_twist_lanes(scratch.wide_swing_twists[wj.angular], m, s);
    if (wj.type == JointType::Hinge) warm_start_hinge_lanes(scratch.wide_hinges[wj.angular], m, s);
    apply(wj, m, s, rotate(m.dqa, wj.ra), rotate(m.dqb, wj.rb), wj.impulse);
}

// solve_joint_lanes; with kWarm, then the next substep's warm start added to `warm`.
template <bool kWarm>
void solve_lanes(SolverScratch& scratch, WideJoint& wj, SolverBody* bodies, const JointSolveParams& params,
                 EffectCounts& counts, PushVelocity* warm) {
    counts.joints += static_cast<std::uint64_t>(wj.lanes);
    WideVelocities s = gather(wj, bodies);
    TurnedInertia turned_inertia[2];
    const WideMotion m = gather_motion(wj, bodies, turned_inertia);
    if (wj.type == JointType::SwingTwist) solve_swing_twist_lanes(scratch.wide_swing_twists[wj.angular], m, s, params);
    if (wj.type == JointType::Hinge) solve_hinge_lanes(scratch.wide_hinges[wj.angular], m, s, params);
    solve_point(wj, s, m, params);
    scatter(wj, bodies, s);
    if constexpr (kWarm) {
        WideVelocities change;
        apply_warm_start(scratch, wj, m, change);
        scatter_add(wj, bodies, warm, change);
    }
}

}  // namespace

void warm_start_joint_lanes(const SolverScratch& scratch, const WideJoint& wj, SolverBody* bodies) {
    WideVelocities s = gather(wj, bodies);
    TurnedInertia turned_inertia[2];
    apply_warm_start(scratch, wj, gather_motion(wj, bodies, turned_inertia), s);
    scatter(wj, bodies, s);
}

void solve_joint_lanes(SolverScratch& scratch, WideJoint& wj, SolverBody* bodies, const JointSolveParams& params,
                       EffectCounts& counts) {
    solve_lanes<false>(scratch, wj, bodies, params, counts, nullptr);
}

void relax_and_warm_start_joint_lanes(SolverScratch& scratch, WideJoint& wj, SolverBody* bodies,
                                      const JointSolveParams& params, EffectCounts& counts, PushVelocity* warm) {
    solve_lanes<true>(scratch, wj, bodies, params, counts, warm);
}

void store_joint_lane_impulses(SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi) {
    for (std::uint32_t k = lo; k < hi; ++k) {
        const WideJoint& wj = scratch.wide_joints[k];
        for (int l = 0; l < wj.lanes; ++l) {
            JointConstraint& jc = scratch.joints[wj.joint[l]];
            jc.linear_impulse = wj.impulse.lane(l);
            if (wj.type == JointType::SwingTwist) store_swing_twist_lane(scratch.wide_swing_twists[wj.angular], l, jc);
            if (wj.type == JointType::Hinge) store_hinge_lane(scratch.wide_hinges[wj.angular], l, jc);
        }
    }
}

}  // namespace spindle
