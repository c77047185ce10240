// A convex shape as a core (a point set: a sphere's centre, a capsule's segment, a box's
// corners, a hull's vertices) plus a radius: the form gjk_distance() takes. Shape casts
// and the Continuous stage's sweeps measure distances on it.
#pragma once

#include <array>

#include <spindle/engine/math.hpp>
#include <spindle/engine/shape.hpp>

namespace spindle {

struct ConvexCore {
    static constexpr int kMaxPoints = 256;  // ConvexHull keeps at most this many vertices
    std::array<Vec3, kMaxPoints> points;
    int count = 0;
    Real radius = 0;
};

// Sphere, capsule, box or hull.
bool is_convex(const Shape& shape);
// The core of a convex shape posed by x in the query's frame.
void make_core(const Shape& shape, const Transform& x, ConvexCore& core);

// How far a dynamic body's shape reaches from its centre of mass along each of the body's
// own axes, and its thinnest half-size (a sphere's or capsule's radius, a box's least half
// extent, a hull's inner radius; the least over a compound's parts): Box3D's maxExtent and
// minExtent, which decide whether a step moves the body far enough to be swept. A turn
// moves the body's surface only as far as it moves its core: the rounding about the core (a
// sphere's, a capsule's) turns onto itself, so `core_reach` leaves it out.
struct SweepExtent {
    Vec3 reach = Vec3::Zero();
    Vec3 core_reach = Vec3::Zero();
    Real thinnest = 0;
    // reach's length (Box3D's maxExtent), made once: the narrowphase's recycling test asks
    // it of both bodies of every pair it tests, the continuous stage of every fast body.
    Real reach_length = 0;
};
SweepExtent sweep_extent(const Shape& shape, const Vec3& local_com);
// One convex shape's thinnest half-size, as above.
Real thinnest_half_size(const Shape& shape);

}  // namespace spindle
