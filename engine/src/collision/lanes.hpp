// Four doubles worked on together, and a polyhedron's vertices laid out that way: what the
// SAT's support queries (sat.cpp) and a hull's bounds (convex_hull.cpp) loop over; and an
// edge with its Gauss-map arc, alone and four in lanes, which a hull keeps made for the SAT.
#pragma once

#include <cstdint>

#include <spindle/engine/math.hpp>

namespace spindle::detail {

// GCC's vector extensions: AVX where the build has it. Each lane computes what the scalar
// code computes, in the same order, so the results are the same bits.
using Lanes = double __attribute__((vector_size(4 * sizeof(double))));
using LaneMask = std::int64_t __attribute__((vector_size(4 * sizeof(std::int64_t))));
// Bit k set when lane k is set.
inline unsigned lane_bits(LaneMask m) {
#ifdef __AVX__
    return static_cast<unsigned>(__builtin_ia32_movmskpd256(reinterpret_cast<Lanes>(m)));
#else
    return (m[0] ? 1u : 0u) | (m[1] ? 2u : 0u) | (m[2] ? 4u : 0u) | (m[3] ? 8u : 0u);
#endif
}
// The square root of each lane.
inline Lanes lane_sqrt(Lanes x) {
#ifdef __AVX__
    return __builtin_ia32_sqrtpd256(x);
#else
    for (int k = 0; k < 4; ++k) x[k] = __builtin_sqrt(x[k]);
    return x;
#endif
}

// The magnitude of each lane (its sign bit cleared, as std::abs does).
inline Lanes lane_abs(Lanes x) {
    constexpr std::int64_t kMagnitude = 0x7fffffffffffffff;
    return reinterpret_cast<Lanes>(reinterpret_cast<LaneMask>(x) & kMagnitude);
}

// Vertices in lanes: lane k of group i holds vertex 4i + k; lanes past the last vertex
// repeat vertex 0, which never wins a support query over it (ties go to the lower index)
// and leaves a minimum or maximum as it is.
struct VertexLanes {
    Lanes x, y, z;
};

// An edge in the common frame with what the Gauss-map test needs: the edge's arc
// holds direction x when x . t0 >= 0 and x . t1 >= 0 (see on_edge_arc).
struct ArcEdge {
    Vec3 origin;
    Vec3 direction;
    Vec3 n0, n1;  // normals of the two faces
    Vec3 t0, t1;  // direction x n0, n1 x direction
};

// Four edges' arcs in lanes, lane k of group i holding edge 4i + k: what the edge query's
// bound on an arc's reach and its cheap rejections read, four edges at a time (sat.cpp).
// Lanes past the last edge hold a unit direction (`dd` one: no 0 / 0) and zero normals;
// the query masks them off.
struct ArcLanes {
    Lanes dx, dy, dz;     // direction
    Lanes dd;             // direction's squared norm, as Eigen sums it: x x + (y y + z z)
    Lanes n0x, n0y, n0z;  // normals of the two faces
    Lanes n1x, n1y, n1z;
    Lanes t0x, t0y, t0z;  // direction x n0
    Lanes t1x, t1y, t1z;  // n1 x direction
};

// edges[0, count) into (count + 3) / 4 groups of lanes.
inline void fill_arc_lanes(const ArcEdge* edges, std::uint32_t count, ArcLanes* out) {
    const Vec3 zero = Vec3::Zero();
    const ArcEdge past_the_last{zero, Vec3::UnitX(), zero, zero, zero, zero};  // its t0, t1 are zero too
    for (std::uint32_t k = 0; k < (count + 3) / 4 * 4; ++k) {
        ArcLanes& l = out[k / 4];
        const std::uint32_t lane = k % 4;
        const ArcEdge& e = k < count ? edges[k] : past_the_last;
        l.dx[lane] = e.direction.x(), l.dy[lane] = e.direction.y(), l.dz[lane] = e.direction.z();
        l.dd[lane] = e.direction.squaredNorm();
        l.n0x[lane] = e.n0.x(), l.n0y[lane] = e.n0.y(), l.n0z[lane] = e.n0.z();
        l.n1x[lane] = e.n1.x(), l.n1y[lane] = e.n1.y(), l.n1z[lane] = e.n1.z();
        l.t0x[lane] = e.t0.x(), l.t0y[lane] = e.t0.y(), l.t0z[lane] = e.t0.z();
        l.t1x[lane] = e.t1.x(), l.t1y[lane] = e.t1.y(), l.t1z[lane] = e.t1.z();
    }
}

}  // namespace spindle::detail
