// Building blocks shared by the pair functions: feature-id packing, polygon clipping
// that tracks which features made each point, manifold reduction to four points, and
// closest points between segments.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "collision/collide.hpp"
#include "collision/lanes.hpp"

namespace spindle::detail {

// ---- Feature ids ----------------------------------------------------------------------
// Bits 31..30 say what kind of contact made the point:
//   0 / 1  face contact with the reference face on shape A / on shape B:
//          bits 29..23 reference face, 22..15 incident face, 14..0 clip-vertex key
//   2      edge-edge contact: bits 29..15 edge of A, 14..0 edge of B
//   3      anything else (rounded shapes, planes): bits 29..0 a key chosen by the pair
// Indices wider than their field wrap; ids only need to stay equal while the same
// features touch, and a wrap costs at most a cold warm start.
inline constexpr std::uint32_t face_contact_id(bool reference_is_b, std::uint32_t reference_face,
                                               std::uint32_t incident_face, std::uint32_t clip_key) {
    return (reference_is_b ? 1u : 0u) << 30 | (reference_face & 0x7Fu) << 23 | (incident_face & 0xFFu) << 15 |
           (clip_key & 0x7FFFu);
}
inline constexpr std::uint32_t edge_contact_id(std::uint32_t edge_a, std::uint32_t edge_b) {
    return 2u << 30 | (edge_a & 0x7FFFu) << 15 | (edge_b & 0x7FFFu);
}
inline constexpr std::uint32_t other_contact_id(std::uint32_t key) { return 3u << 30 | (key & 0x3FFFFFFFu); }

// ---- Clipping -------------------------------------------------------------------------
// A vertex of the incident polygon while it is clipped against the reference face's
// side planes. `key` names the features that made it (14 bits):
//   kind 0: incident vertex a;  kind 1: incident edge a cut by side plane b;
//   kind 2: side plane a cut by side plane b (a corner of the reference face).
// `edge` names what the polygon edge leaving this vertex lies on: an incident edge
// (bit 15 clear) or a side plane (bit 15 set), so the next cut knows its features.
// Left unset until written (every clip writes all three): a clip's room is made on each call.
struct ClipVertex {
    Vec3 p;
    std::uint16_t key;
    std::uint16_t edge;
};

inline constexpr std::uint16_t clip_key(std::uint32_t kind, std::uint32_t a, std::uint32_t b) {
    return static_cast<std::uint16_t>((kind & 3u) << 12 | (a & 0x3Fu) << 6 | (b & 0x3Fu));
}
inline constexpr std::uint16_t kSidePlaneBit = 0x8000;

// Half-space dot(normal, p) <= offset.
struct ClipPlane {
    Vec3 normal;
    Real offset;
};

// Incident polygon p[0..count), counter-clockwise or not; vertices get key (0, i) and
// edge i. Returns count.
int start_clip_polygon(const Vec3* p, int count, ClipVertex* out);

// One Sutherland-Hodgman step against the half-space distance(p) <= 0 (side plane number
// `side`). `out` must hold count + 1 vertices. Returns the new count (0 when nothing is
// left). Inline, so a caller whose plane is simpler than a general one (a box's side
// planes lie along its axes: one coordinate is the distance) pays only for that.
template <typename Distance>
int clip_polygon_by(const ClipVertex* in, int count, Distance&& distance, std::uint32_t side, ClipVertex* out) {
    if (count == 0) return 0;
    const auto side_edge = static_cast<std::uint16_t>(kSidePlaneBit | (side & 0x3Fu));
    int n = 0;
    const ClipVertex* prev = &in[count - 1];
    Real d_prev = distance(prev->p);
    for (int i = 0; i < count; ++i) {
        const ClipVertex* cur = &in[i];
        const Real d_cur = distance(cur->p);
        if ((d_prev <= 0) != (d_cur <= 0)) {
            // The edge prev -> cur crosses the plane; the cut point is named after the
            // feature that edge lies on and this side plane.
            const Real t = d_prev / (d_prev - d_cur);
            ClipVertex& x = out[n++];
            x.p = prev->p + t * (cur->p - prev->p);
            const bool on_side_plane = (prev->edge & kSidePlaneBit) != 0;
            x.key = clip_key(on_side_plane ? 2 : 1, prev->edge & 0x3Fu, side);
            // Entering: the polygon continues along the old edge. Leaving: along the plane.
            x.edge = d_cur <= 0 ? prev->edge : side_edge;
        }
        if (d_cur <= 0) out[n++] = *cur;
        prev = cur;
        d_prev = d_cur;
    }
    return n;
}

// clip_polygon_by against `plane`: dot(normal, p) <= offset.
int clip_polygon(const ClipVertex* in, int count, const ClipPlane& plane, std::uint32_t side, ClipVertex* out);

// ---- Reduction ------------------------------------------------------------------------
struct ContactCandidate {
    Vec3 point;  // midway between the surfaces
    Real separation;
    std::uint32_t id;
};

// Writes at most four of the candidates into m.points (m.normal must be set): all of them
// when there are at most four (unless `prune`), else the deepest and then those spanning
// the largest area. With `prune`, points that add no area (duplicates, points on a line
// already covered) are dropped even from small sets, as when manifolds are merged.
void reduce_to_manifold(const ContactCandidate* candidates, int count, Manifold& m, bool prune = false);

// Scratch space that lives on the stack unless a (rare) large hull needs more. Only the
// `size` elements asked for are made, default-initialised (left as they are for vectors
// and numbers): a room of N made with the array did every element's initialisers each
// time, such as a compound pair's 32 identity poses and empty boxes.
template <typename T, std::size_t N>
class ScratchBuffer {
    static_assert(std::is_trivially_destructible_v<T>, "the elements made in place are never destroyed");

public:
    explicit ScratchBuffer(std::size_t size) {
        if (size > N) m_heap.resize(size);
        m_data = size > N ? m_heap.data()
                          : std::uninitialized_default_construct_n(reinterpret_cast<T*>(m_inline), size) - size;
    }
    ScratchBuffer(const ScratchBuffer&) = delete;
    ScratchBuffer& operator=(const ScratchBuffer&) = delete;
    T* data() { return m_data; }
    const T* data() const { return m_data; }
    T& operator[](std::size_t i) { return m_data[i]; }

private:
    alignas(T) std::byte m_inline[N * sizeof(T)];
    std::vector<T> m_heap;
    T* m_data;
};

// ---- Geometry -------------------------------------------------------------------------
// Parameter in [0, 1] of the point of segment a + t (b - a) closest to p.
Real closest_parameter_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);

// Closest points between segments p1 + s d1 and p2 + t d2 (s, t in [0, 1]). Handles
// zero-length and parallel segments (then picks the middle of the overlap, so a stack
// of parallel capsules gets a centred point).
void closest_segment_parameters(const Vec3& p1, const Vec3& d1, const Vec3& p2, const Vec3& d2, Real& s, Real& t);

// A unit vector perpendicular to v (v need not be unit; any non-zero length).
Vec3 any_perpendicular(const Vec3& v);

// Points p in frame x turned into the world four at a time, in lanes, each lane the sums
// Transform::apply makes, in its order: Eigen's q v is v + w uv + q.vec x uv, with uv twice
// q.vec x v.
inline void lanes_to_world(Lanes& px, Lanes& py, Lanes& pz, const Transform& x) {
    const Real qx = x.q.x(), qy = x.q.y(), qz = x.q.z(), qw = x.q.w();
    Lanes ux = qy * pz - qz * py, uy = qz * px - qx * pz, uz = qx * py - qy * px;
    ux += ux, uy += uy, uz += uz;
    const Lanes wx = x.p.x() + ((px + qw * ux) + (qy * uz - qz * uy));
    const Lanes wy = x.p.y() + ((py + qw * uy) + (qz * ux - qx * uz));
    const Lanes wz = x.p.z() + ((pz + qw * uz) + (qx * uy - qy * ux));
    px = wx, py = wy, pz = wz;
}

// Maps a manifold computed in frame x into the world, its points turned in lanes (every
// slot: those past the count are left as they were).
inline void manifold_to_world(Manifold& m, const Transform& x) {
    static_assert(kMaxManifoldPoints == 4, "a manifold's points fill one group of lanes");
    m.normal = x.rotate(m.normal);
    Lanes px, py, pz;
    for (int i = 0; i < 4; ++i) {
        const Vec3& p = m.points[i].point;
        px[i] = p.x(), py[i] = p.y(), pz[i] = p.z();
    }
    lanes_to_world(px, py, pz, x);
    for (int i = 0; i < m.point_count; ++i) m.points[i].point = Vec3(px[i], py[i], pz[i]);
}

// reduce_to_manifold and then manifold_to_world for at most four candidates (all kept, in
// their order): each point written once, already in the world. m.normal must be set, in x.
inline void candidates_to_world(const ContactCandidate* c, int count, Manifold& m, const Transform& x) {
    static_assert(kMaxManifoldPoints == 4, "a manifold's points fill one group of lanes");
    m.normal = x.rotate(m.normal);
    Lanes px = {}, py = {}, pz = {};
    for (int i = 0; i < count; ++i) px[i] = c[i].point.x(), py[i] = c[i].point.y(), pz[i] = c[i].point.z();
    lanes_to_world(px, py, pz, x);
    for (int i = 0; i < count; ++i) m.points[i] = {Vec3(px[i], py[i], pz[i]), c[i].separation, c[i].id};
    m.point_count = count;
}

inline void flip_manifold(Manifold& m) {
    m.normal = -m.normal;
    std::swap(m.part_a, m.part_b);
}

}  // namespace spindle::detail
