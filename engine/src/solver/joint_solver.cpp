// The joint solver inside the soft step (solver.cpp): prepare, warm start, solve with
// soft position correction from the dp/dq deltas, relax, and keep impulses. The
// ball-socket, hinge, fixed and distance joints are here, with the rows all joints share;
// the others have a file each (joint_<type>.cpp), dispatched from here.
#include <algorithm>
#include <cmath>

#include "api/joint_store.hpp"
#include "solver/joint_rows.hpp"
#include "stages/stages.hpp"

namespace spindle {

Vec3 perpendicular(const Vec3& n) {
    const Vec3 t = std::abs(n.x()) < 0.57735 ? Vec3::UnitX() : Vec3::UnitY();
    return (t - n * n.dot(t)).normalized();
}

Real limit_impulse(Real c, Real cdot, Real mass, Real& accumulated, const JointSolveParams& p, const Softness* spring) {
    Softness s{0, 1, 0};
    if (c > 0) {
        s.bias_rate = p.inv_h;
    } else if (spring != nullptr) {
        s = *spring;
    } else if (p.use_bias) {
        s = p.soft;
    }
    const Real impulse = -s.mass_scale * mass * (cdot + s.bias_rate * c) - s.impulse_scale * accumulated;
    const Real total = std::max(accumulated + impulse, Real(0));
    const Real applied = total - accumulated;
    accumulated = total;
    return applied;
}

namespace {

constexpr std::uint32_t kJointGrain = 32;

// The hinge's two alignment rows: C = (a1.b2, a1.c2) with a1 A's axis and b2, c2
// perpendicular to B's; Cdot = u.(wB - wA) with u = b2 x a1, c2 x a1.
struct AlignRows {
    Vec3 axis;  // A's axis now
    Vec3 u[2];
    Vec2 c;
};

AlignRows align_rows(const JointConstraint& jc, const Quat& dqa, const Quat& dqb) {
    AlignRows r;
    r.axis = dqa * jc.axis_a;
    const Vec3 b2 = dqb * jc.perp_b[0], c2 = dqb * jc.perp_b[1];
    r.u[0] = b2.cross(r.axis);
    r.u[1] = c2.cross(r.axis);
    r.c = Vec2(r.axis.dot(b2), r.axis.dot(c2));
    return r;
}

Real hinge_angle(const JointConstraint& jc, const Vec3& axis, const Quat& dqa, const Quat& dqb) {
    const Vec3 ra = dqa * jc.ref_a, rb = dqb * jc.ref_b;
    return std::atan2(axis.dot(ra.cross(rb)), ra.dot(rb));
}

}  // namespace

Vec3 rotation_error(const JointConstraint& jc, const Quat& dqa, const Quat& dqb) {
    const Quat e = dqb * jc.rotation_error * dqa.conjugate();
    return (e.w() < 0 ? -2 : 2) * e.vec();
}

void solve_point(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                 const JointSolveParams& p) {
    const Vec3 ra = A.dq * jc.ra, rb = B.dq * jc.rb;
    const Softness soft = pass_softness(p);
    // Current separation of the anchors, from small deltas (exact far from the origin).
    const Vec3 c = (B.dp - A.dp) + (rb - ra) + jc.delta_center;
    const Vec3 cdot = relative_velocity(s, ra, rb);
    // K from the anchors now: a light link can turn far within a step, and a mass from
    // the step's start would then overshoot.
    const Mat3 mass = point_mass(A, B, ra, rb);
    const Vec3 impulse = -soft.mass_scale * (mass * (cdot + soft.bias_rate * c)) -
                         soft.impulse_scale * jc.linear_impulse;
    jc.linear_impulse += impulse;
    apply(A, B, s, ra, rb, impulse);
}

void solve_rotation_lock(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                         const JointSolveParams& p) {
    const Softness soft = pass_softness(p);
    const Vec3 c = rotation_error(jc, A.dq, B.dq);
    const Vec3 cdot = s.wb - s.wa;
    const Vec3 impulse = -soft.mass_scale * (jc.rotation_mass * (cdot + soft.bias_rate * c)) -
                         soft.impulse_scale * jc.angular_impulse;
    jc.angular_impulse += impulse;
    apply_angular(A, B, s, impulse);
}

void prepare_rotation_lock(const Joint& j, const SolverBody& A, const SolverBody& B, const Quat& qa, const Quat& qb,
                           JointConstraint& jc) {
    jc.rotation_error = qb * j.reference.conjugate() * qa.conjugate();
    jc.rotation_mass = inverse_or_pseudo(Mat3(A.inv_inertia + B.inv_inertia), has_locks(A, B));
    jc.angular_impulse = j.angular_impulse;
}

Vec2 onto_rows(const Vec3 (&rows)[2], const Vec3& impulse) {
    Vec2 r;
    for (int k = 0; k < 2; ++k) {
        const Real norm2 = rows[k].squaredNorm();
        r[k] = norm2 > 1e-12 ? rows[k].dot(impulse) / norm2 : 0;
    }
    return r;
}

namespace {

// Hinge: motor and limit about the axis, two alignment rows, then the point.
void solve_hinge(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                 const JointSolveParams& p) {
    const AlignRows rows = align_rows(jc, A.dq, B.dq);
    const Mat3 inv_inertia = A.inv_inertia + B.inv_inertia;
    const Real axial = rows.axis.dot(inv_inertia * rows.axis);
    const Real axial_mass = axial > 0 ? 1 / axial : 0;
    if (jc.enable_motor) {
        const Real cdot = rows.axis.dot(s.wb - s.wa) - jc.motor_speed;
        const Real old = jc.motor_impulse;
        jc.motor_impulse = std::clamp(old - axial_mass * cdot, -jc.max_motor_impulse, jc.max_motor_impulse);
        apply_angular(A, B, s, (jc.motor_impulse - old) * rows.axis);
    }
    if (jc.enable_limit) {
        const Real angle = hinge_angle(jc, rows.axis, A.dq, B.dq);
        const Softness* spring = jc.soft_limit ? &jc.limit_spring : nullptr;
        const Real lower = limit_impulse(angle - jc.lower, rows.axis.dot(s.wb - s.wa), axial_mass, jc.lower_impulse, p,
                                         spring);
        apply_angular(A, B, s, lower * rows.axis);
        const Real upper = limit_impulse(jc.upper - angle, rows.axis.dot(s.wa - s.wb), axial_mass, jc.upper_impulse, p,
                                         spring);
        apply_angular(A, B, s, -upper * rows.axis);
    }
    {
        const Softness soft = pass_softness(p);
        const Vec3 dw = s.wb - s.wa;
        const Vec2 cdot(rows.u[0].dot(dw), rows.u[1].dot(dw));
        Mat2 k;
        for (int r = 0; r < 2; ++r) {
            for (int c = 0; c < 2; ++c) k(r, c) = rows.u[r].dot(inv_inertia * rows.u[c]);
        }
        const Vec2 impulse = -soft.mass_scale *
                                 (inverse_or_pseudo(k, has_locks(A, B)) * (cdot + soft.bias_rate * rows.c)) -
                             soft.impulse_scale * jc.align_impulse;
        jc.align_impulse += impulse;
        apply_angular(A, B, s, impulse.x() * rows.u[0] + impulse.y() * rows.u[1]);
    }
    solve_point(jc, A, B, s, p);
}

// Fixed: three angular rows that hold the relative rotation, then the point.
void solve_fixed(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                 const JointSolveParams& p) {
    solve_rotation_lock(jc, A, B, s, p);
    solve_point(jc, A, B, s, p);
}

// Current direction between the anchors and its length.
Vec3 distance_axis(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, const Vec3& ra, const Vec3& rb,
                   Real& length) {
    const Vec3 d = (B.dp - A.dp) + (rb - ra) + jc.delta_center;
    length = d.norm();
    return length > 1e-9 ? Vec3(d / length) : jc.axis;
}

// Distance: one row along the anchors' line: rigid, or a spring with min/max limits.
void solve_distance(JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s,
                    const JointSolveParams& p) {
    const Vec3 ra = A.dq * jc.ra, rb = B.dq * jc.rb;
    Real length = 0;
    const Vec3 axis = distance_axis(jc, A, B, ra, rb, length);
    const Real mass = effective_mass(A, B, ra, rb, axis);
    auto speed = [&] { return axis.dot(relative_velocity(s, ra, rb)); };
    if (!jc.enable_spring) {
        // Rigid rod: softened like every joint, relaxed without bias.
        const Softness soft = pass_softness(p);
        const Real c = length - jc.rest_length;
        const Real impulse = -soft.mass_scale * mass * (speed() + soft.bias_rate * c) -
                             soft.impulse_scale * jc.axial_impulse;
        jc.axial_impulse += impulse;
        apply(A, B, s, ra, rb, impulse * axis);
        return;
    }
    if (jc.spring_hertz > 0) {
        // The spring is physics, not error correction: the same in solve and relax.
        const Real c = length - jc.rest_length;
        const Real impulse = -jc.spring.mass_scale * mass * (speed() + jc.spring.bias_rate * c) -
                             jc.spring.impulse_scale * jc.axial_impulse;
        jc.axial_impulse += impulse;
        apply(A, B, s, ra, rb, impulse * axis);
    }
    if (jc.enable_limit) {
        const Real lower = limit_impulse(length - jc.lower, speed(), mass, jc.lower_impulse, p);
        apply(A, B, s, ra, rb, lower * axis);
        if (jc.upper < kHuge) {
            const Real upper = limit_impulse(jc.upper - length, -speed(), mass, jc.upper_impulse, p);
            apply(A, B, s, ra, rb, -upper * axis);
        }
    }
}

// A ball-socket's constraint is made by setting what its rows read (type, anchors, centres,
// point impulse; prepare_joint) and zeroing the impulses it keeps none of: the rest of the
// record, hundreds of bytes, is never read for it, and a chain or a net is all ball-sockets.
void clear_unused_impulses(JointConstraint& jc) {
    jc.angular_impulse = Vec3::Zero();
    jc.axial_impulse = jc.motor_impulse = jc.lower_impulse = jc.upper_impulse = jc.swing_impulse = 0;
}

void prepare_joint(const World& world, const SolverBody* bodies, JointConstraint& jc, Real h) {
    const Bodies& b = world.bodies;
    const Joint& j = world.joints.joint[jc.joint];
    const SolverBody& A = bodies[jc.a];
    const SolverBody& B = bodies[jc.b];
    const Quat qa = b.q[j.body_a], qb = b.q[j.body_b];
    jc.type = j.type;
    jc.ra = qa * j.local_a;
    jc.rb = qb * j.local_b;
    jc.delta_center = b.x[j.body_b] - b.x[j.body_a];
    jc.linear_impulse = j.linear_impulse;
    switch (j.type) {
        case JointType::BallSocket: break;
        case JointType::Hinge: {
            jc.axis_a = qa * j.axis_a;
            jc.perp_b[0] = qb * j.ref_b;
            jc.perp_b[1] = (qb * j.axis_b).cross(jc.perp_b[0]);
            jc.ref_a = qa * j.ref_a;
            jc.ref_b = jc.perp_b[0];
            // The kept impulse is a world vector: the rows' directions move between steps.
            const AlignRows rows = align_rows(jc, Quat::Identity(), Quat::Identity());
            jc.align_impulse = onto_rows(rows.u, j.angular_impulse);
            const HingeParams& hp = j.hinge;
            jc.enable_limit = hp.enable_limit;
            jc.lower = hp.lower_angle;
            jc.upper = hp.upper_angle;
            jc.soft_limit = hp.limit_spring_hertz > 0;
            jc.limit_spring = make_softness(hp.limit_spring_hertz, hp.limit_damping_ratio, h);
            jc.enable_motor = hp.enable_motor;
            jc.motor_speed = hp.motor_speed;
            jc.max_motor_impulse = hp.max_motor_torque * h;
            jc.motor_impulse = hp.enable_motor ? j.motor_impulse : 0;
            jc.lower_impulse = hp.enable_limit ? j.lower_impulse : 0;
            jc.upper_impulse = hp.enable_limit ? j.upper_impulse : 0;
            break;
        }
        case JointType::Fixed: prepare_rotation_lock(j, A, B, qa, qb, jc); break;
        case JointType::Distance: {
            const DistanceParams& dp = j.distance;
            const Vec3 d = jc.delta_center + jc.rb - jc.ra;
            jc.axis = d.norm() > 1e-9 ? Vec3(d.normalized()) : Vec3::UnitY();
            jc.rest_length = j.rest_length;
            // A spring pinned by equal limits is a rigid rod at that length.
            jc.enable_spring = dp.enable_spring && !(dp.enable_limit && dp.min_length >= dp.max_length);
            if (dp.enable_spring && !jc.enable_spring) jc.rest_length = dp.min_length;
            jc.spring_hertz = dp.spring_hertz;
            jc.spring = make_softness(dp.spring_hertz, dp.spring_damping_ratio, h);
            jc.enable_limit = dp.enable_limit;
            jc.lower = dp.min_length;
            jc.upper = dp.max_length;
            jc.axial_impulse = j.axial_impulse;
            jc.lower_impulse = dp.enable_limit ? j.lower_impulse : 0;
            jc.upper_impulse = dp.enable_limit ? j.upper_impulse : 0;
            break;
        }
        case JointType::SwingTwist: prepare_swing_twist(j, A, B, qa, qb, h, jc); break;
        case JointType::Prismatic: prepare_prismatic(j, A, B, qa, qb, h, jc); break;
        case JointType::Motor: prepare_motor(j, A, B, qa, qb, h, jc); break;
    }
}

}  // namespace

Softness joint_softness(const SolverSettings& settings, Real h) {
    // As for contacts, no stiffer than a quarter of the substep rate: stiffer joints
    // solved one at a time fight each other (a rigid bias of the whole error per
    // substep makes a hanging chain under a heavy load blow up).
    const Real stiffest = Real(0.25) / h;
    const Real hertz = settings.joint_hertz > 0 ? std::min(settings.joint_hertz, stiffest) : stiffest;
    return make_softness(hertz, settings.joint_damping_ratio, h);
}

void prepare_joints(World& world, SolverScratch& scratch, Real h) {
    scratch.joint_refs.clear();
    const Joints& js = world.joints;
    if (js.live == 0) {
        scratch.joints.clear();
        return;
    }
    const Bodies& b = world.bodies;
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    auto solver_index = [&](std::uint32_t slot) {
        const std::int32_t k = b.awake_index[slot];
        return k >= 0 ? static_cast<std::uint32_t>(k) : n;
    };
    // Slot order: the same list, so the same colours, for any worker count.
    for (std::uint32_t slot : awake_joints(world)) {
        const Joint& j = js.joint[slot];
        const std::uint32_t a = solver_index(j.body_a), bb = solver_index(j.body_b);
        if (!scratch.bodies[a].dynamic && !scratch.bodies[bb].dynamic) continue;  // nothing it could move
        scratch.joint_refs.push_back({slot, a, bb, static_cast<std::uint32_t>(j.type)});
    }
    // The constraints are made afresh in the jobs: a joint's is hundreds of bytes, too
    // many to write on one thread.
    scratch.joints.resize(scratch.joint_refs.size());
    const SolverBody* bodies = scratch.bodies.data();
    world.jobs->parallel_for("PrepareJoints", 0, static_cast<std::uint32_t>(scratch.joints.size()), kJointGrain,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
                                 for (std::uint32_t k = lo; k < hi; ++k) {
                                     const JointRef& ref = scratch.joint_refs[k];
                                     JointConstraint& jc = scratch.joints[k];
                                     if (ref.type == static_cast<std::uint32_t>(JointType::BallSocket)) {
                                         clear_unused_impulses(jc);
                                     } else {
                                         jc = JointConstraint{};
                                     }
                                     jc.joint = ref.joint;
                                     jc.a = ref.a;
                                     jc.b = ref.b;
                                     prepare_joint(world, bodies, jc, h);
                                 }
                             });
}

namespace {

// The warm start's velocity changes: the impulses the joint has so far applied to `s`.
void apply_warm_start(const JointConstraint& jc, const SolverBody& A, const SolverBody& B, Velocities& s) {
    const Vec3 ra = A.dq * jc.ra, rb = B.dq * jc.rb;
    switch (jc.type) {
        case JointType::BallSocket: apply(A, B, s, ra, rb, jc.linear_impulse); break;
        case JointType::Hinge: {
            const AlignRows rows = align_rows(jc, A.dq, B.dq);
            const Real axial = jc.motor_impulse + jc.lower_impulse - jc.upper_impulse;
            apply_angular(A, B, s,
                          jc.align_impulse.x() * rows.u[0] + jc.align_impulse.y() * rows.u[1] + axial * rows.axis);
            apply(A, B, s, ra, rb, jc.linear_impulse);
            break;
        }
        case JointType::Fixed:
            apply_angular(A, B, s, jc.angular_impulse);
            apply(A, B, s, ra, rb, jc.linear_impulse);
            break;
        case JointType::Distance: {
            Real length = 0;
            const Vec3 axis = distance_axis(jc, A, B, ra, rb, length);
            apply(A, B, s, ra, rb, (jc.axial_impulse + jc.lower_impulse - jc.upper_impulse) * axis);
            break;
        }
        case JointType::SwingTwist:
            warm_start_swing_twist(jc, A, B, s);
            apply(A, B, s, ra, rb, jc.linear_impulse);
            break;
        case JointType::Prismatic: warm_start_prismatic(jc, A, B, s); break;
        case JointType::Motor: warm_start_motor(jc, A, B, s); break;
    }
}

}  // namespace

void warm_start_joint(JointConstraint& jc, SolverBody* bodies) {
    SolverBody& A = bodies[jc.a];
    SolverBody& B = bodies[jc.b];
    Velocities s = load(A, B);
    SolverBody copy_a, copy_b;
    apply_warm_start(jc, turned(A, copy_a), turned(B, copy_b), s);
    store(A, B, s);
}

void relax_and_warm_start_joint(JointConstraint& jc, SolverBody* bodies, const JointSolveParams& params,
                                EffectCounts& counts, PushVelocity* warm) {
    solve_joint(jc, bodies, params, counts);
    const SolverBody& A = bodies[jc.a];
    const SolverBody& B = bodies[jc.b];
    Velocities change{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    SolverBody copy_a, copy_b;
    apply_warm_start(jc, turned(A, copy_a), turned(B, copy_b), change);
    add_to(A, B, warm[jc.a], warm[jc.b], change);
}

void solve_joint(JointConstraint& jc, SolverBody* bodies, const JointSolveParams& params, EffectCounts& counts) {
    ++counts.joints;
    SolverBody& A = bodies[jc.a];
    SolverBody& B = bodies[jc.b];
    Velocities s = load(A, B);
    SolverBody copy_a, copy_b;
    const SolverBody& a = turned(A, copy_a);
    const SolverBody& b = turned(B, copy_b);
    switch (jc.type) {
        case JointType::BallSocket: solve_point(jc, a, b, s, params); break;
        case JointType::Hinge: solve_hinge(jc, a, b, s, params); break;
        case JointType::Fixed: solve_fixed(jc, a, b, s, params); break;
        case JointType::Distance: solve_distance(jc, a, b, s, params); break;
        case JointType::SwingTwist: solve_swing_twist(jc, a, b, s, params); break;
        case JointType::Prismatic: solve_prismatic(jc, a, b, s, params); break;
        case JointType::Motor: solve_motor(jc, a, b, s, params); break;
    }
    store(A, B, s);
}

void store_joint_impulses(World& world, const SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi) {
    const SolverBody* bodies = scratch.bodies.data();
    // Each constraint writes its own joint: any order, any split gives the same result.
    for (std::uint32_t k = lo; k < hi; ++k) {
        const JointConstraint& jc = scratch.joints[k];
        Joint& j = world.joints.joint[jc.joint];
        j.linear_impulse = jc.linear_impulse;
        j.angular_impulse = jc.angular_impulse;
        j.axial_impulse = jc.axial_impulse;
        j.motor_impulse = jc.motor_impulse;
        j.lower_impulse = jc.lower_impulse;
        j.upper_impulse = jc.upper_impulse;
        j.swing_impulse = jc.swing_impulse;
        if (jc.type == JointType::Hinge) {
            const AlignRows rows = align_rows(jc, bodies[jc.a].dq, bodies[jc.b].dq);
            j.angular_impulse = jc.align_impulse.x() * rows.u[0] + jc.align_impulse.y() * rows.u[1];
        }
        if (jc.type == JointType::Prismatic) {
            const Quat& dqa = bodies[jc.a].dq;
            j.linear_impulse = jc.align_impulse.x() * (dqa * jc.perp_a[0]) +
                               jc.align_impulse.y() * (dqa * jc.perp_a[1]);
        }
    }
}

}  // namespace spindle
