// ConvexHull construction: quickhull over triangles (each step adds the point farthest
// outside a face and re-triangulates the horizon), then coplanar triangles merged into
// polygon faces, collinear loop vertices dropped, and volume moments integrated.
#include "collision/convex_hull.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include <spindle/platform/assert.hpp>
#include <spindle/platform/error.hpp>

#include "collision/error_text.hpp"
#include "collision/polyhedron.hpp"

namespace spindle {
namespace {

constexpr std::size_t kMaxHullVertices = 256;  // the narrowphase's scratch buffers assume this

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) { return std::uint64_t(a) << 32 | b; }

struct Triangle {
    std::uint32_t v[3];
    Vec3 normal;
    Real offset;
    bool alive = true;
    std::vector<std::uint32_t> outside;  // points above this face, not yet on the hull
};

class Quickhull {
public:
    Quickhull(std::span<const Vec3> points, Real tolerance) : m_points(points), m_tolerance(tolerance) {}

    void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        Triangle t;
        t.v[0] = a, t.v[1] = b, t.v[2] = c;
        t.normal = (m_points[b] - m_points[a]).cross(m_points[c] - m_points[a]).normalized();
        t.offset = t.normal.dot(m_points[a]);
        const auto index = static_cast<std::uint32_t>(m_triangles.size());
        for (int k = 0; k < 3; ++k) m_edge_face[edge_key(t.v[k], t.v[(k + 1) % 3])] = index;
        m_triangles.push_back(std::move(t));
    }

    // The tetrahedron a b c d, faces turned outwards.
    void start(const std::uint32_t (&s)[4]) {
        static constexpr int kFaces[4][4] = {{0, 1, 2, 3}, {0, 3, 1, 2}, {0, 2, 3, 1}, {1, 3, 2, 0}};
        for (const auto& f : kFaces) {
            std::uint32_t a = s[f[0]], b = s[f[1]], c = s[f[2]];
            const Vec3 n = (m_points[b] - m_points[a]).cross(m_points[c] - m_points[a]);
            if (n.dot(m_points[s[f[3]]] - m_points[a]) > 0) std::swap(b, c);
            add_triangle(a, b, c);
        }
        for (std::uint32_t i = 0; i < m_points.size(); ++i) {
            if (i != s[0] && i != s[1] && i != s[2] && i != s[3]) assign(i, 0);
        }
    }

    void run() {
        // New faces are appended, so one pass in index order visits every face.
        for (std::uint32_t f = 0; f < m_triangles.size(); ++f) {
            if (m_triangles[f].alive && !m_triangles[f].outside.empty()) add_point(f);
        }
    }

    const std::vector<Triangle>& triangles() const { return m_triangles; }
    std::uint32_t neighbour(std::uint32_t a, std::uint32_t b) const { return m_edge_face.at(edge_key(b, a)); }

private:
    Real distance(const Triangle& t, std::uint32_t p) const { return t.normal.dot(m_points[p]) - t.offset; }

    // Puts point p on the outside list of the face (from index `first_face` on) it is
    // farthest above; a point above no face is inside and forgotten.
    void assign(std::uint32_t p, std::size_t first_face) {
        Real best = m_tolerance;
        std::size_t best_face = m_triangles.size();
        for (std::size_t f = first_face; f < m_triangles.size(); ++f) {
            if (!m_triangles[f].alive) continue;
            const Real d = distance(m_triangles[f], p);
            if (d > best) best = d, best_face = f;
        }
        if (best_face < m_triangles.size()) m_triangles[best_face].outside.push_back(p);
    }

    void add_point(std::uint32_t seed) {
        const std::vector<std::uint32_t>& candidates = m_triangles[seed].outside;
        const std::uint32_t eye = *std::max_element(candidates.begin(), candidates.end(), [&](auto x, auto y) {
            return distance(m_triangles[seed], x) < distance(m_triangles[seed], y);
        });
        // Faces that see the eye, grown from the seed across edges so the set stays connected.
        std::vector<std::uint32_t> visible{seed};
        m_triangles[seed].alive = false;
        for (std::size_t i = 0; i < visible.size(); ++i) {
            const Triangle& t = m_triangles[visible[i]];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t n = neighbour(t.v[k], t.v[(k + 1) % 3]);
                if (m_triangles[n].alive && distance(m_triangles[n], eye) > m_tolerance) {
                    m_triangles[n].alive = false;
                    visible.push_back(n);
                }
            }
        }
        // Horizon: edges of visible faces whose other side is still alive.
        std::vector<std::pair<std::uint32_t, std::uint32_t>> horizon;
        std::vector<std::uint32_t> orphans;
        for (const std::uint32_t f : visible) {
            const Triangle& t = m_triangles[f];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t a = t.v[k], b = t.v[(k + 1) % 3];
                if (m_triangles[neighbour(a, b)].alive) horizon.emplace_back(a, b);
            }
            for (const std::uint32_t p : t.outside) {
                if (p != eye) orphans.push_back(p);
            }
        }
        // Only now forget the visible faces' edges (the lookups above still needed them);
        // horizon edges are taken over by the new faces.
        for (const std::uint32_t f : visible) {
            for (int k = 0; k < 3; ++k) m_edge_face.erase(edge_key(m_triangles[f].v[k], m_triangles[f].v[(k + 1) % 3]));
        }
        for (const std::uint32_t f : visible) std::vector<std::uint32_t>().swap(m_triangles[f].outside);
        const std::size_t first_new = m_triangles.size();
        for (const auto& [a, b] : horizon) add_triangle(a, b, eye);
        for (const std::uint32_t p : orphans) assign(p, first_new);
    }

    std::span<const Vec3> m_points;
    Real m_tolerance;
    std::vector<Triangle> m_triangles;
    std::unordered_map<std::uint64_t, std::uint32_t> m_edge_face;
};

struct UnionFind {
    std::vector<std::uint32_t> parent;
    explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    void unite(std::uint32_t a, std::uint32_t b) {
        a = find(a), b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
};

// The initial tetrahedron: the widest pair along the longest axis, the point farthest
// from their line, the point farthest from that plane. Throws for flat sets.
void find_simplex(std::span<const Vec3> p, Real thickness_tolerance, std::uint32_t (&s)[4]) {
    Aabb box;
    for (const Vec3& v : p) box.include(v);
    int axis = 0;
    box.extents().maxCoeff(&axis);
    s[0] = s[1] = 0;
    for (std::uint32_t i = 0; i < p.size(); ++i) {
        if (p[i][axis] < p[s[0]][axis]) s[0] = i;
        if (p[i][axis] > p[s[1]][axis]) s[1] = i;
    }
    const Vec3 dir = (p[s[1]] - p[s[0]]).normalized();
    Real best = -1;
    for (std::uint32_t i = 0; i < p.size(); ++i) {
        const Real d = (p[i] - p[s[0]]).cross(dir).norm();
        if (d > best) best = d, s[2] = i;
    }
    if (best <= thickness_tolerance) throw Error("convex hull: zero-thickness hull: the points are collinear");
    const Vec3 n = (p[s[1]] - p[s[0]]).cross(p[s[2]] - p[s[0]]).normalized();
    best = -1;
    for (std::uint32_t i = 0; i < p.size(); ++i) {
        const Real d = std::abs(n.dot(p[i] - p[s[0]]));
        if (d > best) best = d, s[3] = i;
    }
    if (best <= thickness_tolerance) {
        throw Error("convex hull: zero-thickness hull: the points are coplanar (thickness " + detail::to_text(best) +
                    ")");
    }
}

}  // namespace

ConvexHull::ConvexHull(std::span<const Vec3> points) {
    if (points.size() < 4) {
        throw Error("convex hull: needs at least 4 points, got " + std::to_string(points.size()));
    }
    Aabb box;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!is_finite(points[i])) {
            throw Error("convex hull: point " + std::to_string(i) + " must be finite, got " +
                        detail::to_text(points[i]));
        }
        if (points[i].cwiseAbs().maxCoeff() > kMaxCoordinate) {
            throw Error("convex hull: point " + std::to_string(i) + " must be within " +
                        detail::to_text(kMaxCoordinate) + " m of the origin, got " + detail::to_text(points[i]));
        }
        box.include(points[i]);
    }
    const Real size = (box.max - box.min).norm();
    if (!(size > 0)) throw Error("convex hull: zero-thickness hull: all points coincide");
    // Round-off in the plane tests grows with the coordinates' magnitude, not just the size.
    const Real magnitude = std::max(box.max.cwiseAbs().maxCoeff(), box.min.cwiseAbs().maxCoeff());
    const Real tolerance = 1e-12 * (size + magnitude);
    std::uint32_t simplex[4];
    find_simplex(points, 1e-6 * size, simplex);

    Quickhull qh(points, tolerance);
    qh.start(simplex);
    qh.run();
    const std::vector<Triangle>& tris = qh.triangles();

    // Merge neighbouring triangles that lie in one plane (each one's far vertex within
    // tolerance of the other's plane) into polygon faces.
    const Real merge_tolerance = 1e-9 * size + tolerance;
    UnionFind groups(tris.size());
    for (std::uint32_t t = 0; t < tris.size(); ++t) {
        if (!tris[t].alive) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t u = qh.neighbour(tris[t].v[k], tris[t].v[(k + 1) % 3]);
            const std::uint32_t far_u = tris[u].v[0] + tris[u].v[1] + tris[u].v[2] - tris[t].v[k] -
                                        tris[t].v[(k + 1) % 3];
            const std::uint32_t far_t = tris[t].v[(k + 2) % 3];
            if (std::abs(tris[t].normal.dot(points[far_u]) - tris[t].offset) <= merge_tolerance &&
                std::abs(tris[u].normal.dot(points[far_t]) - tris[u].offset) <= merge_tolerance &&
                tris[t].normal.dot(tris[u].normal) > 0) {
                groups.unite(t, u);
            }
        }
    }

    // Each group's boundary, walked into one counter-clockwise loop.
    std::vector<std::uint32_t> remap(points.size(), UINT32_MAX);
    std::vector<std::vector<std::uint32_t>> loops;
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> members;
    for (std::uint32_t t = 0; t < tris.size(); ++t) {
        if (tris[t].alive) members[groups.find(t)].push_back(t);
    }
    std::vector<std::uint32_t> roots;
    for (const auto& [root, list] : members) roots.push_back(root);
    std::sort(roots.begin(), roots.end());  // deterministic face order
    for (const std::uint32_t root : roots) {
        std::unordered_map<std::uint32_t, std::uint32_t> next;
        for (const std::uint32_t t : members[root]) {
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t a = tris[t].v[k], b = tris[t].v[(k + 1) % 3];
                if (groups.find(qh.neighbour(a, b)) != root) next[a] = b;
            }
        }
        std::uint32_t start = UINT32_MAX;
        for (const auto& [a, b] : next) start = std::min(start, a);
        std::vector<std::uint32_t> loop{start};
        for (std::uint32_t v = next[loop[0]]; v != loop[0] && loop.size() <= next.size(); v = next[v])
            loop.push_back(v);
        SPINDLE_ASSERT(loop.size() == next.size(), "a merged hull face must have one boundary loop");
        // Drop vertices that sit on a straight run of the loop: they are not corners.
        std::vector<std::uint32_t> corners;
        for (std::size_t k = 0; k < loop.size(); ++k) {
            const Vec3& prev = points[loop[(k + loop.size() - 1) % loop.size()]];
            const Vec3& cur = points[loop[k]];
            const Vec3& nxt = points[loop[(k + 1) % loop.size()]];
            const Vec3 e0 = cur - prev, e1 = nxt - cur;
            if (e0.cross(e1).norm() > 1e-9 * e0.norm() * e1.norm()) corners.push_back(loop[k]);
        }
        if (corners.size() >= 3) loops.push_back(std::move(corners));
    }

    for (const auto& loop : loops) {
        HullFace face;
        face.first = static_cast<std::uint32_t>(m_face_vertices.size());
        face.count = static_cast<std::uint32_t>(loop.size());
        Vec3 newell = Vec3::Zero();
        Vec3 centre = Vec3::Zero();
        for (std::size_t k = 0; k < loop.size(); ++k) {
            const std::uint32_t v = loop[k];
            if (remap[v] == UINT32_MAX) {
                remap[v] = static_cast<std::uint32_t>(m_vertices.size());
                m_vertices.push_back(points[v]);
            }
            m_face_vertices.push_back(remap[v]);
            newell += points[v].cross(points[loop[(k + 1) % loop.size()]]);
            centre += points[v];
        }
        face.normal = newell.normalized();
        face.offset = face.normal.dot(centre / Real(loop.size()));
        m_faces.push_back(face);
    }
    if (m_vertices.size() > kMaxHullVertices) {
        throw Error("convex hull: has " + std::to_string(m_vertices.size()) + " vertices, at most " +
                    std::to_string(kMaxHullVertices) + " are supported");
    }
    const auto face_count = static_cast<std::uint32_t>(m_faces.size());
    m_edges.resize(m_face_vertices.size());
    const std::uint32_t edge_count = detail::collect_edges(m_faces.data(), face_count, m_face_vertices.data(),
                                                           m_edges.data(), static_cast<std::uint32_t>(m_edges.size()));
    m_edges.resize(edge_count);
    SPINDLE_ASSERT(m_vertices.size() + m_faces.size() == m_edges.size() + 2, "hull must satisfy V - E + F = 2");
    for (const Vec3& v : m_vertices) m_bounds.include(v);
    m_vertex_lanes.resize((m_vertices.size() + 3) / 4);
    for (std::size_t i = 0; i < 4 * m_vertex_lanes.size(); ++i) {
        const Vec3& v = m_vertices[i < m_vertices.size() ? i : 0];
        detail::VertexLanes& group = m_vertex_lanes[i / 4];
        group.x[i % 4] = v.x(), group.y[i % 4] = v.y(), group.z[i % 4] = v.z();
    }
    m_arc_edges.resize(m_edges.size());
    for (std::size_t j = 0; j < m_edges.size(); ++j) {
        const HullEdge& e = m_edges[j];
        detail::ArcEdge& a = m_arc_edges[j];
        a.origin = m_vertices[e.v0];
        a.direction = m_vertices[e.v1] - a.origin;
        a.n0 = m_faces[e.f0].normal;
        a.n1 = m_faces[e.f1].normal;
        a.t0 = a.direction.cross(a.n0);
        a.t1 = a.n1.cross(a.direction);
    }
    m_arc_lanes.resize((m_arc_edges.size() + 3) / 4);
    detail::fill_arc_lanes(m_arc_edges.data(), static_cast<std::uint32_t>(m_arc_edges.size()), m_arc_lanes.data());
    compute_volume_properties();
}

namespace {

// Both bounds() inline this, so the one taking x keeps its matrix local, as it was before the
// one taking the matrix existed.
inline Aabb lanes_bounds(std::span<const detail::VertexLanes> lanes, const Mat3& r, const Vec3& p) {
    using detail::Lanes;
    Lanes lo[3], hi[3];
    for (std::size_t g = 0; g < lanes.size(); ++g) {
        const detail::VertexLanes& v = lanes[g];
        for (int i = 0; i < 3; ++i) {
            // Eigen sums a row of r * v as r0 v0 + (r1 v1 + r2 v2).
            const Lanes world = p[i] + (r(i, 0) * v.x + (r(i, 1) * v.y + r(i, 2) * v.z));
            lo[i] = g == 0 ? world : (world < lo[i] ? world : lo[i]);
            hi[i] = g == 0 ? world : (world > hi[i] ? world : hi[i]);
        }
    }
    Aabb box;
    for (int i = 0; i < 3; ++i) {
        box.min[i] = std::min(std::min(lo[i][0], lo[i][1]), std::min(lo[i][2], lo[i][3]));
        box.max[i] = std::max(std::max(hi[i][0], hi[i][1]), std::max(hi[i][2], hi[i][3]));
    }
    return box;
}

}  // namespace

Aabb ConvexHull::bounds(const Transform& x) const { return lanes_bounds(m_vertex_lanes, x.q.toRotationMatrix(), x.p); }

Aabb ConvexHull::bounds(const Mat3& r, const Vec3& p) const { return lanes_bounds(m_vertex_lanes, r, p); }

void ConvexHull::compute_volume_properties() {
    // Sum signed tetrahedra (r, a, b, c) over a fan of each face, r inside the hull; the
    // second moment of a tetrahedron with a vertex at the origin and edges J is
    // det(J)/120 * J [[2,1,1],[1,2,1],[1,1,2]] J^T.
    Vec3 r = Vec3::Zero();
    for (const Vec3& v : m_vertices) r += v;
    r /= Real(m_vertices.size());
    Mat3 canonical;
    canonical << 2, 1, 1, 1, 2, 1, 1, 1, 2;
    Real volume = 0;
    Vec3 moment = Vec3::Zero();
    Mat3 second = Mat3::Zero();
    for (const HullFace& f : m_faces) {
        const Vec3 a = m_vertices[m_face_vertices[f.first]] - r;
        for (std::uint32_t k = 1; k + 1 < f.count; ++k) {
            Mat3 j;
            j.col(0) = a;
            j.col(1) = m_vertices[m_face_vertices[f.first + k]] - r;
            j.col(2) = m_vertices[m_face_vertices[f.first + k + 1]] - r;
            const Real det = j.determinant();
            volume += det / 6;
            moment += det / 24 * (j.col(0) + j.col(1) + j.col(2));
            second += det / 120 * (j * canonical * j.transpose());
        }
    }
    const Vec3 c = moment / volume;  // relative to r
    m_volume = volume;
    m_centroid = r + c;
    m_covariance = second - volume * c * c.transpose();
    // A merged face's vertices may stray from its plane by the merge tolerance; the ball
    // keeps that far clear of every plane so that it stays inside the vertices' hull.
    Real stray = 0;
    m_inner_radius = kHuge;
    for (const HullFace& f : m_faces) {
        m_inner_radius = std::min(m_inner_radius, f.offset - f.normal.dot(m_centroid));
        for (std::uint32_t k = 0; k < f.count; ++k) {
            stray = std::max(stray, std::abs(f.normal.dot(m_vertices[m_face_vertices[f.first + k]]) - f.offset));
        }
    }
    m_inner_radius = std::max(m_inner_radius - stray, Real(0));
}

std::uint32_t ConvexHull::support_index(const Vec3& d) const noexcept {
    std::uint32_t best = 0;
    Real best_dot = m_vertices[0].dot(d);
    for (std::uint32_t i = 1; i < m_vertices.size(); ++i) {
        const Real x = m_vertices[i].dot(d);
        if (x > best_dot) best_dot = x, best = i;
    }
    return best;
}

}  // namespace spindle
