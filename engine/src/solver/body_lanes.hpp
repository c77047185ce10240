// The bodies of kLanes constraints of one colour in floats, a lane each: gathered from
// the solver bodies' doubles before a pass over the constraints and scattered back after
// it. Shared by the solvers that work on lanes (contact_solver.cpp, joint_lanes.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "solver/solver_body.hpp"
#include "solver/wide.hpp"

namespace spindle {

// The lanes' body velocities while constraints are solved. gather and scatter are forced
// inline: as calls they returned and copied their result per pass.
struct WideVelocities {
    Wide3 va, wa, vb, wb;
};

// A solver body read as a row of doubles: v, w from its start, dp and dq (x, y, z, w)
// from the sixth. Eight lanes' rows are loaded, narrowed and transposed into columns.
static_assert(std::is_standard_layout_v<SolverBody> && offsetof(SolverBody, v) == 0 &&
                  offsetof(SolverBody, w) == 3 * sizeof(Real) && offsetof(SolverBody, dp) == 6 * sizeof(Real) &&
                  offsetof(SolverBody, dq) == 9 * sizeof(Real) && sizeof(SolverBody) >= 14 * sizeof(Real),
              "the solver's gather reads a body's v, w, dp and dq as consecutive doubles");
inline constexpr int kVelocityRow = 0, kMotionRow = 6;

[[gnu::always_inline]] inline void gather_rows(const SolverBody* bodies, const std::uint32_t* index, int first,
                                               Wide (&rows)[kLanes]) {
    for (int l = 0; l < kLanes; ++l) rows[l] = load_narrow(reinterpret_cast<const Real*>(bodies + index[l]) + first);
    transpose(rows);
}

// Lanes: anything with the lanes' solver bodies in `a` and `b` (kLanes each).
template <typename Lanes>
[[gnu::always_inline]] inline WideVelocities gather(const Lanes& lanes, const SolverBody* bodies) {
    Wide a[kLanes], b[kLanes];
    gather_rows(bodies, lanes.a, kVelocityRow, a);
    gather_rows(bodies, lanes.b, kVelocityRow, b);
    return {{a[0], a[1], a[2]}, {a[3], a[4], a[5]}, {b[0], b[1], b[2]}, {b[3], b[4], b[5]}};
}

// Writes the dynamic bodies back: static and kinematic ones (and the empty lanes'
// immovable body) are shared by constraints of every colour and never written.
template <typename Lanes>
[[gnu::always_inline]] inline void scatter(const Lanes& lanes, SolverBody* bodies, const WideVelocities& s) {
    Wide a[kLanes] = {s.va.x, s.va.y, s.va.z, s.wa.x, s.wa.y, s.wa.z};
    Wide b[kLanes] = {s.vb.x, s.vb.y, s.vb.z, s.wb.x, s.wb.y, s.wb.z};
    transpose(a);
    transpose(b);
    for (int l = 0; l < kLanes; ++l) {
        SolverBody& A = bodies[lanes.a[l]];
        SolverBody& B = bodies[lanes.b[l]];
        if (A.dynamic) store_widened6(reinterpret_cast<Real*>(&A) + kVelocityRow, a[l]);
        if (B.dynamic) store_widened6(reinterpret_cast<Real*>(&B) + kVelocityRow, b[l]);
    }
}

// Adds the lanes' velocity changes `d` to the dynamic bodies' rows of `rows` (at the solver
// bodies' indices: SolverScratch::warm_velocities), as scatter writes the velocities.
template <typename Lanes>
[[gnu::always_inline]] inline void scatter_add(const Lanes& lanes, const SolverBody* bodies, PushVelocity* rows,
                                               const WideVelocities& d) {
    Wide a[kLanes] = {d.va.x, d.va.y, d.va.z, d.wa.x, d.wa.y, d.wa.z};
    Wide b[kLanes] = {d.vb.x, d.vb.y, d.vb.z, d.wb.x, d.wb.y, d.wb.z};
    transpose(a);
    transpose(b);
    auto add = [](PushVelocity& row, Wide change) {
        row.v += Vec3(Real(change[0]), Real(change[1]), Real(change[2]));
        row.w += Vec3(Real(change[3]), Real(change[4]), Real(change[5]));
    };
    for (int l = 0; l < kLanes; ++l) {
        if (bodies[lanes.a[l]].dynamic) add(rows[lanes.a[l]], a[l]);
        if (bodies[lanes.b[l]].dynamic) add(rows[lanes.b[l]], b[l]);
    }
}

// Velocity of B's anchor relative to A's, per lane.
inline Wide3 point_velocity(const WideVelocities& s, const Wide3& ra, const Wide3& rb) {
    return s.vb + cross(s.wb, rb) - s.va - cross(s.wa, ra);
}

}  // namespace spindle
