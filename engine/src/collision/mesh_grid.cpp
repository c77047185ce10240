// MeshGrid: buckets over a flat mesh's footprint, built once; a query reports each
// triangle from one bucket only and sorts what it found into the tree's order.
#include "collision/mesh_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "collision/triangle_mesh.hpp"

namespace spindle {
namespace {

// Below this many triangles the tree is shallow enough.
constexpr std::size_t kMinTriangles = 256;
// A flat mesh's triangles each reach a few buckets, and no bucket holds many; a mesh
// that stacks triangles (a closed shape, a cave) is served by its tree.
constexpr std::size_t kMaxEntriesPerTriangle = 6;
constexpr std::uint32_t kMaxPerBucket = 24;
constexpr int kMaxCellsPerAxis = 4096;
// Buckets and triangles one query walks and sorts; a larger box goes to the tree, which
// also prunes by height.
constexpr int kMaxBuckets = 256;
constexpr std::size_t kMaxGathered = 512;
// An entry is a triangle's index shifted past two flags.
constexpr std::uint32_t kFirstAlongU = 1, kFirstAlongV = 2;
constexpr int kFlagBits = 2;

}  // namespace

std::optional<MeshGrid> MeshGrid::build(std::span<const Vec3> vertices, std::span<const MeshTriangle> triangles,
                                        const Aabb& bounds) {
    if (triangles.size() < kMinTriangles || triangles.size() >> (32 - kFlagBits) != 0) return std::nullopt;
    MeshGrid grid;
    const Vec3 size = bounds.max - bounds.min;
    int up = 0;
    size.minCoeff(&up);
    grid.m_axis[0] = up == 0 ? 1 : 0;
    grid.m_axis[1] = up == 2 ? 1 : 2;
    const Real width = size[grid.m_axis[0]], depth = size[grid.m_axis[1]];
    if (!(width > 0) || !(depth > 0)) return std::nullopt;
    // About one bucket per two triangles: a heightfield's cell.
    const Real cell = std::sqrt(2 * width * depth / static_cast<Real>(triangles.size()));
    grid.m_origin = bounds.min;
    grid.m_inverse_cell = 1 / cell;
    for (int k = 0; k < 2; ++k) {
        const Real n = std::floor(size[grid.m_axis[k]] * grid.m_inverse_cell) + 1;
        if (!(n <= kMaxCellsPerAxis)) return std::nullopt;
        grid.m_count[k] = static_cast<int>(n);
    }

    const auto buckets = static_cast<std::size_t>(grid.m_count[0]) * static_cast<std::size_t>(grid.m_count[1]);
    std::vector<std::uint32_t> count(buckets + 1, 0);
    std::size_t entries = 0;
    // fn(bucket, flags): kFirstAlongU / kFirstAlongV when the bucket is the triangle's first
    // along that axis.
    const auto each_bucket = [&](const MeshTriangle& t, auto&& fn) {
        const Aabb box = triangle_bounds(vertices, t);
        const Range u = grid.triangle_cells(box.min[grid.m_axis[0]], box.max[grid.m_axis[0]], 0);
        const Range v = grid.triangle_cells(box.min[grid.m_axis[1]], box.max[grid.m_axis[1]], 1);
        for (int j = v.lo; j <= v.hi; ++j) {
            for (int i = u.lo; i <= u.hi; ++i) {
                const std::uint32_t flags = (i == u.lo ? kFirstAlongU : 0u) | (j == v.lo ? kFirstAlongV : 0u);
                fn(static_cast<std::size_t>(j) * grid.m_count[0] + i, flags);
            }
        }
    };
    for (const MeshTriangle& t : triangles) {
        each_bucket(t, [&](std::size_t b, std::uint32_t) {
            ++count[b];
            ++entries;
        });
        if (entries > kMaxEntriesPerTriangle * triangles.size()) return std::nullopt;
    }
    if (*std::max_element(count.begin(), count.end()) > kMaxPerBucket) return std::nullopt;
    grid.m_first.assign(buckets + 1, 0);
    for (std::size_t b = 0; b < buckets; ++b) grid.m_first[b + 1] = grid.m_first[b] + count[b];
    grid.m_entries.resize(entries);
    std::vector<std::uint32_t> next(grid.m_first.begin(), grid.m_first.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
        each_bucket(triangles[t],
                    [&](std::size_t b, std::uint32_t flags) { grid.m_entries[next[b]++] = t << kFlagBits | flags; });
    }
    return grid;
}

// Coordinate x in cells along the grid's axis (0 or 1).
Real MeshGrid::in_cells(Real x, int axis) const { return (x - m_origin[m_axis[axis]]) * m_inverse_cell; }

int MeshGrid::clamped(Real c, int axis) const {
    return static_cast<int>(std::clamp(c, Real(0), Real(m_count[axis] - 1)));
}

// A triangle spanning [lo, hi] takes the buckets from floor(lo) to ceil(hi) - 1: a
// heightfield's triangle, whose bounds end on the next cell's border, stays in its own
// cell instead of reaching into three more.
MeshGrid::Range MeshGrid::triangle_cells(Real lo, Real hi, int axis) const {
    const int first = clamped(std::floor(in_cells(lo, axis)), axis);
    return {first, std::max(first, clamped(std::ceil(in_cells(hi, axis)) - 1, axis))};
}

// A query spanning [lo, hi] looks from ceil(lo) - 1 to floor(hi): one bucket lower when lo
// lies on a border, where a triangle ending on that border sits. Both ends of both ranges
// never decrease as their input grows, so a triangle whose bounds overlap the box's
// along the axis (its lo <= the box's hi, the box's lo <= its hi) shares a bucket with it.
MeshGrid::Range MeshGrid::query_cells(Real lo, Real hi, int axis) const {
    return {clamped(std::ceil(in_cells(lo, axis)) - 1, axis), clamped(std::floor(in_cells(hi, axis)), axis)};
}

bool MeshGrid::query(const Aabb& box, std::span<const Aabb> bounds, FunctionRef<void(std::uint32_t)> visit) const {
    const Range u = query_cells(box.min[m_axis[0]], box.max[m_axis[0]], 0);
    const Range v = query_cells(box.min[m_axis[1]], box.max[m_axis[1]], 1);
    if ((u.hi - u.lo + 1) * (v.hi - v.lo + 1) > kMaxBuckets) return false;
    std::array<std::uint32_t, kMaxGathered> found;
    std::size_t n = 0;
    for (int j = v.lo; j <= v.hi; ++j) {
        for (int i = u.lo; i <= u.hi; ++i) {
            const std::size_t b = static_cast<std::size_t>(j) * m_count[0] + i;
            for (std::uint32_t e = m_first[b]; e < m_first[b + 1]; ++e) {
                // Reported from the first bucket of the query's that holds it, once: its
                // own first along an axis, or the query's first where it began before.
                const std::uint32_t entry = m_entries[e];
                if (!(i == u.lo || entry & kFirstAlongU) || !(j == v.lo || entry & kFirstAlongV)) continue;
                const std::uint32_t t = entry >> kFlagBits;
                if (!bounds[t].overlaps(box)) continue;
                if (n == kMaxGathered) return false;
                found[n++] = t;
            }
        }
    }
    std::sort(found.begin(), found.begin() + n);
    for (std::size_t k = 0; k < n; ++k) visit(found[k]);
    return true;
}

}  // namespace spindle
