// Compounds the compound tests share: a dumbbell and a table, with their measures.
#pragma once

#include <spindle/engine/shape.hpp>

#include <functional>
#include <string>

namespace spindle::test {

// Two balls of radius kBell at x = +-kBellOffset, joined by a bar (a capsule along x).
inline constexpr Real kBell = 0.3;
inline constexpr Real kBellOffset = 0.6;
Shape dumbbell();

// A top (half extents kTopHalf) on four legs (half extents kLegHalf) at x = +-kLegX,
// z = +-kLegZ; the legs stand on y = 0 of the shape's frame, the top is at kTableHeight.
inline constexpr Real kLegX = 0.8, kLegZ = 0.45;
inline const Vec3 kLegHalf{0.06, 0.3, 0.06};
inline const Vec3 kTopHalf{1.0, 0.05, 0.6};
inline constexpr Real kTableHeight = 0.7;
Shape table();

// The message of the spindle::Error the call throws ("" when it throws none).
std::string error_of(const std::function<void()>& call);

}  // namespace spindle::test
