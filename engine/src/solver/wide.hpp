// Wide: eight floats worked on together, the engine's one SIMD header. GCC's vector
// extensions compile it to one AVX instruction when the build enables AVX and to two
// SSE halves otherwise, with no intrinsics to port but the square root's (wide_sqrt);
// every operation is IEEE lane by lane, so both give the same bits. The contact solver
// puts eight manifolds of one colour in the lanes, so the dependent chain of one
// manifold's Gauss-Seidel rows overlaps seven others instead of stalling on its own
// latency. Floats are enough for what it keeps (Box2D v3 and Box3D solve in floats):
// anchors and separations are relative to the bodies, positions stay in double in the
// bodies themselves.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#if defined(__AVX__)
#include <immintrin.h>
#endif

#include <spindle/engine/math.hpp>

namespace spindle {

inline constexpr int kLanes = 8;
using Wide = float __attribute__((vector_size(kLanes * sizeof(float))));
using WideMask = std::int32_t __attribute__((vector_size(kLanes * sizeof(std::int32_t))));  // lanes: 0 or -1

inline Wide splat(Real x) {
    const auto f = static_cast<float>(x);
    return Wide{f, f, f, f, f, f, f, f};
}
inline Wide wide_max(Wide a, Wide b) { return a > b ? a : b; }
inline Wide wide_min(Wide a, Wide b) { return a < b ? a : b; }
inline Wide select(WideMask m, Wide if_set, Wide if_clear) { return m ? if_set : if_clear; }
inline bool any(WideMask m) {
    std::int32_t set = 0;
    for (int i = 0; i < kLanes; ++i) set |= m[i];
    return set != 0;
}
// One instruction where the target has eight-lane vectors: the lane loop compiles to eight
// scalar roots, each behind a branch to sqrtf for errno. IEEE roots round correctly either
// way, so the lanes get the same bits.
inline Wide wide_sqrt(Wide a) {
#if defined(__AVX__)
    static_assert(kLanes == 8, "one __m256 of lanes");
    return _mm256_sqrt_ps(a);
#else
    Wide r;
    for (int i = 0; i < kLanes; ++i) r[i] = __builtin_sqrtf(a[i]);
    return r;
#endif
}

// Eight rows of eight lanes turned into eight columns (the 8x8 transpose Box2D v3
// gathers its bodies with): three rounds of shuffles instead of 64 lane inserts.
[[gnu::always_inline]] inline void transpose(Wide (&r)[8]) {
    static_assert(kLanes == 8, "an 8x8 transpose");
    Wide t[8], u[8];
    for (int i = 0; i < 8; i += 2) {
        t[i] = __builtin_shufflevector(r[i], r[i + 1], 0, 8, 1, 9, 4, 12, 5, 13);
        t[i + 1] = __builtin_shufflevector(r[i], r[i + 1], 2, 10, 3, 11, 6, 14, 7, 15);
    }
    for (int i = 0; i < 8; i += 4) {
        for (int k = 0; k < 2; ++k) {
            u[i + 2 * k] = __builtin_shufflevector(t[i + k], t[i + k + 2], 0, 1, 8, 9, 4, 5, 12, 13);
            u[i + 2 * k + 1] = __builtin_shufflevector(t[i + k], t[i + k + 2], 2, 3, 10, 11, 6, 7, 14, 15);
        }
    }
    for (int k = 0; k < 4; ++k) {
        r[k] = __builtin_shufflevector(u[k], u[k + 4], 0, 1, 2, 3, 8, 9, 10, 11);
        r[k + 4] = __builtin_shufflevector(u[k], u[k + 4], 4, 5, 6, 7, 12, 13, 14, 15);
    }
}

// Eight doubles from memory as a row of floats (rounded to nearest, as a scalar cast), and
// back: the first `count` lanes stored as doubles.
using Double4 = double __attribute__((vector_size(4 * sizeof(double))));
using Float4 = float __attribute__((vector_size(4 * sizeof(float))));
inline Wide load_narrow(const Real* p) {
    Double4 lo, hi;
    std::memcpy(&lo, p, sizeof lo);
    std::memcpy(&hi, p + 4, sizeof hi);
    return __builtin_shufflevector(__builtin_convertvector(lo, Float4), __builtin_convertvector(hi, Float4), 0, 1, 2, 3,
                                   4, 5, 6, 7);
}
inline void store_widened6(Real* p, Wide row) {
    const Double4 lo = __builtin_convertvector(__builtin_shufflevector(row, row, 0, 1, 2, 3), Double4);
    const Double4 hi = __builtin_convertvector(__builtin_shufflevector(row, row, 4, 5, 6, 7), Double4);
    std::memcpy(p, &lo, sizeof lo);
    std::memcpy(p + 4, &hi, 2 * sizeof(Real));
}

// A vector per lane, as three Wide components (structure of arrays).
struct Wide3 {
    Wide x{}, y{}, z{};

    Vec3 lane(int i) const { return {Real(x[i]), Real(y[i]), Real(z[i])}; }
    void set_lane(int i, const Vec3& v) {
        x[i] = static_cast<float>(v.x());
        y[i] = static_cast<float>(v.y());
        z[i] = static_cast<float>(v.z());
    }
};

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
            for (int c = 0; c < 3; ++c) m[r][c][i] = static_cast<float>(a(r, c));
        }
    }
};

inline Wide3 operator*(const WideMat3& a, const Wide3& v) {
    return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z, a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
            a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}

// A symmetric 3x3 matrix per lane (an inverse inertia, an effective mass): six entries.
struct WideSym3 {
    Wide xx{}, xy{}, xz{}, yy{}, yz{}, zz{};

    void set_lane(int i, const Mat3& a) {
        xx[i] = static_cast<float>(a(0, 0));
        xy[i] = static_cast<float>(a(0, 1));
        xz[i] = static_cast<float>(a(0, 2));
        yy[i] = static_cast<float>(a(1, 1));
        yz[i] = static_cast<float>(a(1, 2));
        zz[i] = static_cast<float>(a(2, 2));
    }
};

inline Wide3 operator*(const WideSym3& a, const Wide3& v) {
    return {a.xx * v.x + a.xy * v.y + a.xz * v.z, a.xy * v.x + a.yy * v.y + a.yz * v.z,
            a.xz * v.x + a.yz * v.y + a.zz * v.z};
}

// A unit quaternion per lane.
struct WideQuat {
    Wide3 v;  // x, y, z
    Wide w{};

    void set_lane(int i, const Quat& q) {
        v.set_lane(i, q.vec());
        w[i] = static_cast<float>(q.w());
    }
};

// q applied to a: a + 2w (v x a) + 2 v x (v x a).
inline Wide3 rotate(const WideQuat& q, const Wide3& a) {
    const Wide3 t = cross(q.v, a);
    const Wide two = splat(2);
    return a + (two * q.w) * t + two * cross(q.v, t);
}

// q^-1 applied to a: a - 2w (v x a) + 2 v x (v x a).
inline Wide3 rotate_inverse(const WideQuat& q, const Wide3& a) {
    const Wide3 t = cross(q.v, a);
    const Wide two = splat(2);
    return a - (two * q.w) * t + two * cross(q.v, t);
}

// R a R^T for the rotation R of the unit quaternion q: a symmetric matrix turned by q
// (an inverse inertia given in the world at the step's start, turned with its body since).
inline WideSym3 turned(const WideSym3& a, const WideQuat& q) {
    const Wide one = splat(1), two = splat(2);
    const Wide x = q.v.x, y = q.v.y, z = q.v.z, w = q.w;
    const Wide r00 = one - two * (y * y + z * z), r01 = two * (x * y - w * z), r02 = two * (x * z + w * y);
    const Wide r10 = two * (x * y + w * z), r11 = one - two * (x * x + z * z), r12 = two * (y * z - w * x);
    const Wide r20 = two * (x * z - w * y), r21 = two * (y * z + w * x), r22 = one - two * (x * x + y * y);
    // m = R a, by rows; then (m R^T)_ij = m_i . R_j.
    const Wide m00 = r00 * a.xx + r01 * a.xy + r02 * a.xz, m01 = r00 * a.xy + r01 * a.yy + r02 * a.yz,
               m02 = r00 * a.xz + r01 * a.yz + r02 * a.zz;
    const Wide m10 = r10 * a.xx + r11 * a.xy + r12 * a.xz, m11 = r10 * a.xy + r11 * a.yy + r12 * a.yz,
               m12 = r10 * a.xz + r11 * a.yz + r12 * a.zz;
    const Wide m20 = r20 * a.xx + r21 * a.xy + r22 * a.xz, m21 = r20 * a.xy + r21 * a.yy + r22 * a.yz,
               m22 = r20 * a.xz + r21 * a.yz + r22 * a.zz;
    return {m00 * r00 + m01 * r01 + m02 * r02, m00 * r10 + m01 * r11 + m02 * r12, m00 * r20 + m01 * r21 + m02 * r22,
            m10 * r10 + m11 * r11 + m12 * r12, m10 * r20 + m11 * r21 + m12 * r22, m20 * r20 + m21 * r21 + m22 * r22};
}

// Eight lanes of doubles, for preparing: the contact solver prepares its rows in double
// lane by lane, as scalar code would, and keeps them in floats. The sums of three
// products here are Eigen's (x0 + (x1 + x2): it unrolls a sum of three by halves), so a
// lane gets the same bits as Eigen's scalar dot or matrix product on that lane's values.
using WideD = double __attribute__((vector_size(kLanes * sizeof(double))));
using WideDMask = std::int64_t __attribute__((vector_size(kLanes * sizeof(std::int64_t))));  // lanes: 0 or -1

inline WideD splat_d(Real x) { return WideD{x, x, x, x, x, x, x, x}; }
// By the bits: GCC splits `m ? a : b` on vectors wider than the target's lane by lane.
inline WideD select(WideDMask m, WideD if_set, WideD if_clear) {
    return reinterpret_cast<WideD>((m & reinterpret_cast<WideDMask>(if_set)) |
                                   (~m & reinterpret_cast<WideDMask>(if_clear)));
}
// The lanes' sign bits, lane i in bit i: a mask's set lanes.
inline unsigned lane_bits(WideDMask m) {
#if defined(__AVX__)
    const auto lo = reinterpret_cast<__m256d>(__builtin_shufflevector(m, m, 0, 1, 2, 3));
    const auto hi = reinterpret_cast<__m256d>(__builtin_shufflevector(m, m, 4, 5, 6, 7));
    return static_cast<unsigned>(_mm256_movemask_pd(lo)) | static_cast<unsigned>(_mm256_movemask_pd(hi)) << 4;
#else
    unsigned bits = 0;
    for (int i = 0; i < kLanes; ++i) bits |= (m[i] < 0 ? 1u : 0u) << i;
    return bits;
#endif
}
inline bool any(WideDMask m) { return lane_bits(m) != 0; }
inline bool all(WideDMask m) { return lane_bits(m) == (1u << kLanes) - 1; }
// |a| >= b lane by lane, as std::abs(a) >= b: the sign bit cleared.
inline WideDMask abs_at_least(WideD a, WideD b) {
    constexpr std::int64_t kMagnitude = 0x7fffffffffffffff;
    return reinterpret_cast<WideD>(reinterpret_cast<WideDMask>(a) & kMagnitude) >= b;
}
// a > b ? a : b and a < b ? a : b lane by lane: where either is NaN, b (x86's maxpd and
// minpd, one instruction a half; GCC splits the vector ternary lane by lane).
#if defined(__AVX__)
template <class Op>
inline WideD by_halves(WideD a, WideD b, Op op) {
    const Double4 lo = op(__builtin_shufflevector(a, a, 0, 1, 2, 3), __builtin_shufflevector(b, b, 0, 1, 2, 3));
    const Double4 hi = op(__builtin_shufflevector(a, a, 4, 5, 6, 7), __builtin_shufflevector(b, b, 4, 5, 6, 7));
    return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
}
inline WideD wide_max(WideD a, WideD b) {
    return by_halves(a, b, [](Double4 x, Double4 y) -> Double4 { return _mm256_max_pd(x, y); });
}
inline WideD wide_min(WideD a, WideD b) {
    return by_halves(a, b, [](Double4 x, Double4 y) -> Double4 { return _mm256_min_pd(x, y); });
}
#else
inline WideD wide_max(WideD a, WideD b) {
    WideD r;
    for (int i = 0; i < kLanes; ++i) r[i] = a[i] > b[i] ? a[i] : b[i];
    return r;
}
inline WideD wide_min(WideD a, WideD b) {
    WideD r;
    for (int i = 0; i < kLanes; ++i) r[i] = a[i] < b[i] ? a[i] : b[i];
    return r;
}
#endif
inline Wide narrow(WideD a) { return __builtin_convertvector(a, Wide); }  // each lane rounded as a scalar cast
inline WideD wide_sqrt(WideD a) {
#if defined(__AVX__)
    static_assert(kLanes == 8, "two __m256d of lanes");
    const Double4 lo = _mm256_sqrt_pd(__builtin_shufflevector(a, a, 0, 1, 2, 3));
    const Double4 hi = _mm256_sqrt_pd(__builtin_shufflevector(a, a, 4, 5, 6, 7));
    return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
#else
    WideD r;
    for (int i = 0; i < kLanes; ++i) r[i] = __builtin_sqrt(a[i]);
    return r;
#endif
}

// Not zeroed when default-built (WideD3{} is zero): preparing writes what it reads.
struct WideD3 {
    WideD x, y, z;

    void set_lane(int i, const Vec3& v) {
        x[i] = v.x();
        y[i] = v.y();
        z[i] = v.z();
    }
};

inline WideD3 operator+(const WideD3& a, const WideD3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline WideD3 operator-(const WideD3& a, const WideD3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline WideD3 operator*(WideD s, const WideD3& v) { return {s * v.x, s * v.y, s * v.z}; }
inline WideD3 operator/(const WideD3& v, WideD s) { return {v.x / s, v.y / s, v.z / s}; }
inline WideD3 select(WideDMask m, const WideD3& if_set, const WideD3& if_clear) {
    return {select(m, if_set.x, if_clear.x), select(m, if_set.y, if_clear.y), select(m, if_set.z, if_clear.z)};
}
inline WideD dot(const WideD3& a, const WideD3& b) { return a.x * b.x + (a.y * b.y + a.z * b.z); }
inline WideD3 cross(const WideD3& a, const WideD3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Wide3 narrow(const WideD3& v) { return {narrow(v.x), narrow(v.y), narrow(v.z)}; }

// A 3x3 matrix per lane, row-major.
struct WideDMat3 {
    WideD m[3][3];

    void set_lane(int i, const Mat3& a) {
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) m[r][c][i] = a(r, c);
        }
    }
};

inline WideD3 operator*(const WideDMat3& a, const WideD3& v) {
    return {a.m[0][0] * v.x + (a.m[0][1] * v.y + a.m[0][2] * v.z),
            a.m[1][0] * v.x + (a.m[1][1] * v.y + a.m[1][2] * v.z),
            a.m[2][0] * v.x + (a.m[2][1] * v.y + a.m[2][2] * v.z)};
}
inline WideMat3 narrow(const WideDMat3& a) {
    WideMat3 n;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) n.m[r][c] = narrow(a.m[r][c]);
    }
    return n;
}

}  // namespace spindle
