// TriangleMesh construction (validation, zero-area triangles dropped, active-edge flags)
// and its static AABB tree: built top-down with a binned SAH split, queried iteratively.
#include "collision/triangle_mesh.hpp"

#include <algorithm>
#include <array>
#include <string>

#include <spindle/platform/assert.hpp>
#include <spindle/platform/error.hpp>

#include "collision/error_text.hpp"
#include "collision/polyhedron.hpp"

namespace spindle {
namespace {

constexpr std::uint32_t kLeafSize = 4;
constexpr int kBins = 12;
// Past this depth splits are by count, so the tree is at most ~kSahDepth + log2(n) deep
// and the query's fixed stack cannot overflow.
constexpr int kSahDepth = 48;
constexpr int kQueryStack = 128;
// Neighbouring triangles closer than ~5 degrees to flat share an inactive edge.
constexpr Real kFlatCosine = 0.9962;

}  // namespace

TriangleMesh::TriangleMesh(std::span<const Vec3> vertices, std::span<const std::uint32_t> indices) {
    if (indices.size() % 3 != 0) {
        throw Error("triangle mesh: index count must be a multiple of 3, got " + std::to_string(indices.size()));
    }
    for (std::size_t i = 0; i < vertices.size(); ++i) {
        if (!is_finite(vertices[i])) {
            throw Error("triangle mesh: vertex " + std::to_string(i) + " must be finite, got " +
                        detail::to_text(vertices[i]));
        }
        if (vertices[i].cwiseAbs().maxCoeff() > kMaxCoordinate) {
            throw Error("triangle mesh: vertex " + std::to_string(i) + " must be within " +
                        detail::to_text(kMaxCoordinate) + " m of the origin, got " + detail::to_text(vertices[i]));
        }
    }
    for (std::size_t k = 0; k < indices.size(); ++k) {
        if (indices[k] >= vertices.size()) {
            throw Error("triangle mesh: index " + std::to_string(k) + " (triangle " + std::to_string(k / 3) +
                        ") must be below the vertex count " + std::to_string(vertices.size()) + ", got " +
                        std::to_string(indices[k]));
        }
    }
    m_vertices.assign(vertices.begin(), vertices.end());
    for (std::size_t k = 0; k < indices.size(); k += 3) {
        MeshTriangle t;
        t.v[0] = indices[k], t.v[1] = indices[k + 1], t.v[2] = indices[k + 2];
        const Vec3 e0 = m_vertices[t.v[1]] - m_vertices[t.v[0]];
        const Vec3 e1 = m_vertices[t.v[2]] - m_vertices[t.v[0]];
        const Vec3 e2 = m_vertices[t.v[2]] - m_vertices[t.v[1]];
        // Zero area, relative to the triangle's size: no normal, nothing to collide with.
        const Real scale = e0.squaredNorm() + e1.squaredNorm() + e2.squaredNorm();
        if (e0.cross(e1).norm() <= Real(1e-12) * scale) continue;
        m_triangles.push_back(t);
    }
    if (m_triangles.empty()) throw Error("triangle mesh: has no triangle of non-zero area");
    mark_active_edges();
    build_tree();
    m_normals.resize(m_triangles.size());
    m_bounds.resize(m_triangles.size());
    for (std::uint32_t t = 0; t < m_triangles.size(); ++t) {
        m_normals[t] = made_normal(t);
        m_bounds[t] = triangle_bounds(m_vertices, m_triangles[t]);
    }
    m_grid = MeshGrid::build(m_vertices, m_triangles, local_bounds());
}

Vec3 TriangleMesh::made_normal(std::uint32_t t) const {
    const MeshTriangle& tri = m_triangles[t];
    return detail::triangle_normal(m_vertices[tri.v[0]], m_vertices[tri.v[1]], m_vertices[tri.v[2]]);
}

void TriangleMesh::mark_active_edges() {
    // Sort the edges by their undirected key; an edge shared by exactly two triangles
    // with matching winding is inactive when the pair is flat or concave there.
    struct EdgeRef {
        std::uint64_t key;
        std::uint32_t triangle;
        std::uint32_t edge;
        bool operator<(const EdgeRef& o) const { return key < o.key || (key == o.key && triangle < o.triangle); }
    };
    std::vector<EdgeRef> refs;
    refs.reserve(3 * m_triangles.size());
    for (std::uint32_t t = 0; t < m_triangles.size(); ++t) {
        for (std::uint32_t k = 0; k < 3; ++k) {
            const std::uint64_t a = m_triangles[t].v[k], b = m_triangles[t].v[(k + 1) % 3];
            refs.push_back({std::min(a, b) << 32 | std::max(a, b), t, k});
        }
    }
    std::sort(refs.begin(), refs.end());
    for (std::size_t i = 0; i < refs.size();) {
        std::size_t j = i;
        while (j < refs.size() && refs[j].key == refs[i].key) ++j;
        if (j - i == 2) {
            MeshTriangle& t1 = m_triangles[refs[i].triangle];
            MeshTriangle& t2 = m_triangles[refs[i + 1].triangle];
            const std::uint32_t k1 = refs[i].edge, k2 = refs[i + 1].edge;
            const bool opposite_winding = t1.v[k1] == t2.v[(k2 + 1) % 3];
            const Vec3 n1 = made_normal(refs[i].triangle), n2 = made_normal(refs[i + 1].triangle);
            const Vec3& on_edge = m_vertices[t1.v[k1]];
            const Vec3& far2 = m_vertices[t2.v[(k2 + 2) % 3]];
            const bool concave = n1.dot(far2 - on_edge) > 0;
            if (opposite_winding && (concave || n1.dot(n2) >= kFlatCosine)) {
                t1.active_edges &= static_cast<std::uint8_t>(~(1u << k1));
                t2.active_edges &= static_cast<std::uint8_t>(~(1u << k2));
            }
        }
        i = j;
    }
}

void TriangleMesh::build_tree() {
    struct Item {
        Aabb box;
        Vec3 centre;
        MeshTriangle triangle;
    };
    std::vector<Item> items;
    items.reserve(m_triangles.size());
    for (const MeshTriangle& t : m_triangles) {
        const Aabb box = triangle_bounds(m_vertices, t);
        items.push_back({box, box.center(), t});
    }
    struct Task {
        std::uint32_t node, begin, end;
        int depth;
    };
    m_nodes.clear();
    m_nodes.emplace_back();
    std::vector<Task> tasks{{0, 0, static_cast<std::uint32_t>(items.size()), 0}};
    while (!tasks.empty()) {
        const Task task = tasks.back();
        tasks.pop_back();
        Aabb box, centres;
        for (std::uint32_t i = task.begin; i < task.end; ++i) {
            box = box.merged(items[i].box);
            centres.include(items[i].centre);
        }
        m_nodes[task.node].box = box;
        const std::uint32_t count = task.end - task.begin;
        if (count <= kLeafSize) {
            m_nodes[task.node].first = task.begin;
            m_nodes[task.node].count = count;
            continue;
        }
        int axis = 0;
        const Real extent = centres.extents().maxCoeff(&axis);
        const Real lo = centres.min[axis];
        std::uint32_t mid = task.begin + count / 2;
        bool by_count = extent <= 0 || task.depth >= kSahDepth;
        if (!by_count) {
            // Binned SAH: cost of a split ~ area(left) * n(left) + area(right) * n(right).
            std::array<Aabb, kBins> bin_box;
            std::array<std::uint32_t, kBins> bin_count{};
            const auto bin_of = [&](const Item& it) {
                return std::min(kBins - 1, static_cast<int>((it.centre[axis] - lo) / (2 * extent) * kBins));
            };
            for (std::uint32_t i = task.begin; i < task.end; ++i) {
                const int b = bin_of(items[i]);
                bin_box[b] = bin_box[b].merged(items[i].box);
                ++bin_count[b];
            }
            std::array<Real, kBins> right_cost{};
            Aabb acc;
            std::uint32_t n = 0;
            for (int b = kBins - 1; b > 0; --b) {
                acc = acc.merged(bin_box[b]);
                n += bin_count[b];
                right_cost[b] = n ? acc.perimeter() * n : 0;
            }
            acc = Aabb();
            n = 0;
            Real best = kHuge;
            int split = -1;
            for (int b = 0; b < kBins - 1; ++b) {
                acc = acc.merged(bin_box[b]);
                n += bin_count[b];
                if (n == 0 || n == count) continue;
                const Real cost = acc.perimeter() * n + right_cost[b + 1];
                if (cost < best) best = cost, split = b;
            }
            if (split < 0) {
                by_count = true;
            } else {
                const auto it = std::partition(items.begin() + task.begin, items.begin() + task.end,
                                               [&](const Item& item) { return bin_of(item) <= split; });
                mid = static_cast<std::uint32_t>(it - items.begin());
            }
        }
        if (by_count) {
            std::nth_element(items.begin() + task.begin, items.begin() + mid, items.begin() + task.end,
                             [&](const Item& x, const Item& y) { return x.centre[axis] < y.centre[axis]; });
        }
        const auto left = static_cast<std::uint32_t>(m_nodes.size());
        m_nodes.emplace_back();
        m_nodes.emplace_back();
        m_nodes[task.node].first = left;
        m_nodes[task.node].count = 0;
        tasks.push_back({left, task.begin, mid, task.depth + 1});
        tasks.push_back({left + 1, mid, task.end, task.depth + 1});
    }
    for (std::size_t i = 0; i < items.size(); ++i) m_triangles[i] = items[i].triangle;
}

void TriangleMesh::query(const Aabb& box, FunctionRef<void(std::uint32_t)> visit) const {
    if (!local_bounds().overlaps(box)) return;
    if (m_grid && m_grid->query(box, m_bounds, visit)) return;
    query_tree(box, visit);
}

void TriangleMesh::query_tree(const Aabb& box, FunctionRef<void(std::uint32_t)> visit) const {
    std::uint32_t stack[kQueryStack];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const MeshNode& node = m_nodes[stack[--top]];
        if (!node.box.overlaps(box)) continue;
        if (node.count > 0) {
            for (std::uint32_t t = node.first; t < node.first + node.count; ++t) {
                if (m_bounds[t].overlaps(box)) visit(t);
            }
            continue;
        }
        SPINDLE_ASSERT(top + 2 <= kQueryStack, "mesh tree deeper than its build allows");
        stack[top++] = node.first + 1;
        stack[top++] = node.first;
    }
}

}  // namespace spindle
