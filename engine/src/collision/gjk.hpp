// GJK distance between the convex hulls of two small point sets given in one frame:
// used for the cores of rounded shapes (a point or a segment) against a polyhedron.
#pragma once

#include <spindle/engine/math.hpp>

namespace spindle::detail {

struct GjkResult {
    Vec3 point_a = Vec3::Zero();  // closest point on hull(a)
    Vec3 point_b = Vec3::Zero();  // closest point on hull(b)
    Real distance = 0;            // 0 when the hulls overlap (then the points mean nothing)
    bool overlap = false;
};

GjkResult gjk_distance(const Vec3* a, int a_count, const Vec3* b, int b_count);

}  // namespace spindle::detail
