// Convex pairs that involve a hull, and capsule-box: each shape is seen as a polyhedron
// (a box through BoxPoly) or as a rounded core, and the shared SAT / GJK code does the work.
#include <spindle/engine/convex_hull.hpp>

#include "pair_functions.hpp"

namespace spindle::detail {

int collide_sphere_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                        Manifold* out, int) {
    return collide_rounded_polyhedron(Vec3::Zero(), Vec3::Zero(), a.radius, xa, view_of(*b.hull), xb, speculative,
                                      out[0])
               ? 1
               : 0;
}

int collide_capsule_box(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                        Manifold* out, int) {
    Vec3 p0, p1;
    rounded_core(a, p0, p1);
    const BoxPoly box(b.half_extents);
    return collide_rounded_polyhedron(p0, p1, a.radius, xa, box.view(), xb, speculative, out[0]) ? 1 : 0;
}

int collide_capsule_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                         Manifold* out, int) {
    Vec3 p0, p1;
    rounded_core(a, p0, p1);
    return collide_rounded_polyhedron(p0, p1, a.radius, xa, view_of(*b.hull), xb, speculative, out[0]) ? 1 : 0;
}

int collide_box_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                     Manifold* out, int) {
    const BoxPoly box(a.half_extents);
    return collide_polyhedra(box.view(), xa, view_of(*b.hull), xb, speculative, out[0]) ? 1 : 0;
}

int collide_hull_hull(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                      Manifold* out, int) {
    return collide_polyhedra(view_of(*a.hull), xa, view_of(*b.hull), xb, speculative, out[0]) ? 1 : 0;
}

}  // namespace spindle::detail
