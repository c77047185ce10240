// collide(): one table lookup per pair. The table is filled once with the pair
// functions for (lower type, higher type) and flipping wrappers for the other order.
#include <array>
#include <type_traits>

#include <spindle/platform/assert.hpp>

#include "collision/clipping.hpp"
#include "collision/collide.hpp"
#include "collision/pair_functions.hpp"

namespace spindle {
namespace detail {
namespace {

constexpr int kTypeCount = static_cast<int>(ShapeType::Count);
// A table entry: a pair function, given the compounds' part boxes and the bodies' motion (only a
// compound's reads them).
using Entry = int (*)(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                      Manifold* out, int capacity, const PartBoxes& boxes, const PairMotion* motion);
using Table = std::array<std::array<Entry, kTypeCount>, kTypeCount>;

template <auto Fn>
int call(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative, Manifold* out,
         int capacity, const PartBoxes& boxes, const PairMotion* motion) {
    if constexpr (std::is_same_v<decltype(Fn), PairFunction>) {
        return Fn(a, xa, b, xb, speculative, out, capacity);
    } else {
        return Fn(a, xa, b, xb, speculative, out, capacity, boxes, motion);
    }
}

// Calls Fn with the shapes swapped and turns the normals round, so they point from a to b.
template <auto Fn>
int swapped(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative, Manifold* out,
            int capacity, const PartBoxes& boxes, const PairMotion* motion) {
    const PairMotion turned = motion ? motion->swapped() : PairMotion{};
    const int count = call<Fn>(b, xb, a, xa, speculative, out, capacity, PartBoxes{boxes.b, boxes.a},
                               motion ? &turned : nullptr);
    for (int i = 0; i < count; ++i) flip_manifold(out[i]);
    return count;
}

template <auto Fn>
void add(Table& table, ShapeType a, ShapeType b) {
    table[static_cast<int>(a)][static_cast<int>(b)] = call<Fn>;
    if (a != b) table[static_cast<int>(b)][static_cast<int>(a)] = swapped<Fn>;
}

Table make_table() {
    using T = ShapeType;
    Table table{};  // null: static-only pairs (plane, mesh) never collide with each other
    add<collide_sphere_sphere>(table, T::Sphere, T::Sphere);
    add<collide_sphere_capsule>(table, T::Sphere, T::Capsule);
    add<collide_sphere_box>(table, T::Sphere, T::Box);
    add<collide_sphere_hull>(table, T::Sphere, T::ConvexHull);
    add<collide_capsule_capsule>(table, T::Capsule, T::Capsule);
    add<collide_capsule_box>(table, T::Capsule, T::Box);
    add<collide_capsule_hull>(table, T::Capsule, T::ConvexHull);
    add<collide_box_box>(table, T::Box, T::Box);
    add<collide_box_hull>(table, T::Box, T::ConvexHull);
    add<collide_hull_hull>(table, T::ConvexHull, T::ConvexHull);
    for (const T convex : {T::Sphere, T::Capsule, T::Box, T::ConvexHull}) {
        add<collide_convex_plane>(table, convex, T::Plane);
        add<collide_convex_mesh>(table, convex, T::TriangleMesh);
    }
    for (int other = 0; other < static_cast<int>(T::Compound); ++other) {
        add<collide_shape_compound>(table, static_cast<T>(other), T::Compound);
    }
    add<collide_compound_compound>(table, T::Compound, T::Compound);
    return table;
}

const Table& table() {
    static const Table instance = make_table();
    return instance;
}

// Out's first `count` manifolds, labelled with no part where neither shape is a compound:
// the convex pair functions leave the labels alone, and a caller reuses its slots from pair
// to pair (the narrowphase, for a chunk of pairs), so a compound's part labels stayed on the
// next pair's manifold, which then missed its own warm start.
int unlabelled(const Shape& a, const Shape& b, Manifold* out, int count) {
    if (a.type != ShapeType::Compound && b.type != ShapeType::Compound) {
        for (int i = 0; i < count; ++i) out[i].part_a = out[i].part_b = 0;
    }
    return count;
}

}  // namespace
}  // namespace detail

int collide(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative_distance,
            Manifold* out, int capacity, const PartBoxes& boxes, const PairMotion* motion) {
    SPINDLE_ASSERT(a.type < ShapeType::Count && b.type < ShapeType::Count, "collide: invalid shape type");
    if (capacity <= 0) return 0;
    const detail::Entry fn = detail::table()[static_cast<int>(a.type)][static_cast<int>(b.type)];
    if (fn == nullptr) return 0;
    return detail::unlabelled(a, b, out, fn(a, xa, b, xb, speculative_distance, out, capacity, boxes, motion));
}

int collide_cached(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative_distance,
                   Manifold* out, int capacity, FeatureCache& cache, TriangleFeatures& triangles, Real feature_slop,
                   const PartBoxes& boxes, const PairMotion* motion, MeshQueries* queries, Real recycle_distance) {
    // Box-box, most pairs of a pile, called straight (as collide() would call it): nothing of
    // a mesh or a feature kept, and no table.
    if (a.type == ShapeType::Box && b.type == ShapeType::Box && capacity > 0) {
        triangles.clear();
        if (queries) *queries = MeshQueries();
        cache = FeatureCache();
        return detail::unlabelled(a, b, out,
                                  detail::collide_box_box(a, xa, b, xb, speculative_distance, out, capacity));
    }
    const auto polyhedron = [](const Shape& s) { return s.type == ShapeType::Box || s.type == ShapeType::ConvexHull; };
    const bool mesh_a = a.type == ShapeType::TriangleMesh;
    const bool mesh_b = b.type == ShapeType::TriangleMesh;
    const Shape& shape = mesh_a ? b : a;  // the one against the mesh, if one is a mesh
    if (capacity > 0 && mesh_a != mesh_b && (polyhedron(shape) || shape.type == ShapeType::Compound)) {
        cache = FeatureCache();
        const Shape& mesh = mesh_a ? a : b;
        const Transform& x_mesh = mesh_a ? xa : xb;
        const Transform& x_shape = mesh_a ? xb : xa;
        detail::TriangleFeatureWalk walk(triangles, feature_slop, queries);
        // The pair functions' normals: from the mesh to a compound, from a convex shape to the mesh.
        const bool from_mesh = shape.type == ShapeType::Compound;
        const PairMotion mesh_first = motion && !mesh_a ? motion->swapped() : PairMotion{};
        const PairMotion* const compound_motion = !motion ? nullptr : mesh_a ? motion : &mesh_first;
        const int count = from_mesh
                              ? detail::collide_mesh_compound_cached(mesh, x_mesh, shape, x_shape, speculative_distance,
                                                                     out, capacity, walk, mesh_a ? boxes.b : boxes.a,
                                                                     compound_motion, recycle_distance)
                              : detail::collide_convex_mesh_cached(shape, x_shape, mesh, x_mesh, speculative_distance,
                                                                   out, capacity, 0, walk);
        walk.finish();
        if (from_mesh != mesh_a) {
            for (int i = 0; i < count; ++i) detail::flip_manifold(out[i]);
        }
        return detail::unlabelled(a, b, out, count);
    }
    triangles.clear();
    if (queries) *queries = MeshQueries();
    // A compound's walk takes its part boxes (box-box went straight to its own test above).
    if (capacity <= 0 || !polyhedron(a) || !polyhedron(b)) {
        cache = FeatureCache();
        return collide(a, xa, b, xb, speculative_distance, out, capacity, boxes, motion);
    }
    // The pair functions' order: the lower type is A (box before hull), as in the table.
    const bool swap = b.type < a.type;
    const Shape& first = swap ? b : a;
    const Shape& second = swap ? a : b;
    const Transform& x_first = swap ? xb : xa;
    const Transform& x_second = swap ? xa : xb;
    const detail::PolyView second_view = detail::view_of(*second.hull);
    bool touching = false;
    if (first.type == ShapeType::Box) {
        const detail::BoxPoly box(first.half_extents);
        touching = detail::collide_polyhedra(box.view(), x_first, second_view, x_second, speculative_distance, out[0],
                                             &cache, feature_slop);
    } else {
        touching = detail::collide_polyhedra(detail::view_of(*first.hull), x_first, second_view, x_second,
                                             speculative_distance, out[0], &cache, feature_slop);
    }
    if (!touching) return 0;
    if (swap) detail::flip_manifold(out[0]);
    return detail::unlabelled(a, b, out, 1);
}

}  // namespace spindle
