// Four doubles worked on together, and a polyhedron's vertices laid out that way: what the
// SAT's support queries (sat.cpp) and a hull's bounds (convex_hull.cpp) loop over; and an
// edge with its Gauss-map arc, which a hull keeps made for the SAT.
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

}  // namespace spindle::detail
