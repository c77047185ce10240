// The narrowphase's pair functions, one per unordered pair of shape types, A being the
// type that comes first in ShapeType. The dispatch table (pair_table.cpp)
// calls them with swapped arguments for the other order and flips the normal.
// Convex pairs write at most one manifold; all take capacity >= 1.
#pragma once

#include <spindle/scheduler/function_ref.hpp>

#include "collision/collide.hpp"
#include "collision/polyhedron.hpp"

namespace spindle::detail {

using PairFunction = int (*)(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                             Real speculative_distance, Manifold* out, int capacity);

// collide_rounded.cpp: spheres and capsules among themselves, sphere-box.
int collide_sphere_sphere(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
int collide_sphere_capsule(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
int collide_sphere_box(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
int collide_capsule_capsule(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);

// collide_box.cpp: box-box, SAT over 15 axes.
int collide_box_box(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);

// rounded_polyhedron.cpp (sphere/capsule vs hull, capsule vs box) and sat.cpp (box/hull vs hull).
int collide_sphere_hull(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
int collide_capsule_box(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
int collide_capsule_hull(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
int collide_box_hull(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
int collide_hull_hull(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);

// collide_plane.cpp: every convex shape against a plane (B).
int collide_convex_plane(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);

// A contact's triangle features through one collide (collide_mesh.cpp): those kept from
// the last are looked up, this collide's are written behind them (in the same order:
// parts in order, each part's triangles in increasing index, as a mesh query visits
// them), and finish() leaves only the new ones.
class TriangleFeatureWalk {
public:
    // With `queries`, each part's mesh query is kept for the next collide the same way.
    TriangleFeatureWalk(TriangleFeatures& features, Real slop, MeshQueries* queries = nullptr)
        : m_features(features),
          m_last(features.size()),
          m_slop(slop),
          m_queries(queries),
          m_last_parts(queries ? queries->parts.size() : 0),
          m_last_triangles(queries ? queries->triangles.size() : 0),
          m_last_manifolds(queries ? queries->manifolds.size() : 0) {}
    // The cache of (part, triangle) for this collide's SAT, holding the feature it had
    // last time (none if it was not met then); valid until the next call. Calls come in
    // increasing (part, triangle).
    FeatureCache* next(std::uint32_t part, std::uint32_t triangle);
    // Calls visit(t) for each triangle of `mesh` whose bounds overlap `box` (mesh frame),
    // in increasing t, as mesh.query does: from the triangles kept for `part` when `box`
    // lies inside their enlarged box, else from a query of a new enlarged box, kept for
    // the next collide. Calls come in increasing part.
    void query(std::uint32_t part, const TriangleMesh& mesh, const Aabb& box, FunctionRef<void(std::uint32_t)> visit);
    Real slop() const { return m_slop; }
    void finish();

    // A compound's parts' manifolds against the mesh (MeshQuery), with queries kept. Whether
    // the last collide met `mesh` at `pose` (its parts' manifolds, kept in the world, may
    // stand for this one's); this collide's are kept as met there. Called before query().
    bool met_at(const TriangleMesh& mesh, const Transform& pose);
    bool keeps_queries() const { return m_queries != nullptr; }
    // The last collide's record of `part`, or null. Calls come in increasing part, each
    // before that part's query() or carry().
    const MeshQuery* last(std::uint32_t part);
    // The manifolds kept with `was`, a record last() gave, as they were made.
    std::span<const Manifold> kept(const MeshQuery& was) const {
        return {m_queries->manifolds.data() + was.first_manifold, was.manifold_count};
    }
    // Takes `part`'s record from the last collide into this one as it was (its query, its
    // triangles' features and its manifolds), in place of query(): the part is not collided.
    // Returns its manifolds.
    std::span<const Manifold> carry(std::uint32_t part);
    // Keeps `found`, the manifolds just made for the part whose query() came last, and where
    // it was (its centre and its body's orientation), for the next collide's carry().
    void keep_manifolds(const Vec3& centre, const Quat& turn, std::span<const Manifold> found);

private:
    void meet(const TriangleMesh& mesh);  // the queries from here on are on `mesh`
    static std::uint64_t order_key(std::uint32_t part, std::uint32_t triangle) {
        return std::uint64_t{part} << 32 | triangle;
    }
    TriangleFeatures& m_features;
    std::size_t m_last;        // m_features[0, m_last) are the last collide's
    std::size_t m_cursor = 0;  // where the last collide's are merged up to
    Real m_slop;
    MeshQueries* m_queries;         // null: every query goes to the mesh
    std::size_t m_last_parts;       // m_queries->parts[0, m_last_parts) are the last collide's
    std::size_t m_last_triangles;   // and the triangles they hold, m_queries->triangles[0, m_last_triangles)
    std::size_t m_last_manifolds;   // and their manifolds, m_queries->manifolds[0, m_last_manifolds)
    std::size_t m_part_cursor = 0;  // where the last collide's parts are merged up to
};

// collide_mesh.cpp: every convex shape against a triangle mesh (B).
int collide_convex_mesh(const Shape&, const Transform&, const Shape&, const Transform&, Real, Manifold*, int);
// The same with each triangle's SAT reading and writing its feature in `walk` (a box or
// hull; a sphere or capsule has none) as compound part `part` (0 for a whole shape).
// `a_bounds`: a.bounds(xa) where the caller has them (null: made here when needed).
int collide_convex_mesh_cached(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                               Real speculative, Manifold* out, int capacity, std::uint32_t part,
                               TriangleFeatureWalk& walk, const Aabb* a_bounds = nullptr);

// collide_compound.cpp: any shape against a compound (B), and two compounds, part by part,
// each compound's part boxes taken from `boxes` where given (empty: made by the walk); with
// more manifolds than `capacity`, those deepest a step ahead under `motion` (null: now).
int collide_shape_compound(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                           Manifold* out, int capacity, const PartBoxes& boxes, const PairMotion* motion);
int collide_compound_compound(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                              Real speculative, Manifold* out, int capacity, const PartBoxes& boxes,
                              const PairMotion* motion);
// collide_shape_compound for a triangle mesh A, each part's triangles met through `walk`;
// with the walk's queries kept, each part's manifolds are kept too, and a part that has moved
// less than `recycle_distance` (over 0) since keeps them instead of a collide (collide_cached).
int collide_mesh_compound_cached(const Shape& mesh, const Transform& xm, const Shape& b, const Transform& xb,
                                 Real speculative, Manifold* out, int capacity, TriangleFeatureWalk& walk,
                                 std::span<const Aabb> b_boxes, const PairMotion* motion, Real recycle_distance);

// ---- Shared convex machinery (sat.cpp, rounded_polyhedron.cpp) --------------------------
// Polyhedron a (posed by xa) against polyhedron b (posed by xb): SAT over face normals and
// Gauss-map-pruned edge pairs, then face clipping or a single edge-edge point.
// With a cache (see FeatureCache), the feature it holds is tried first (a touching one
// while its separation stays within `feature_slop`) and the one found is kept there.
bool collide_polyhedra(const PolyView& a, const Transform& xa, const PolyView& b, const Transform& xb,
                       Real speculative_distance, Manifold& out, FeatureCache* cache = nullptr, Real feature_slop = 0);
// The same with A prepared once for many tests (sat_prepared.hpp): a hull against each
// triangle a mesh query finds.
class PreparedPolyhedron;
bool collide_polyhedra(const PreparedPolyhedron& a, const Transform& xa, const PolyView& b, const Transform& xb,
                       Real speculative_distance, Manifold& out, FeatureCache* cache = nullptr, Real feature_slop = 0);
// B's pose in A's frame as the SAT works with it, a rotation matrix and an offset: made
// once for many b posed alike (each triangle of a mesh against one hull), the same to the
// bit as the pair function makes it from xa and xb each time.
struct RelativePose {
    RelativePose(const Transform& xa, const Transform& xb)
        : r((xa.q.conjugate() * xb.q).toRotationMatrix()), t(xa.apply_inverse(xb.p)) {}
    Mat3 r;
    Vec3 t;
};
bool collide_polyhedra(const PreparedPolyhedron& a, const Transform& xa, const PolyView& b, const RelativePose& b_in_a,
                       Real speculative_distance, Manifold& out, FeatureCache* cache, Real feature_slop);

// The manifold of face `face_b` of b as the reference, whatever the SAT would pick, measured
// over that face only (a mesh triangle's face, for a shape whose SAT axis the triangle does
// not admit): a's incident face clipped against it; when nothing clipped is within reach, a's
// vertex deepest along the normal if it lies over the face, else a's faces that face against
// the normal, each clipped against it. False when nothing of a over the face is within the
// speculative distance of its plane. With a cache, a manifold made keeps face_b there (FaceB,
// with the separation along its normal; marked as measured over the face when it came from
// the fallbacks): while that stays within the slop, collide_polyhedra's cached path makes this
// manifold again (the incident face's clip, or the same measure over the face) without a
// whole SAT and its re-measure.
bool face_of_b_manifold(const PreparedPolyhedron& a, const Transform& xa, const PolyView& b, const Transform& xb,
                        std::uint32_t face_b, Real speculative_distance, Manifold& out);
bool face_of_b_manifold(const PreparedPolyhedron& a, const Transform& xa, const PolyView& b, const RelativePose& b_in_a,
                        std::uint32_t face_b, Real speculative_distance, Manifold& out, FeatureCache* cache = nullptr);

// How a mesh takes a polyhedron's contact with one of its triangles (collide_mesh.cpp): when
// again(m) (m's normal and points in the frame xa places a in, the mesh's) says so, the
// contact is measured again over the triangle's face `face` (0 front, 1 back) as
// face_of_b_manifold measures it. Without points_matter, again reads m's normal only, and is
// asked it before the SAT makes the points (m then has none): none are made that would be
// measured again.
struct FaceMeasure {
    std::uint32_t face;
    bool points_matter;
    FunctionRef<bool(const Manifold&)> again;
};
// collide_polyhedra of a against a mesh triangle (b), then, when `measure` asks it, its
// face_of_b_manifold over the triangle's face, in one posing of the triangle: what the two
// calls give, the same to the bit, with the same cache. But when the rule reads the normal
// alone (!points_matter) and the cache keeps the face it measures over, that face past the
// slop is measured over again at once (face_of_b_manifold's answer) and the whole SAT is
// run only if nothing over it is within reach.
bool collide_polyhedron_triangle(const PreparedPolyhedron& a, const Transform& xa, const PolyView& triangle,
                                 const RelativePose& triangle_in_a, Real speculative_distance, Manifold& out,
                                 FeatureCache* cache, Real feature_slop, const FaceMeasure& measure);

// True when the feature `cache` keeps for a against a triangle (B: corners `triangle` and
// unit front normal `normal`, posed in a's frame by b_in_a), an A's face or an edge pair,
// separates them past the speculative distance: collide_polyhedra with that cache would
// end there, with no manifold and the cache as it is. Measured as collide_polyhedra
// measures it, to the bit, without building the triangle's polyhedron.
bool kept_axis_separates(const PreparedPolyhedron& a, const Vec3 (&triangle)[3], const Vec3& normal,
                         const RelativePose& b_in_a, const FeatureCache& cache, Real speculative_distance);

// A rounded shape A (the segment p0-p1 in A's frame, p0 == p1 for a sphere, swept by
// radius) against polyhedron b: GJK distance between the cores while they are apart, SAT
// when they overlap; a capsule lying on a face gets two points.
bool collide_rounded_polyhedron(const Vec3& p0, const Vec3& p1, Real radius, const Transform& xa, const PolyView& b,
                                const Transform& xb, Real speculative_distance, Manifold& out);

// The core segment of a sphere or capsule in its own frame.
inline void rounded_core(const Shape& s, Vec3& p0, Vec3& p1) {
    p0 = Vec3(0, -s.half_height, 0);
    p1 = Vec3(0, s.half_height, 0);
}

// Tolerances that make SAT prefer a face over an edge, and A's face over B's, unless the
// other is clearly better: this keeps the chosen features, and so the ids, from flickering.
inline bool clearly_greater(Real candidate, Real current) {
    constexpr Real kRelative = 0.02;
    constexpr Real kAbsolute = 5e-4;
    return candidate > current + kRelative * std::abs(current) + kAbsolute;
}

}  // namespace spindle::detail
