// Number formatting for the error messages shape factories throw ("got -1", "got (1, nan, 0)").
#pragma once

#include <charconv>
#include <string>

#include <spindle/engine/math.hpp>

namespace spindle::detail {

// How far from its origin a hull's points and a mesh's vertices may lie: the bound of
// positions (api/validation.hpp's kMaxCoordinate, the same value), past which the plane
// tests, areas and bounds of the shape overflow.
inline constexpr Real kMaxShapeCoordinate = 1e9;

// Shortest text that reads back to the same double.
inline std::string to_text(Real x) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
    return std::string(buffer, result.ptr);
}

inline std::string to_text(const Vec3& v) {
    // Appended piecewise: GCC 12 warns (falsely) about chained operator+ on short strings.
    std::string text = "(";
    text.append(to_text(v.x())).append(", ").append(to_text(v.y())).append(", ").append(to_text(v.z()));
    text.push_back(')');
    return text;
}

}  // namespace spindle::detail
