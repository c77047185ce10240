// Math types for the engine: Eigen fixed-size types in double precision (so a stack
// 10 km from the origin and the analytic tests keep their accuracy), plus the few
// helpers every stage needs.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>

namespace spindle {

using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Quat = Eigen::Quaternion<Real>;

inline constexpr Real kPi = 3.14159265358979323846;
inline constexpr Real kHuge = std::numeric_limits<Real>::max();

inline bool is_finite(Real x) noexcept { return std::isfinite(x); }
inline bool is_finite(const Vec3& v) noexcept { return v.allFinite(); }
inline bool is_finite(const Quat& q) noexcept { return q.coeffs().allFinite(); }

// A rigid transform: rotate by q, then translate by p.
struct Transform {
    Vec3 p = Vec3::Zero();
    Quat q = Quat::Identity();

    Vec3 apply(const Vec3& local) const { return p + q * local; }
    Vec3 apply_inverse(const Vec3& world) const { return q.conjugate() * (world - p); }
    Vec3 rotate(const Vec3& local) const { return q * local; }
    Vec3 rotate_inverse(const Vec3& world) const { return q.conjugate() * world; }
    // this * other: first other, then this.
    Transform operator*(const Transform& other) const { return {apply(other.p), q * other.q}; }
    Transform inverse() const {
        const Quat qi = q.conjugate();
        return {-(qi * p), qi};
    }
};

// Axis-aligned bounding box.
struct Aabb {
    Vec3 min = Vec3::Constant(kHuge);
    Vec3 max = Vec3::Constant(-kHuge);

    static Aabb from_center_extents(const Vec3& c, const Vec3& e) { return {c - e, c + e}; }
    bool overlaps(const Aabb& o) const {
        return (min.array() <= o.max.array()).all() && (o.min.array() <= max.array()).all();
    }
    bool contains(const Aabb& o) const {
        return (min.array() <= o.min.array()).all() && (o.max.array() <= max.array()).all();
    }
    Aabb merged(const Aabb& o) const { return {min.cwiseMin(o.min), max.cwiseMax(o.max)}; }
    Aabb fattened(Real margin) const { return {min.array() - margin, max.array() + margin}; }
    void include(const Vec3& v) {
        min = min.cwiseMin(v);
        max = max.cwiseMax(v);
    }
    Vec3 center() const { return (min + max) * Real(0.5); }
    Vec3 extents() const { return (max - min) * Real(0.5); }
    // Half the surface area (the SAH cost the tree minimises).
    Real perimeter() const {
        const Vec3 d = max - min;
        return d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
    }
    bool valid() const { return (min.array() <= max.array()).all(); }
};

// Unit quaternion integration: q' = normalize(q + 0.5 * dt * (0, w) * q).
inline Quat integrate_rotation(const Quat& q, const Vec3& w, Real dt) {
    const Quat dq(0, w.x() * dt * Real(0.5), w.y() * dt * Real(0.5), w.z() * dt * Real(0.5));
    Quat r = q;
    r.coeffs() += (dq * q).coeffs();
    return r.normalized();
}

// Slerp on the shortest arc; t = 0 gives a, t = 1 gives b.
inline Quat slerp_shortest(const Quat& a, const Quat& b, Real t) {
    Quat bb = b;
    if (a.dot(b) < 0) bb.coeffs() = -b.coeffs();
    return a.slerp(t, bb);
}

}  // namespace spindle
