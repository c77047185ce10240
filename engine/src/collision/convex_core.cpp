// Convex cores (convex_core.hpp), and the reach and thinness of a body's shape that they
// give.
#include "collision/convex_core.hpp"

#include <algorithm>

#include <spindle/platform/assert.hpp>

#include "collision/collide.hpp"
#include "collision/compound.hpp"
#include "collision/convex_hull.hpp"

namespace spindle {

bool is_convex(const Shape& shape) {
    return shape.type == ShapeType::Sphere || shape.type == ShapeType::Capsule || shape.type == ShapeType::Box ||
           shape.type == ShapeType::ConvexHull;
}

void make_core(const Shape& shape, const Transform& x, ConvexCore& core) {
    core.radius = round_radius(shape);
    core.count = 0;
    switch (shape.type) {
        case ShapeType::Sphere: core.points[core.count++] = x.p; break;
        case ShapeType::Capsule:
            core.points[core.count++] = x.apply(Vec3(0, -shape.half_height, 0));
            core.points[core.count++] = x.apply(Vec3(0, shape.half_height, 0));
            break;
        case ShapeType::Box: {
            const Vec3& h = shape.half_extents;
            for (int i = 0; i < 8; ++i) {
                core.points[core.count++] =
                    x.apply(Vec3(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z()));
            }
            break;
        }
        case ShapeType::ConvexHull:
            SPINDLE_ASSERT(shape.hull->vertices().size() <= ConvexCore::kMaxPoints,
                           "hull has more vertices than a core holds");
            for (const Vec3& v : shape.hull->vertices()) core.points[core.count++] = x.apply(v);
            break;
        default: SPINDLE_ASSERT(false, "make_core: not a convex shape");
    }
}

Real thinnest_half_size(const Shape& shape) {
    switch (shape.type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule: return shape.radius;
        case ShapeType::Box: return shape.half_extents.minCoeff();
        case ShapeType::ConvexHull: return shape.hull->inner_radius();
        default: return 0;
    }
}

namespace {

// Adds a convex part posed by x in the body's shape frame.
void add_part(const Shape& part, const Transform& x, const Vec3& local_com, SweepExtent& extent) {
    ConvexCore core;
    make_core(part, x, core);
    for (int i = 0; i < core.count; ++i) {
        const Vec3 from_com = (core.points[i] - local_com).cwiseAbs();
        extent.core_reach = extent.core_reach.cwiseMax(from_com);
        extent.reach = extent.reach.cwiseMax(from_com + Vec3::Constant(core.radius));
    }
    extent.thinnest = std::min(extent.thinnest, thinnest_half_size(part));
}

}  // namespace

SweepExtent sweep_extent(const Shape& shape, const Vec3& local_com) {
    SweepExtent extent;
    extent.thinnest = kHuge;
    if (shape.type == ShapeType::Compound) {
        const Compound& parts = *shape.parts;
        for (std::uint32_t i = 0; i < parts.size(); ++i) add_part(parts.shape(i), parts.pose(i), local_com, extent);
    } else if (shape.type == ShapeType::Box) {
        // The farthest corner along each axis, without making the corners: a box is most bodies.
        extent.reach = extent.core_reach = local_com.cwiseAbs() + shape.half_extents;
        extent.thinnest = shape.half_extents.minCoeff();
    } else if (is_convex(shape)) {
        add_part(shape, Transform{}, local_com, extent);
    } else {
        extent.thinnest = 0;  // a plane or mesh: static only, never swept
    }
    extent.reach_length = extent.reach.norm();
    return extent;
}

}  // namespace spindle
