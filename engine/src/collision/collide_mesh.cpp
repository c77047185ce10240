// Convex shape against a triangle mesh: the shape meets each triangle the mesh finds
// under its bounds and whose plane it comes near (shape_span.hpp); contacts on inactive
// (flat interior) edges take the triangle's face normal so shapes slide over seams
// without catching; manifolds whose normals agree are merged, and the deepest come first.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <spindle/platform/assert.hpp>

#include "collision/clipping.hpp"
#include "collision/manifold_slots.hpp"
#include "collision/pair_functions.hpp"
#include "collision/sat_prepared.hpp"
#include "collision/shape_span.hpp"
#include "collision/triangle_mesh.hpp"

namespace spindle::detail {
namespace {

constexpr int kMaxMeshManifolds = 32;   // distinct normals kept while walking triangles
constexpr int kMaxMeshOutput = 4;       // the deepest of them a shape keeps against the mesh
constexpr Real kSameNormal = 0.999;     // manifolds closer than this merge
constexpr Real kFaceNormal = 1 - 1e-6;  // a contact this aligned with the face is a face contact
constexpr Real kOnEdge = 1e-6;          // barycentric weight below which a point is on an edge
// How far a kept mesh query reaches past the query box it was made for (Box3D's
// B3_MAX_AABB_MARGIN, in metres): a part rocking or creeping where it lies stays inside.
constexpr Real kQueryMargin = 0.1;

// True when some contact point lies on an active edge of the triangle (a, b, c).
bool touches_active_edge(const Manifold& m, const Vec3 (&v)[3], std::uint8_t active_edges) {
    if (active_edges == 0) return false;
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
    const Real area2 = n.squaredNorm();
    for (int i = 0; i < m.point_count; ++i) {
        const Vec3 q = m.points[i].point + m.normal * (Real(0.5) * m.points[i].separation);
        for (int k = 0; k < 3; ++k) {
            if ((active_edges >> k & 1) == 0) continue;
            // Weight of the vertex opposite edge k (v[k] -> v[k+1]); zero on that edge.
            const Real w = (v[(k + 1) % 3] - v[k]).cross(q - v[k]).dot(n) / area2;
            if (w <= kOnEdge) return true;
        }
    }
    return false;
}

// Replaces an edge or vertex normal of a sphere or capsule by the face normal, on the side
// of the triangle's plane the shape reaches into (`front`: its centre is in front;
// collide_triangles has dropped a shape lying across the plane with its centre behind), and
// measures the contact again against that face from its deepest core point(s) along the new
// normal. (A polyhedron is measured as its SAT would have had the face chosen, over the
// triangle only: collide_polyhedron_triangle, face_of_b_manifold. The triangle's plane
// carried on past its edges says nothing of what lies beyond them, over the neighbouring
// triangles.) The SAT's own points do not serve: for shapes apart, its axis may be one
// beside the triangle, whose points lie off both shapes; for a shape deep in the triangle,
// they may be measured from its far side. False when nothing is within reach.
bool use_face_normal(Manifold& m, const Shape& a, const Transform& xa, bool front, const TrianglePoly& tri,
                     const Vec3& on_plane, Real speculative) {
    const Vec3& n = tri.normal();
    const Vec3 face = front ? Vec3(-n) : n;
    Vec3 core[2];
    rounded_core(a, core[0], core[1]);
    const int ends = a.type == ShapeType::Sphere ? 1 : 2;
    const std::uint32_t id = m.points[0].id;
    m.point_count = 0;
    for (int i = 0; i < ends; ++i) {
        const Vec3 on_a = xa.apply(core[i]) + face * a.radius;
        const Real separation = face.dot(on_plane - on_a);
        if (separation > speculative) continue;
        m.points[m.point_count++] = {on_a + face * (Real(0.5) * separation), separation,
                                     id + static_cast<std::uint32_t>(i)};
    }
    m.normal = face;
    return m.point_count > 0;
}

// Triangle t in the mesh frame against convex a posed there by xa; a box or hull comes
// prepared once for all the triangles of the query, with the mesh's pose in its frame
// (mesh_in_a), and with the triangle's cache when the contact keeps them (null: the whole
// SAT). A contact `measure` asks for is measured again over the triangle's face
// (use_face_normal).
bool collide_triangle(const Shape& a, const Transform& xa, const PreparedPolyhedron* polyhedron,
                      const RelativePose& mesh_in_a, const TrianglePoly& tri, const Vec3& on_plane, Real speculative,
                      FeatureCache* cache, Real feature_slop, const FaceMeasure& measure, Manifold& m) {
    const Transform identity;
    switch (a.type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule: {
            Vec3 p0, p1;
            rounded_core(a, p0, p1);
            if (!collide_rounded_polyhedron(p0, p1, a.radius, xa, tri.view(), identity, speculative, m)) return false;
            return !measure.again(m) || use_face_normal(m, a, xa, measure.face == 0, tri, on_plane, speculative);
        }
        case ShapeType::Box:
        case ShapeType::ConvexHull:
            return collide_polyhedron_triangle(*polyhedron, xa, tri.view(), mesh_in_a, speculative, m, cache,
                                               feature_slop, measure);
        default: return false;
    }
}

// The points each list slot's manifolds brought. Manifolds with nearly the same normal
// merge; their points are kept here and reduced once when the walk is done. Reduced at
// each merge, the result followed the order the triangles came in: a face landing across
// two triangles lost its far corner to a point on the triangles' shared edge barely
// deeper, met before the deepest point had come, and the push there, behind the landing
// edge, turned the body on over it.
using SlotPoints = std::array<std::vector<ContactCandidate>, kMaxMeshManifolds>;

void keep_points(std::vector<ContactCandidate>& points, const Manifold& m) {
    for (int k = 0; k < m.point_count; ++k) {
        points.push_back({m.points[k].point, m.points[k].separation, m.points[k].id});
    }
}

// Adds m to the list, merging it into a manifold with nearly the same normal (its points
// go to the slot's points only: reduce_gathered chooses among them); when the list is full
// a deeper manifold replaces the shallowest. depth[i]: the deepest separation merged into
// slot i.
void gather(ManifoldSlots<kMaxMeshManifolds>& list, Real (&depth)[kMaxMeshManifolds], int& count, const Manifold& m,
            SlotPoints& points) {
    const Real m_depth = deepest(m);
    for (int i = 0; i < count; ++i) {
        if (list[i].normal.dot(m.normal) < kSameNormal) continue;
        depth[i] = std::min(depth[i], m_depth);
        keep_points(points[i], m);
        return;
    }
    if (count < kMaxMeshManifolds) {
        points[count].clear();
        keep_points(points[count], m);
        depth[count] = m_depth;
        list.fill(static_cast<std::size_t>(count++), m);
        return;
    }
    int shallowest = 0;
    for (int i = 1; i < count; ++i) {
        if (depth[i] > depth[shallowest]) shallowest = i;
    }
    if (m_depth < depth[shallowest]) {
        list[shallowest] = m;
        depth[shallowest] = m_depth;
        points[shallowest].clear();
        keep_points(points[shallowest], m);
    }
}

// Each merged manifold reduced once from all the points its manifolds brought, whatever
// the order they came in (a slot holding one manifold's points keeps them as they are).
void reduce_gathered(ManifoldSlots<kMaxMeshManifolds>& list, int count, SlotPoints& points) {
    for (int i = 0; i < count; ++i) {
        std::vector<ContactCandidate>& held = points[i];
        if (static_cast<int>(held.size()) <= list[i].point_count) continue;
        reduce_to_manifold(held.data(), static_cast<int>(held.size()), list[i], true);
    }
}

// True when x leaves every point where it is: the mesh's frame is then the world's.
bool is_identity(const Transform& x) { return x.p == Vec3::Zero() && x.q.coeffs() == Quat::Identity().coeffs(); }

// The walk over the triangles the mesh finds under a's bounds (a posed in the mesh's frame
// by a_in_mesh); `polyhedron` is a box or hull prepared once for all of them, null for a
// sphere or capsule. With a walk, a polyhedron's SATs read and keep their triangles'
// features as part `part`. `a_world_bounds`, when given, are a's bounds in the world: with
// the mesh at the identity they are its bounds in the mesh's frame too (a_in_mesh is then
// a's pose to the bit, but for the signs of zeros), and are not made again.
int collide_triangles(const Shape& a, const Transform& a_in_mesh, const PreparedPolyhedron* polyhedron,
                      const TriangleMesh& mesh, const Transform& xb, Real speculative, Manifold* out, int capacity,
                      std::uint32_t part, TriangleFeatureWalk* walk, const Aabb* a_world_bounds) {
    const Aabb bounds = a_world_bounds && is_identity(xb) ? *a_world_bounds : a.bounds(a_in_mesh);
    const Aabb query = bounds.fattened(std::max(speculative, Real(0)));
    const ShapeSpan span(a, a_in_mesh);
    // A sphere's or capsule's core, a box's centre, a hull's centroid.
    const Vec3 centre = polyhedron ? a_in_mesh.apply(polyhedron->view().inner_centre) : a_in_mesh.p;
    // The mesh's frame in a's, made once for all the triangles (a polyhedron's SAT works there).
    const RelativePose mesh_in_a(a_in_mesh, Transform());

    ManifoldSlots<kMaxMeshManifolds> found;
    int found_count = 0;
    Real depth[kMaxMeshManifolds];
    // Kept from call to call (no allocation once grown); gather clears a slot as it fills it.
    thread_local SlotPoints gathered;
    const auto visit = [&](std::uint32_t t) {
        const MeshTriangle& tri = mesh.triangles()[t];
        const Vec3 v[3] = {mesh.vertices()[tri.v[0]], mesh.vertices()[tri.v[1]], mesh.vertices()[tri.v[2]]};
        const Vec3& normal = mesh.normal(t);  // triangle_normal of v, for the cull and the polyhedron
        if (span.clear_of_plane(v, normal, speculative)) return;
        // Triangles are one-sided for a shape lying across their plane (Box3D culls by the
        // shape's centre too). With its centre behind, it has passed the middle and gets no
        // contact here: pushed on out of the back while its body's other parts are pushed out
        // of the front, it would lever the body up about them. One wholly behind is pushed on
        // out of the back, as a shape that started there should be.
        const bool centre_in_front = normal.dot(centre - v[0]) >= 0;  // on the plane: in front
        if (!centre_in_front) {
            Real lo, hi;
            span.along(normal, lo, hi);
            if (hi > normal.dot(v[0])) return;
        }
        FeatureCache* const cache = walk && polyhedron ? walk->next(part, t) : nullptr;
        // Half the tests end on the kept axis (a part resting on a few of the triangles under
        // it): told from the three corners, before the triangle's polyhedron is made.
        if (cache && kept_axis_separates(*polyhedron, v, normal, mesh_in_a, *cache, speculative)) return;
        const TrianglePoly poly(v[0], v[1], v[2], normal);
        // With its centre in front, a normal that would push it on through the back (the back
        // face, or an edge axis leaning that way, can win the SAT once it is deep) is measured
        // again against the front face, from its deep side; so is a normal the triangle does not
        // admit (off its face, with no point on an active edge).
        const auto again = [&](const Manifold& m) {
            const Real facing = m.normal.dot(normal);  // the normal points from the shape to the triangle
            const bool through = centre_in_front && facing > 0;
            return through || (std::abs(facing) < kFaceNormal && !touches_active_edge(m, v, tri.active_edges));
        };
        const FaceMeasure measure{centre_in_front ? 0u : 1u, tri.active_edges != 0, again};
        Manifold m;
        if (!collide_triangle(a, a_in_mesh, polyhedron, mesh_in_a, poly, v[0], speculative, cache,
                              walk ? walk->slop() : 0, measure, m))
            return;
        // Ids from different triangles must differ inside a merged manifold.
        for (int i = 0; i < m.point_count; ++i) m.points[i].id ^= t * 0x9E3779B1u;
        gather(found, depth, found_count, m, gathered);
    };
    if (walk) walk->query(part, mesh, query, visit);
    else mesh.query(query, visit);

    reduce_gathered(found, found_count, gathered);
    std::sort(found.data(), found.data() + found_count,
              [](const Manifold& x, const Manifold& y) { return deepest(x) < deepest(y); });
    const int count = std::min({found_count, capacity, kMaxMeshOutput});
    for (int i = 0; i < count; ++i) {
        out[i] = found[i];
        manifold_to_world(out[i], xb);
    }
    return count;
}

}  // namespace

FeatureCache* TriangleFeatureWalk::next(std::uint32_t part, std::uint32_t triangle) {
    // Parts come in order and a mesh query visits its triangles in increasing t, so the
    // last collide's features and this one's are both in key order: one merge finds them.
    const std::uint64_t key = order_key(part, triangle);
    SPINDLE_ASSERT(m_features.size() == m_last || order_key(m_features.back().part, m_features.back().triangle) < key,
                   "TriangleFeatureWalk: triangles out of order");
    while (m_cursor < m_last && order_key(m_features[m_cursor].part, m_features[m_cursor].triangle) < key) ++m_cursor;
    const bool kept = m_cursor < m_last && m_features[m_cursor].part == part &&
                      m_features[m_cursor].triangle == triangle;
    m_features.push_back({part, triangle, kept ? m_features[m_cursor].feature : FeatureCache()});
    return &m_features.back().feature;
}

void TriangleFeatureWalk::query(std::uint32_t part, const TriangleMesh& mesh, const Aabb& box,
                                FunctionRef<void(std::uint32_t)> visit) {
    if (!m_queries) {
        mesh.query(box, visit);
        return;
    }
    MeshQueries& q = *m_queries;
    SPINDLE_ASSERT(q.parts.size() == m_last_parts || q.parts.back().part < part,
                   "TriangleFeatureWalk: parts out of order");
    meet(mesh);
    const MeshQuery* const was = last(part);
    const bool kept = was && was->box.contains(box);
    MeshQuery now;
    now.part = part;
    now.first = static_cast<std::uint32_t>(q.triangles.size());
    if (kept) {
        const std::uint32_t first = was->first, count = was->count;  // `was` is in q.parts, not pushed to yet
        now.box = was->box;
        for (std::uint32_t k = 0; k < count; ++k) {
            const std::uint32_t t = q.triangles[first + k];
            q.triangles.push_back(t);
        }
    } else {
        now.box = box.fattened(kQueryMargin);
        mesh.query(now.box, [&](std::uint32_t t) { q.triangles.push_back(t); });
    }
    now.count = static_cast<std::uint32_t>(q.triangles.size()) - now.first;
    q.parts.push_back(now);
    // The kept box holds `box`, so every triangle overlapping `box` is among its triangles:
    // the same test as the mesh's leaves the same triangles in the same order.
    for (std::uint32_t k = now.first; k < now.first + now.count; ++k) {
        const std::uint32_t t = q.triangles[k];
        if (mesh.bounds(t).overlaps(box)) visit(t);
    }
}

void TriangleFeatureWalk::meet(const TriangleMesh& mesh) {
    if (m_queries->mesh == &mesh) return;
    m_part_cursor = m_last_parts;  // made on another mesh: none is kept
    m_queries->mesh = &mesh;
}

bool TriangleFeatureWalk::met_at(const TriangleMesh& mesh, const Transform& pose) {
    if (!m_queries) return false;
    MeshQueries& q = *m_queries;
    const bool same = q.mesh == &mesh && q.pose.p == pose.p && q.pose.q.coeffs() == pose.q.coeffs();
    meet(mesh);
    q.pose = pose;
    q.parts_collided = q.parts_recycled = 0;
    return same;
}

const MeshQuery* TriangleFeatureWalk::last(std::uint32_t part) {
    const MeshQueries& q = *m_queries;
    while (m_part_cursor < m_last_parts && q.parts[m_part_cursor].part < part) ++m_part_cursor;
    return m_part_cursor < m_last_parts && q.parts[m_part_cursor].part == part ? &q.parts[m_part_cursor] : nullptr;
}

std::span<const Manifold> TriangleFeatureWalk::carry(std::uint32_t part) {
    MeshQueries& q = *m_queries;
    SPINDLE_ASSERT(last(part) && (q.parts.size() == m_last_parts || q.parts.back().part < part),
                   "TriangleFeatureWalk: a part carried that was not met, or out of order");
    MeshQuery now = q.parts[m_part_cursor];
    const std::uint32_t first = now.first, first_manifold = now.first_manifold;
    now.first = static_cast<std::uint32_t>(q.triangles.size());
    for (std::uint32_t k = 0; k < now.count; ++k) q.triangles.push_back(q.triangles[first + k]);
    now.first_manifold = static_cast<std::uint32_t>(q.manifolds.size());
    for (std::uint32_t k = 0; k < now.manifold_count; ++k) q.manifolds.push_back(q.manifolds[first_manifold + k]);
    q.parts.push_back(now);
    q.parts_recycled += 1;
    // Its triangles' features as they were, in key order behind this collide's earlier parts'.
    const std::uint64_t key = order_key(part, 0);
    while (m_cursor < m_last && order_key(m_features[m_cursor].part, m_features[m_cursor].triangle) < key) ++m_cursor;
    for (; m_cursor < m_last && m_features[m_cursor].part == part; ++m_cursor) {
        const TriangleFeature kept = m_features[m_cursor];
        m_features.push_back(kept);
    }
    return {q.manifolds.data() + now.first_manifold, now.manifold_count};
}

void TriangleFeatureWalk::keep_manifolds(const Vec3& centre, const Quat& turn, std::span<const Manifold> found) {
    MeshQueries& q = *m_queries;
    MeshQuery& now = q.parts.back();
    q.parts_collided += 1;
    now.has_manifolds = true;
    now.centre = centre;
    now.turn = turn;
    now.first_manifold = static_cast<std::uint32_t>(q.manifolds.size());
    now.manifold_count = static_cast<std::uint32_t>(found.size());
    q.manifolds.insert(q.manifolds.end(), found.begin(), found.end());
}

void TriangleFeatureWalk::finish() {
    m_features.erase(m_features.begin(), m_features.begin() + static_cast<std::ptrdiff_t>(m_last));
    m_last = m_cursor = 0;
    if (!m_queries) return;
    MeshQueries& q = *m_queries;
    q.parts.erase(q.parts.begin(), q.parts.begin() + static_cast<std::ptrdiff_t>(m_last_parts));
    q.triangles.erase(q.triangles.begin(), q.triangles.begin() + static_cast<std::ptrdiff_t>(m_last_triangles));
    q.manifolds.erase(q.manifolds.begin(), q.manifolds.begin() + static_cast<std::ptrdiff_t>(m_last_manifolds));
    for (MeshQuery& p : q.parts) {
        p.first -= static_cast<std::uint32_t>(m_last_triangles);
        p.first_manifold -= static_cast<std::uint32_t>(m_last_manifolds);
    }
    m_last_parts = m_last_triangles = m_last_manifolds = m_part_cursor = 0;
}

namespace {

int collide_convex_mesh_with(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                             Manifold* out, int capacity, std::uint32_t part, TriangleFeatureWalk* walk,
                             const Aabb* a_bounds) {
    const TriangleMesh& mesh = *b.mesh;
    const Transform a_in_mesh = xb.inverse() * xa;
    // Each branch prepares its polyhedron in place: an empty std::optional of one had its
    // whole room (tens of kilobytes, most of it for a hull's edges) zeroed on every call.
    switch (a.type) {
        case ShapeType::Box: {
            const BoxPoly box(a.half_extents);
            const PreparedPolyhedron prepared(box.view());
            return collide_triangles(a, a_in_mesh, &prepared, mesh, xb, speculative, out, capacity, part, walk,
                                     a_bounds);
        }
        case ShapeType::ConvexHull: {
            const PreparedPolyhedron prepared(view_of(*a.hull));
            return collide_triangles(a, a_in_mesh, &prepared, mesh, xb, speculative, out, capacity, part, walk,
                                     a_bounds);
        }
        default:
            return collide_triangles(a, a_in_mesh, nullptr, mesh, xb, speculative, out, capacity, part, walk, a_bounds);
    }
}

}  // namespace

int collide_convex_mesh(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                        Manifold* out, int capacity) {
    return collide_convex_mesh_with(a, xa, b, xb, speculative, out, capacity, 0, nullptr, nullptr);
}

int collide_convex_mesh_cached(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                               Real speculative, Manifold* out, int capacity, std::uint32_t part,
                               TriangleFeatureWalk& walk, const Aabb* a_bounds) {
    return collide_convex_mesh_with(a, xa, b, xb, speculative, out, capacity, part, &walk, a_bounds);
}

}  // namespace spindle::detail
