// The speed limits of SolverSettings (max_linear_speed, max_angular_speed), applied
// wherever a velocity is written: integration, buffered writes, creation. With them no
// finite input, however large, makes a velocity or a position infinite.
#pragma once

#include <algorithm>

#include <cmath>

#include <spindle/engine/math.hpp>

namespace spindle {

// The direction of a non-zero v without NaN, as a unit vector; infinite components (a
// finite input that overflowed on the way) dominate. Scaled before squaring, since the
// square of a huge component overflows.
inline Vec3 unit_of(const Vec3& v) {
    if (!is_finite(v)) {
        Vec3 sign = Vec3::Zero();
        for (int k = 0; k < 3; ++k) {
            if (std::isinf(v[k])) sign[k] = std::copysign(Real(1), v[k]);
        }
        return sign.normalized();
    }
    return (v / v.cwiseAbs().maxCoeff()).normalized();
}

// v, or v shortened to `limit` keeping its direction. Below the limit v is returned
// untouched (bit for bit). NaN passes through: it is a bug upstream, for the state check
// (SPINDLE_VALIDATE_STATE) to find, not something to hide.
inline Vec3 limit_speed(const Vec3& v, Real limit) {
    if (!(v.squaredNorm() > limit * limit)) return v;
    return limit * unit_of(v);
}

// v + scale * (m * j) for an inverse inertia m and a finite torque or impulse j, exactly
// as written while that is finite. When a huge j makes it overflow (m j may then hold
// inf - inf, a NaN), a vector of length `limit` in m j's direction instead: what the
// speed limit would have made of it.
// The overflow case apart and out of line, so that the sum is inlined where it is hot
// (the integrator's loops).
[[gnu::noinline, gnu::cold]] inline Vec3 overflowed_angular(const Mat3& m, const Vec3& j, Real limit) {
    return limit * unit_of(m * (j / j.cwiseAbs().maxCoeff()));
}
inline Vec3 add_angular(const Vec3& v, Real scale, const Mat3& m, const Vec3& j, Real limit) {
    const Vec3 sum = v + scale * (m * j);
    if (is_finite(sum)) [[likely]]
        return sum;
    return overflowed_angular(m, j, limit);
}

// An accumulated force or torque stays finite however many huge ones are added.
inline Vec3 saturate(const Vec3& v) { return v.cwiseMax(Vec3::Constant(-kHuge)).cwiseMin(Vec3::Constant(kHuge)); }

// a x b with each product held to +-kHuge before the differences: huge finite inputs may
// give an infinite component (which saturate() takes back) but never inf - inf, a NaN.
inline Vec3 saturated_cross(const Vec3& a, const Vec3& b) {
    auto product = [](Real x, Real y) { return std::clamp(x * y, -kHuge, kHuge); };
    return Vec3(product(a.y(), b.z()) - product(a.z(), b.y()), product(a.z(), b.x()) - product(a.x(), b.z()),
                product(a.x(), b.y()) - product(a.y(), b.x()));
}

}  // namespace spindle
