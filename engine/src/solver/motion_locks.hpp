// Motion locks (BodyDesc::locks) as the engine keeps them: six bits per body, and the
// projections that make them exact. A locked axis gets an exact zero, never a small
// number, so a locked coordinate does not drift however long the body moves.
#pragma once

#include <cstdint>

#include <spindle/engine/body.hpp>
#include <spindle/engine/math.hpp>

namespace spindle {

// Bit k: translation along world axis k locked; bit 3 + k: rotation about it.
inline constexpr std::uint8_t kLockTranslation = 0b000111;
inline constexpr std::uint8_t kLockRotation = 0b111000;

inline std::uint8_t lock_bits(const MotionLocks& l) {
    const bool bits[6] = {l.translation_x, l.translation_y, l.translation_z, l.rotation_x, l.rotation_y, l.rotation_z};
    std::uint8_t out = 0;
    for (int k = 0; k < 6; ++k) out = static_cast<std::uint8_t>(out | (bits[k] ? 1u << k : 0u));
    return out;
}

// v without the components along the locked axes of `axes` (3 bits). Zeros are
// selected, not multiplied in, so an infinite component cannot turn into NaN.
inline Vec3 without_axes(const Vec3& v, unsigned axes) {
    if (axes == 0) return v;
    return {(axes & 1u) ? Real(0) : v.x(), (axes & 2u) ? Real(0) : v.y(), (axes & 4u) ? Real(0) : v.z()};
}
inline Vec3 project_linear(const Vec3& v, std::uint8_t locks) { return without_axes(v, locks & kLockTranslation); }
inline Vec3 project_angular(const Vec3& w, std::uint8_t locks) { return without_axes(w, (locks & kLockRotation) >> 3); }

// The inverse mass seen along a unit direction: inv_mass, or its share along the free axes.
inline Real inverse_mass_along(Real inv_mass, std::uint8_t locks, const Vec3& dir) {
    if ((locks & kLockTranslation) == 0) return inv_mass;
    return inv_mass * project_linear(dir, locks).squaredNorm();
}

// The world inverse inertia of a body whose rotation is locked about some world axes:
// the inverse of the inertia's free block, zero on the locked rows and columns. This is
// the constrained body's (as Jolt's allowed DOFs): a box turning about z alone answers
// a torque about z with 1 / I_zz, whatever the tilt of its principal axes. Projecting
// the free body's inverse inertia instead would give (I^-1)_zz, which is larger when
// the axes couple.
inline Mat3 locked_inverse_inertia(const Mat3& inertia_world, std::uint8_t locks) {
    const unsigned locked = (locks & kLockRotation) >> 3;
    if (locked == 0b111) return Mat3::Zero();
    Mat3 free_block = inertia_world;
    for (int k = 0; k < 3; ++k) {
        if ((locked & (1u << k)) == 0) continue;
        free_block.row(k).setZero();
        free_block.col(k).setZero();
        free_block(k, k) = 1;
    }
    Mat3 inverse = free_block.inverse();
    for (int k = 0; k < 3; ++k) {
        if ((locked & (1u << k)) == 0) continue;
        inverse.row(k).setZero();
        inverse.col(k).setZero();
    }
    return inverse;
}

}  // namespace spindle
