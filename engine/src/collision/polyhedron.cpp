// Polyhedron views of hulls, boxes and triangles, and edge extraction from face loops.
#include "collision/polyhedron.hpp"

#include <algorithm>
#include <vector>

#include <spindle/platform/assert.hpp>

namespace spindle::detail {
namespace {

struct BoxTopology {
    std::array<HullEdge, 12> edges;
    BoxTopology() {
        std::array<HullFace, 6> faces;
        for (std::uint32_t f = 0; f < 6; ++f) faces[f].first = 4 * f, faces[f].count = 4;
        const std::uint32_t n = collect_edges(faces.data(), 6, kBoxLoops, edges.data(), 12);
        SPINDLE_ASSERT(n == 12, "a box has 12 edges");
    }
};

const BoxTopology& box_topology() {
    static const BoxTopology topology;
    return topology;
}

PolyView make_view(std::span<const Vec3> vertices, std::span<const HullFace> faces, const std::uint32_t* face_vertices,
                   std::span<const HullEdge> edges, const Vec3& inner_centre, Real inner_radius) {
    PolyView v;
    v.inner_centre = inner_centre;
    v.inner_radius = inner_radius;
    v.vertices = vertices.data();
    v.vertex_count = static_cast<std::uint32_t>(vertices.size());
    v.faces = faces.data();
    v.face_count = static_cast<std::uint32_t>(faces.size());
    v.face_vertices = face_vertices;
    v.edges = edges.data();
    v.edge_count = static_cast<std::uint32_t>(edges.size());
    return v;
}

}  // namespace

PolyView view_of(const ConvexHull& hull) {
    PolyView v = make_view(hull.vertices(), hull.faces(), hull.face_vertices().data(), hull.edges(), hull.centroid(),
                           hull.inner_radius());
    v.vertex_lanes = hull.vertex_lanes().data();
    v.arc_edges = hull.arc_edges().data();
    v.arc_lanes = hull.arc_lanes().data();
    return v;
}

BoxPoly::BoxPoly(const Vec3& h) {
    for (int i = 0; i < 8; ++i) {
        m_vertices[i] = Vec3(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z());
    }
    for (int k = 0; k < 3; ++k) {
        for (int s = 0; s < 2; ++s) {
            HullFace& f = m_faces[2 * k + s];
            f.normal = Vec3::Zero();
            f.normal[k] = s == 0 ? 1 : -1;
            f.offset = h[k];
            f.first = static_cast<std::uint32_t>(4 * (2 * k + s));
            f.count = 4;
        }
    }
}

PolyView BoxPoly::view() const {
    const Vec3 half_extents = m_vertices[7];  // the corner with every sign positive
    return make_view(m_vertices, m_faces, kBoxLoops, box_topology().edges, Vec3::Zero(), half_extents.minCoeff());
}

TrianglePoly::TrianglePoly(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n) : m_vertices{a, b, c} {
    m_faces[0] = {n, n.dot(a), 0, 3};
    m_faces[1] = {-n, -n.dot(a), 3, 3};
}

PolyView TrianglePoly::view() const {
    const Vec3 centroid = (m_vertices[0] + m_vertices[1] + m_vertices[2]) / 3;
    return make_view(m_vertices, m_faces, kTriangleLoops, kTriangleEdges, centroid, 0);
}

std::uint32_t collect_edges(const HullFace* faces, std::uint32_t face_count, const std::uint32_t* face_vertices,
                            HullEdge* out, std::uint32_t capacity) {
    // Each edge of a closed surface appears once in each direction; sort the directed
    // edges so the reverse of a -> b is found by binary search.
    struct Directed {
        std::uint64_t key;
        std::uint32_t face;
        bool operator<(const Directed& o) const { return key < o.key; }
    };
    std::vector<Directed> directed;
    for (std::uint32_t f = 0; f < face_count; ++f) {
        const HullFace& face = faces[f];
        for (std::uint32_t k = 0; k < face.count; ++k) {
            const std::uint64_t a = face_vertices[face.first + k];
            const std::uint64_t b = face_vertices[face.first + (k + 1) % face.count];
            directed.push_back({a << 32 | b, f});
        }
    }
    std::sort(directed.begin(), directed.end());
    std::uint32_t n = 0;
    for (const Directed& d : directed) {
        const auto a = static_cast<std::uint32_t>(d.key >> 32);
        const auto b = static_cast<std::uint32_t>(d.key & 0xFFFFFFFFu);
        if (a > b) continue;
        const Directed probe{std::uint64_t(b) << 32 | a, 0};
        const auto it = std::lower_bound(directed.begin(), directed.end(), probe);
        SPINDLE_ASSERT(it != directed.end() && it->key == probe.key, "face loops must form a closed surface");
        if (n < capacity) out[n] = {a, b, d.face, it->face};
        ++n;
    }
    return n;
}

}  // namespace spindle::detail
