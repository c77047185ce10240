// Number formatting for the error messages shape factories throw ("got -1", "got (1, nan, 0)").
#pragma once

#include <charconv>
#include <string>

#include <spindle/engine/math.hpp>

namespace spindle {

// The world's bound: positions, and a shape's sizes, points and vertices (from its origin),
// within a billion metres (api/validation.cpp checks positions, the factories shapes): far
// enough for any game world, near enough that squared distances, bounds, a shape's plane
// tests and areas and the step's sums stay finite.
inline constexpr Real kMaxCoordinate = 1e9;

}  // namespace spindle

namespace spindle::detail {

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
