// Wide: four doubles worked on together, the engine's one SIMD header. GCC's vector
// extensions compile it to AVX when the build enables it and to two SSE2 halves
// otherwise, with no intrinsics to port. The contact solver puts four manifolds of one
// colour in the lanes, so the dependent chain of one manifold's Gauss-Seidel rows
// overlaps three others instead of stalling on its own latency.
#pragma once

#include <cmath>
#include <cstdint>

#include <spindle/engine/math.hpp>

namespace spindle {

inline constexpr int kLanes = 4;
using Wide = double __attribute__((vector_size(kLanes * sizeof(double))));
using WideMask = std::int64_t __attribute__((vector_size(kLanes * sizeof(std::int64_t))));  // lanes: 0 or -1

// Four floats, for data that is only read back (a contact's rows): half the memory a
// pass streams through. Widened to doubles before any arithmetic.
using WideF = float __attribute__((vector_size(kLanes * sizeof(float))));
inline Wide widen(WideF f) { return __builtin_convertvector(f, Wide); }
inline WideF narrow(Wide d) { return __builtin_convertvector(d, WideF); }

inline Wide splat(Real x) { return Wide{x, x, x, x}; }
inline Wide wide_max(Wide a, Wide b) { return a > b ? a : b; }
inline Wide wide_min(Wide a, Wide b) { return a < b ? a : b; }
inline Wide select(WideMask m, Wide if_set, Wide if_clear) { return m ? if_set : if_clear; }
inline bool any(WideMask m) { return (m[0] | m[1] | m[2] | m[3]) != 0; }
inline Wide wide_sqrt(Wide a) { return Wide{std::sqrt(a[0]), std::sqrt(a[1]), std::sqrt(a[2]), std::sqrt(a[3])}; }

// A vector per lane, as three Wide components (structure of arrays).
struct Wide3 {
    Wide x{}, y{}, z{};

    Vec3 lane(int i) const { return {x[i], y[i], z[i]}; }
    void set_lane(int i, const Vec3& v) {
        x[i] = v.x();
        y[i] = v.y();
        z[i] = v.z();
    }
};

// A Wide3 stored as floats.
struct Wide3F {
    WideF x{}, y{}, z{};

    void set_lane(int i, const Vec3& v) {
        x[i] = static_cast<float>(v.x());
        y[i] = static_cast<float>(v.y());
        z[i] = static_cast<float>(v.z());
    }
};
inline Wide3 widen(const Wide3F& v) { return {widen(v.x), widen(v.y), widen(v.z)}; }
inline Wide3F narrow(const Wide3& v) { return {narrow(v.x), narrow(v.y), narrow(v.z)}; }

inline Wide3 operator+(const Wide3& a, const Wide3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Wide3 operator-(const Wide3& a, const Wide3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Wide3 operator*(Wide s, const Wide3& v) { return {s * v.x, s * v.y, s * v.z}; }
inline Wide3& operator+=(Wide3& a, const Wide3& b) { return a = a + b; }
inline Wide3& operator-=(Wide3& a, const Wide3& b) { return a = a - b; }
inline Wide dot(const Wide3& a, const Wide3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Wide3 cross(const Wide3& a, const Wide3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// A 3x3 matrix per lane, row-major.
struct WideMat3 {
    Wide m[3][3]{};

    void set_lane(int i, const Mat3& a) {
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) m[r][c][i] = a(r, c);
        }
    }
};

inline Wide3 operator*(const WideMat3& a, const Wide3& v) {
    return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z, a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
            a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}

// A unit quaternion per lane.
struct WideQuat {
    Wide3 v;  // x, y, z
    Wide w{};

    void set_lane(int i, const Quat& q) {
        v.set_lane(i, q.vec());
        w[i] = q.w();
    }
};

// q^-1 applied to a: a - 2w (v x a) + 2 v x (v x a).
inline Wide3 rotate_inverse(const WideQuat& q, const Wide3& a) {
    const Wide3 t = cross(q.v, a);
    const Wide two = splat(2);
    return a - (two * q.w) * t + two * cross(q.v, t);
}

}  // namespace spindle
