// The constraint solver (soft step, as Box2D v3 and Box3D): per step, prepare the
// contacts from the manifolds and the joints (joint_solver.cpp) and colour them; per
// substep, integrate velocities, warm start, solve with soft position bias, integrate
// positions, relax without bias; then restitution and storing impulses for the next
// step's warm start. Each colour is solved as parallel jobs: no two constraints of a
// colour share a dynamic body, so the result is bitwise the same for any number of workers.
#include "solver.hpp"

#include <algorithm>
#include <cmath>

#include "stages.hpp"

namespace spindle {

Softness make_softness(Real hertz, Real damping_ratio, Real h) {
    if (hertz == 0) return {0, 1, 0};
    const Real omega = 2 * kPi * hertz;
    const Real a1 = 2 * damping_ratio + h * omega;
    const Real a2 = h * omega * a1;
    const Real a3 = 1 / (1 + a2);
    return {omega / a1, a2 * a3, a3};
}

namespace {

constexpr std::uint32_t kBodyGrain = 128;
constexpr std::uint32_t kConstraintGrain = 32;

// A tangent basis for a unit normal, the same for the same normal every time.
void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
    if (std::abs(n.x()) >= 0.57735) {
        t1 = Vec3(n.y(), -n.x(), 0).normalized();
    } else {
        t1 = Vec3(0, n.z(), -n.y()).normalized();
    }
    t2 = n.cross(t1);
}

// Fills a row's angular terms and returns its effective mass.
Real make_row(const SolverBody& A, const SolverBody& B, const Vec3& ra, const Vec3& rb, const Vec3& dir,
              ContactRow& row) {
    row.ra_x = ra.cross(dir);
    row.rb_x = rb.cross(dir);
    row.ia = A.inv_inertia * row.ra_x;
    row.ib = B.inv_inertia * row.rb_x;
    const Real k = A.inv_mass + B.inv_mass + row.ra_x.dot(row.ia) + row.rb_x.dot(row.ib);
    return k > 0 ? 1 / k : 0;
}

// Relative speed along a row's direction.
inline Real row_speed(const Velocities& s, const Vec3& dir, const ContactRow& row) {
    return dir.dot(s.vb - s.va) + row.rb_x.dot(s.wb) - row.ra_x.dot(s.wa);
}

// Applies an impulse of size L along a row.
inline void apply_row(const SolverBody& A, const SolverBody& B, Velocities& s, const Vec3& dir, const ContactRow& row,
                      Real L) {
    s.va -= (A.inv_mass * L) * dir;
    s.wa -= L * row.ia;
    s.vb += (B.inv_mass * L) * dir;
    s.wb += L * row.ib;
}

void prepare(World& world, SolverScratch& scratch, Real h) {
    const Bodies& b = world.bodies;
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    scratch.bodies.resize(n + 1);
    world.jobs->parallel_for("PrepareBodies", 0, n, kBodyGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t k = lo; k < hi; ++k) {
            const std::uint32_t i = world.awake[k];
            SolverBody& sb = scratch.bodies[k];
            sb.v = b.v[i];
            sb.w = b.w[i];
            sb.push_v = Vec3::Zero();
            sb.push_w = Vec3::Zero();
            sb.dp = Vec3::Zero();
            sb.dq = Quat::Identity();
            sb.dynamic = b.type[i] == MotionType::Dynamic;
            sb.inv_mass = b.inv_mass[i];
            sb.inv_inertia = sb.dynamic ? b.inv_inertia_world(i) : Mat3::Zero();
        }
    });
    scratch.bodies[n] = SolverBody{};  // the immovable partner of static and sleeping bodies

    // Constraint list: one per touching manifold of an awake contact, in contact order.
    scratch.constraints.clear();
    for (std::uint32_t c : awake_contacts(world)) {
        const Contact& contact = world.contacts[c];
        for (int m = 0; m < contact.manifold_count; ++m) {
            if (contact.manifold_at(m).point_count == 0) continue;
            ContactConstraint& cc = scratch.constraints.emplace_back();
            cc.contact = c;
            cc.manifold = m;
        }
    }
    auto solver_index = [&](std::uint32_t slot) {
        const std::int32_t k = b.awake_index[slot];
        return k >= 0 ? static_cast<std::uint32_t>(k) : n;
    };
    const auto count = static_cast<std::uint32_t>(scratch.constraints.size());
    world.jobs->parallel_for("PrepareContacts", 0, count, kConstraintGrain,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t k = lo; k < hi; ++k) {
            ContactConstraint& cc = scratch.constraints[k];
            const Contact& contact = world.contacts[cc.contact];
            const ContactManifold& m = contact.manifold_at(cc.manifold);
            cc.a = solver_index(contact.body_a);
            cc.b = solver_index(contact.body_b);
            const SolverBody& A = scratch.bodies[cc.a];
            const SolverBody& B = scratch.bodies[cc.b];
            cc.normal = m.normal;
            tangent_basis(m.normal, cc.tangent[0], cc.tangent[1]);
            cc.friction = contact.friction;
            cc.restitution = contact.restitution;
            const Vec3 g = world.settings.gravity;
            cc.gravity_normal = cc.normal.dot((B.dynamic ? b.desc[contact.body_b].gravity_scale : 0) * g -
                                              (A.dynamic ? b.desc[contact.body_a].gravity_scale : 0) * g);
            cc.point_count = m.point_count;
            const Vec3 xa = b.x[contact.body_a];
            const Vec3 xb = b.x[contact.body_b];
            const Velocities s = load(A, B);
            for (int j = 0; j < m.point_count; ++j) {
                const ContactPoint& src = m.points[j];
                ConstraintPoint& p = cc.points[j];
                p.ra = src.geometry.point - xa;
                p.rb = src.geometry.point - xb;
                p.adjusted_separation = src.geometry.separation - cc.normal.dot(p.rb - p.ra);
                p.normal_mass = make_row(A, B, p.ra, p.rb, cc.normal, p.normal_row);
                p.tangent_mass[0] = make_row(A, B, p.ra, p.rb, cc.tangent[0], p.tangent_row[0]);
                p.tangent_mass[1] = make_row(A, B, p.ra, p.rb, cc.tangent[1], p.tangent_row[1]);
                p.normal_impulse = src.normal_impulse;
                p.tangent_impulse[0] = src.tangent_impulse[0];
                p.tangent_impulse[1] = src.tangent_impulse[1];
                p.max_normal_impulse = 0;
                p.relative_velocity = cc.normal.dot(relative_velocity(s, p.ra, p.rb));
            }
        }
    });
    (void)h;
}

// Greedy colouring (Box2D v3's graph colouring): the first colour whose bodies include
// neither dynamic body of the constraint; -1 when none is free. Static, kinematic and
// sleeping partners are shared freely: constraints never write them.
int assign_color(SolverScratch& scratch, std::uint32_t a, std::uint32_t b) {
    const bool dyn_a = scratch.bodies[a].dynamic;
    const bool dyn_b = scratch.bodies[b].dynamic;
    for (int c = 0; c < kColorCount; ++c) {
        std::vector<std::uint64_t>& bits = scratch.color_bits[c];
        if (dyn_a && (bits[a / 64] >> (a % 64) & 1)) continue;
        if (dyn_b && (bits[b / 64] >> (b % 64) & 1)) continue;
        if (dyn_a) bits[a / 64] |= std::uint64_t{1} << (a % 64);
        if (dyn_b) bits[b / 64] |= std::uint64_t{1} << (b % 64);
        return c;
    }
    return -1;
}

// Joints first, then contacts, in list order (deterministic), sharing the colours'
// body sets: a colour's joints and contacts together touch each dynamic body once.
void color(World& world, SolverScratch& scratch) {
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    const std::size_t words = (n + 63) / 64;
    for (int c = 0; c < kColorCount; ++c) {
        scratch.colors[c].clear();
        scratch.joint_colors[c].clear();
        scratch.color_bits[c].assign(words, 0);
    }
    scratch.overflow.clear();
    scratch.joint_overflow.clear();
    for (std::uint32_t k = 0; k < scratch.joints.size(); ++k) {
        const int c = assign_color(scratch, scratch.joints[k].a, scratch.joints[k].b);
        (c >= 0 ? scratch.joint_colors[c] : scratch.joint_overflow).push_back(k);
    }
    for (std::uint32_t k = 0; k < scratch.constraints.size(); ++k) {
        const int c = assign_color(scratch, scratch.constraints[k].a, scratch.constraints[k].b);
        (c >= 0 ? scratch.colors[c] : scratch.overflow).push_back(k);
    }
}

void warm_start(ContactConstraint& cc, SolverBody* bodies) {
    SolverBody& A = bodies[cc.a];
    SolverBody& B = bodies[cc.b];
    Velocities s = load(A, B);
    for (int j = 0; j < cc.point_count; ++j) {
        const ConstraintPoint& p = cc.points[j];
        apply_row(A, B, s, cc.normal, p.normal_row, p.normal_impulse);
        apply_row(A, B, s, cc.tangent[0], p.tangent_row[0], p.tangent_impulse[0]);
        apply_row(A, B, s, cc.tangent[1], p.tangent_row[1], p.tangent_impulse[1]);
    }
    store(A, B, s);
    if (cc.push_impulse > 0) {
        Velocities push = load_push(A, B);
        apply_row(A, B, push, cc.normal, cc.push_row, cc.push_impulse);
        store_push(A, B, push);
    }
}

struct SolveParams {
    Softness soft;
    Real inv_h = 0;
    Real push_out = 0;
    Real slop = 0;  // gaps wider than this carry no friction
    Real recovery_depth = 0;  // overlap beyond this is pushed out by the split impulse
    bool use_bias = true;
};

// Deep overlap is pushed out by a soft constraint on the push-out velocities (split
// impulse), never by real speed, so a chain of deep overlaps separates without
// launching anything. One row per manifold, through the overlap's depth-weighted centre,
// so a face pushes straight and a tilted corner turns back.
void push_out(ContactConstraint& cc, SolverBody& A, SolverBody& B, Real excess, const Vec3& ra, const Vec3& rb,
              const SolveParams& params) {
    const Real mass = make_row(A, B, ra, rb, cc.normal, cc.push_row);
    Velocities push = load_push(A, B);
    const Real target = std::max(params.soft.bias_rate * excess, -params.push_out);
    const Real speed = row_speed(push, cc.normal, cc.push_row);
    const Real total = std::max(
        cc.push_impulse - mass * params.soft.mass_scale * (speed + target) - params.soft.impulse_scale * cc.push_impulse,
        Real(0));
    apply_row(A, B, push, cc.normal, cc.push_row, total - cc.push_impulse);
    cc.push_impulse = total;
    store_push(A, B, push);
}

void solve_contact(ContactConstraint& cc, SolverBody* bodies, const SolveParams& params) {
    SolverBody& A = bodies[cc.a];
    SolverBody& B = bodies[cc.b];
    Velocities s = load(A, B);
    // Overlap deeper than the recovery depth: its excess and where it is, weighted by depth.
    Real excess_sum = 0, weight_sum = 0;
    Vec3 push_ra = Vec3::Zero(), push_rb = Vec3::Zero();
    // Current separation from the bodies' motion since the step began:
    // n.(dpB - dpA + dqB rb - dqA ra), with n.(dq r) = (dq^-1 n).r so each body's
    // rotation is applied once per constraint rather than once per point.
    const Real moved = cc.normal.dot(B.dp - A.dp);
    const Vec3 na = A.dq.conjugate() * cc.normal;
    const Vec3 nb = B.dq.conjugate() * cc.normal;
    Real gap[kMaxManifoldPoints];
    for (int j = 0; j < cc.point_count; ++j) {
        ConstraintPoint& p = cc.points[j];
        const Real separation = moved + nb.dot(p.rb) - na.dot(p.ra) + p.adjusted_separation;
        gap[j] = separation;
        const Real excess = separation + params.recovery_depth;
        if (excess < 0 && params.use_bias) {
            excess_sum -= excess * excess;
            weight_sum -= excess;
            push_ra -= excess * p.ra;
            push_rb -= excess * p.rb;
        }
        Real bias = 0, mass_scale = 1, impulse_scale = 0;
        if (separation > 0) {
            bias = separation * params.inv_h;  // speculative: may close the gap, no more
        } else if (params.use_bias) {
            // Resting overlap is corrected by the contact's own soft bias (soft step);
            // deeper overlap is left to push_out.
            bias = std::max(params.soft.bias_rate * std::max(separation, -params.recovery_depth), -params.push_out);
            mass_scale = params.soft.mass_scale;
            impulse_scale = params.soft.impulse_scale;
        }
        const Real vn = row_speed(s, cc.normal, p.normal_row);
        Real impulse = -p.normal_mass * mass_scale * (vn + bias) - impulse_scale * p.normal_impulse;
        const Real total = std::max(p.normal_impulse + impulse, Real(0));
        impulse = total - p.normal_impulse;
        // Restitution bounces off the approach speed at impact: the speed when the
        // point first pushes in this step, gravity of the earlier substeps included.
        if (impulse > 0 && p.max_normal_impulse == 0) p.relative_velocity = std::min(p.relative_velocity, vn);
        p.normal_impulse = total;
        p.max_normal_impulse = std::max(p.max_normal_impulse, impulse);
        apply_row(A, B, s, cc.normal, p.normal_row, impulse);
    }
    if (weight_sum > 0) push_out(cc, A, B, excess_sum / weight_sum, push_ra / weight_sum, push_rb / weight_sum, params);
    if (cc.friction > 0) {
        for (int j = 0; j < cc.point_count; ++j) {
            ConstraintPoint& p = cc.points[j];
            // No friction across an open gap: a speculative point far from the body (a
            // fast sphere's, metres ahead) would spin it up through the lever arm.
            if (gap[j] > params.slop) continue;
            const Real old0 = p.tangent_impulse[0], old1 = p.tangent_impulse[1];
            Real new0 = old0 - p.tangent_mass[0] * row_speed(s, cc.tangent[0], p.tangent_row[0]);
            Real new1 = old1 - p.tangent_mass[1] * row_speed(s, cc.tangent[1], p.tangent_row[1]);
            // Coulomb's cone: the friction impulse stays within friction x normal impulse.
            const Real limit = cc.friction * p.normal_impulse;
            const Real length_sq = new0 * new0 + new1 * new1;
            if (length_sq > limit * limit) {
                const Real scale = limit / std::sqrt(length_sq);
                new0 *= scale;
                new1 *= scale;
            }
            p.tangent_impulse[0] = new0;
            p.tangent_impulse[1] = new1;
            apply_row(A, B, s, cc.tangent[0], p.tangent_row[0], new0 - old0);
            apply_row(A, B, s, cc.tangent[1], p.tangent_row[1], new1 - old1);
        }
    }
    store(A, B, s);
}

void apply_restitution(ContactConstraint& cc, SolverBody* bodies, Real threshold, Real h) {
    if (cc.restitution == 0) return;
    SolverBody& A = bodies[cc.a];
    SolverBody& B = bodies[cc.b];
    Velocities s = load(A, B);
    for (int j = 0; j < cc.point_count; ++j) {
        ConstraintPoint& p = cc.points[j];
        // Only points that approached fast enough and actually pushed bounce.
        if (p.relative_velocity > -threshold || p.max_normal_impulse == 0) continue;
        const Real vn = row_speed(s, cc.normal, p.normal_row);
        // Semi-implicit Euler conserves v^2/2 - a.x - h a.v/2, not the plain energy;
        // reversing v at an impact costs h a v of it unless the bounce speed gains a h.
        const Real approach = p.relative_velocity + cc.gravity_normal * h;
        Real impulse = -p.normal_mass * (vn + cc.restitution * std::min(approach, Real(0)));
        const Real total = std::max(p.normal_impulse + impulse, Real(0));
        impulse = total - p.normal_impulse;
        p.normal_impulse = total;
        p.max_normal_impulse = std::max(p.max_normal_impulse, impulse);
        apply_row(A, B, s, cc.normal, p.normal_row, impulse);
    }
    store(A, B, s);
}

// Runs joint_fn and contact_fn over every constraint, colour by colour: one parallel
// range per colour, its joints then its contacts (they share no dynamic body); then
// the overflow serially, joints first. Chunks depend only on the lists, so the result
// does not depend on the worker count. kJoints = false walks the contacts only.
template <bool kJoints = true, typename JointFn, typename ContactFn>
void for_each_colored(World& world, SolverScratch& scratch, const char* name, JointFn&& joint_fn,
                      ContactFn&& contact_fn) {
    for (int c = 0; c < kColorCount; ++c) {
        const std::vector<std::uint32_t>& joints = scratch.joint_colors[c];
        const std::vector<std::uint32_t>& contacts = scratch.colors[c];
        const auto joint_count = kJoints ? static_cast<std::uint32_t>(joints.size()) : 0u;
        const auto total = joint_count + static_cast<std::uint32_t>(contacts.size());
        if (total == 0) continue;
        world.jobs->parallel_for(name, 0, total, kConstraintGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
            for (std::uint32_t k = lo; k < hi; ++k) {
                if (k < joint_count) {
                    joint_fn(scratch.joints[joints[k]]);
                } else {
                    contact_fn(scratch.constraints[contacts[k - joint_count]]);
                }
            }
        });
    }
    if (kJoints) {
        for (std::uint32_t k : scratch.joint_overflow) joint_fn(scratch.joints[k]);
    }
    for (std::uint32_t k : scratch.overflow) contact_fn(scratch.constraints[k]);
}

void finalize(World& world, SolverScratch& scratch) {
    Bodies& b = world.bodies;
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    world.jobs->parallel_for("FinalizeBodies", 0, n, kBodyGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t k = lo; k < hi; ++k) {
            const std::uint32_t i = world.awake[k];
            const SolverBody& sb = scratch.bodies[k];
            b.x[i] += sb.dp;
            b.q[i] = (sb.dq * b.q[i]).normalized();
            b.v[i] = sb.v;
            b.w[i] = sb.w;
            b.force[i] = Vec3::Zero();  // consumed by this step
            b.torque[i] = Vec3::Zero();
        }
    });
}

void store_impulses(World& world, SolverScratch& scratch) {
    const auto count = static_cast<std::uint32_t>(scratch.constraints.size());
    world.jobs->parallel_for("StoreImpulses", 0, count, kConstraintGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t k = lo; k < hi; ++k) {
            const ContactConstraint& cc = scratch.constraints[k];
            ContactManifold& m = world.contacts[cc.contact].manifold_at(cc.manifold);
            for (int j = 0; j < cc.point_count; ++j) {
                m.points[j].normal_impulse = cc.points[j].normal_impulse;
                m.points[j].tangent_impulse[0] = cc.points[j].tangent_impulse[0];
                m.points[j].tangent_impulse[1] = cc.points[j].tangent_impulse[1];
                m.points[j].max_normal_impulse = cc.points[j].max_normal_impulse;
                m.points[j].relative_velocity = cc.points[j].relative_velocity;
            }
        }
    });
}

}  // namespace

void solve(World& world, Real dt) {
    SolverScratch& scratch = *world.solver;
    const SolverSettings& settings = world.settings.solver;
    const int substeps = settings.substeps;
    const Real h = dt / substeps;

    prepare(world, scratch, h);
    prepare_joints(world, scratch, h);  // nothing to do in a scene without joints
    color(world, scratch);
    SolverBody* bodies = scratch.bodies.data();

    SolveParams solve_params;
    // The contact spring may not be stiffer than a quarter of the substep rate.
    const Real stiffest = Real(0.25) / h;
    const Real hertz = settings.contact_hertz > 0 ? std::min(settings.contact_hertz, stiffest) : stiffest;
    solve_params.soft = make_softness(hertz, settings.damping_ratio, h);
    solve_params.inv_h = 1 / h;
    solve_params.push_out = settings.push_out_speed;
    solve_params.slop = settings.linear_slop;
    solve_params.recovery_depth = settings.recovery_depth;
    SolveParams relax_params = solve_params;
    relax_params.use_bias = false;
    const JointSolveParams joint_solve{joint_softness(settings, h), 1 / h, true};
    const JointSolveParams joint_relax{joint_solve.soft, joint_solve.inv_h, false};

    for (int sub = 0; sub < substeps; ++sub) {
        integrate_velocities(world, bodies, h);
        for_each_colored(
            world, scratch, "WarmStart", [&](JointConstraint& jc) { warm_start_joint(jc, bodies); },
            [&](ContactConstraint& cc) { warm_start(cc, bodies); });
        for (int it = 0; it < settings.iterations; ++it) {
            for_each_colored(
                world, scratch, "Solve", [&](JointConstraint& jc) { solve_joint(jc, bodies, joint_solve); },
                [&](ContactConstraint& cc) { solve_contact(cc, bodies, solve_params); });
        }
        integrate_positions(world, bodies, h);
        for (int it = 0; it < settings.relax_iterations; ++it) {
            for_each_colored(
                world, scratch, "Relax", [&](JointConstraint& jc) { solve_joint(jc, bodies, joint_relax); },
                [&](ContactConstraint& cc) { solve_contact(cc, bodies, relax_params); });
        }
    }
    for_each_colored<false>(
        world, scratch, "Restitution", [](JointConstraint&) {},
        [&](ContactConstraint& cc) { apply_restitution(cc, bodies, settings.restitution_threshold, h); });
    store_impulses(world, scratch);
    if (!scratch.joints.empty()) store_joint_impulses(world, scratch);
    finalize(world, scratch);

    // Work counters, derived from the constraint set (no per-point counting in the hot loop).
    std::uint64_t points = 0, friction_points = 0, restitution_points = 0;
    for (const ContactConstraint& cc : scratch.constraints) {
        points += static_cast<std::uint64_t>(cc.point_count);
        if (cc.friction > 0) friction_points += static_cast<std::uint64_t>(cc.point_count);
        if (cc.restitution > 0) restitution_points += static_cast<std::uint64_t>(cc.point_count);
    }
    const auto passes = static_cast<std::uint64_t>(substeps * (settings.iterations + settings.relax_iterations));
    world.counters.contact_points_solved += points * passes;
    world.counters.friction_applied += friction_points * passes;
    world.counters.restitution_applied += restitution_points;
    world.counters.joints_solved += static_cast<std::uint64_t>(scratch.joints.size()) * passes;
    world.counters.bodies_integrated += world.awake.size();
}

}  // namespace spindle
