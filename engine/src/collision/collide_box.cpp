// Box-box: separating axis test over the 15 axes (3 + 3 face normals, 9 edge
// cross products), then the incident face clipped against the reference face, or a
// single point between the two closest edges.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "collision/clipping.hpp"
#include "collision/lanes.hpp"
#include "collision/pair_functions.hpp"

namespace spindle::detail {
namespace {

// Each face's corners in kBoxLoops' order, the signs of their coordinates four at a time
// (kLoopSigns[f][c][k]: corner k's coordinate c).
struct LoopSigns {
    alignas(sizeof(Lanes)) Real signs[6][3][4];
};
constexpr LoopSigns loop_signs() {
    LoopSigns table{};
    for (int f = 0; f < 6; ++f) {
        for (int k = 0; k < 4; ++k) {
            for (int c = 0; c < 3; ++c) table.signs[f][c][k] = (kBoxLoops[4 * f + k] >> c & 1u) != 0 ? 1 : -1;
        }
    }
    return table;
}
constexpr LoopSigns kLoopSigns = loop_signs();

// Lanes from four doubles in a row.
Lanes load_lanes(const Real* x) {
    Lanes lanes;
    std::memcpy(&lanes, x, sizeof lanes);
    return lanes;
}

struct BoxAxis {
    Real separation = -kHuge;
    int index = -1;  // face axis 0..2, or edge pair 3 * i + j
};

// Reference box r (half extents hr) and incident box i (hi, rotation ri and centre ti in
// r's frame). Writes the clipped points in r's frame; n is r's face normal pointing at i.
// A corner that clipping drops lies beside the reference face, outside r: it touches
// nothing, and is not kept (as a point it would prop the box up past r's edge), unless
// no point survives at all. `square`: ri is the identity, up to the signs of its zeros.
int box_face_contact(const Vec3& hr, const Vec3& hi, const Mat3& ri, const Vec3& ti, int axis, Real speculative,
                     bool reference_is_b, bool square, Vec3& n, ContactCandidate* out) {
    const Real sign = ti[axis] < 0 ? -1 : 1;
    n = Vec3::Zero();
    n[axis] = sign;
    const auto reference_face = static_cast<std::uint32_t>(2 * axis + (sign < 0 ? 1 : 0));

    // Incident face: the face of i whose normal is most against n (ri' n, a row of ri: n has
    // one non-zero coordinate).
    const Vec3 along = sign * ri.row(axis).transpose();
    int j = 0;
    for (int k = 1; k < 3; ++k) {
        if (std::abs(along[k]) > std::abs(along[j])) j = k;
    }
    const auto incident_face = static_cast<std::uint32_t>(2 * j + (along[j] > 0 ? 1 : 0));
    // Its corners in BoxPoly's loop order (the clip keys name them by place in the loop),
    // made in r's frame as BoxPoly would make them: four at a time in lanes, lane k corner k,
    // each coordinate the sums of ri * corner + ti (x + (y + z), then ti).
    // (A half extent times its corner's sign: the same bits as the half extent or its negation.)
    const auto& signs = kLoopSigns.signs[incident_face];
    const Lanes cx = hi.x() * load_lanes(signs[0]), cy = hi.y() * load_lanes(signs[1]),
                cz = hi.z() * load_lanes(signs[2]);
    const auto coordinate = [&](int i) { return (ri(i, 0) * cx + (ri(i, 1) * cy + ri(i, 2) * cz)) + ti[i]; };
    // Square, each sum is a half extent (never zero) plus products with zeros: the extent.
    const Lanes corners[3] = {square ? cx + ti[0] : coordinate(0), square ? cy + ti[1] : coordinate(1),
                              square ? cz + ti[2] : coordinate(2)};
    // The reference face's four side planes lie along r's other two axes: a point's
    // distance past one is a coordinate (the same bits a general plane's dot product gives).
    // Side s is +u, -u, +v, -v for s = 0..3 (u, v the axes after `axis`), in the order
    // they are clipped against.
    const auto side_distance = [&](int s, const auto& p) {
        const int u = (axis + 1 + s / 2) % 3;
        return (s % 2 == 0 ? p[u] : -p[u]) - hr[u];
    };
    unsigned past_sides = 0;  // side s set when a corner lies past it (NaN too, as the clip)
    for (int s = 0; s < 4; ++s) past_sides |= (lane_bits(~(side_distance(s, corners) <= 0)) != 0 ? 1u : 0u) << s;
    int n_out = 0;
    // Where no corner lies past a side (a box standing square on a larger face, or beside one
    // of its size) the face is its four corners; where they lie past one side only (a box on
    // two) the face is cut by one line, its cuts made four at a time in lanes. Either way the
    // points are those the clip below gives, in its order, with its keys.
    if ((past_sides & (past_sides - 1)) == 0) {
        const int cut_side = past_sides == 0 ? -1 : __builtin_ctz(past_sides);
        // Lanes 0-3 the corners, 4-7 where the edge from corner k - 1 to corner k crosses the
        // side (Sutherland-Hodgman's cut, prev + t (cur - prev)); `order` the clip's output.
        Lanes points[2][3];
        std::uint16_t keys[8];
        unsigned order[8];
        int count = 0;
        for (int c = 0; c < 3; ++c) points[0][c] = corners[c];
        for (std::uint32_t k = 0; k < 4; ++k) keys[k] = clip_key(0, k, 0);
        if (cut_side < 0) {
            for (unsigned k = 0; k < 4; ++k) order[count++] = k;
        } else {
            const Lanes d = side_distance(cut_side, corners);
            const Lanes d_prev = __builtin_shufflevector(d, d, 3, 0, 1, 2);
            const Lanes t = d_prev / (d_prev - d);
            for (int c = 0; c < 3; ++c) {
                const Lanes prev = __builtin_shufflevector(corners[c], corners[c], 3, 0, 1, 2);
                points[1][c] = prev + t * (corners[c] - prev);
            }
            const unsigned inside = lane_bits(d <= 0);
            for (std::uint32_t k = 0; k < 4; ++k) {
                const std::uint32_t prev = (k + 3) % 4;
                if ((inside >> prev & 1u) != (inside >> k & 1u)) {
                    keys[4 + k] = clip_key(1, prev, static_cast<std::uint32_t>(cut_side));
                    order[count++] = 4 + k;
                }
                if ((inside >> k & 1u) != 0) order[count++] = k;
            }
            // A cut rounded past a later side (its corners on that side, to the last bit) is
            // clipped there too: the general clip below.
            unsigned cuts = 0;
            for (int i = 0; i < count; ++i) cuts |= order[i] >= 4 ? 1u << (order[i] - 4) : 0u;
            for (int s = cut_side + 1; s < 4; ++s) {
                if ((lane_bits(~(side_distance(s, points[1]) <= 0)) & cuts) != 0) count = -1;
            }
        }
        if (count >= 0) {
            // n . p and p - n s / 2 in lanes (n has one non-zero coordinate), each point then
            // read at its place in `order`.
            Real separation[8], surface[3][8];
            for (int g = 0; g < (cut_side < 0 ? 1 : 2); ++g) {
                const Lanes along_n = sign * points[g][axis] - hr[axis];
                const Lanes half = Real(0.5) * along_n;
                std::memcpy(separation + 4 * g, &along_n, sizeof along_n);
                for (int c = 0; c < 3; ++c) {
                    const Lanes on_surface = points[g][c] - n[c] * half;
                    std::memcpy(surface[c] + 4 * g, &on_surface, sizeof on_surface);
                }
            }
            for (int i = 0; i < count; ++i) {
                const unsigned k = order[i];
                if (separation[k] > speculative) continue;
                out[n_out++] = {Vec3(surface[0][k], surface[1][k], surface[2][k]), separation[k],
                                face_contact_id(reference_is_b, reference_face, incident_face, keys[k])};
            }
            if (n_out > 0) return n_out;
            past_sides = 0;  // nothing within reach: the deepest corner below
        }
    }
    // Cut by two sides or more (a box at a corner, or turned): the general clip, each side
    // with a corner past it in turn. A side every point is inside of would give the polygon
    // back as it is, so it is not clipped against.
    if (past_sides != 0) {
        ClipVertex buffer_a[8], buffer_b[8];
        for (std::uint32_t k = 0; k < 4; ++k) {
            buffer_a[k] = {Vec3(corners[0][k], corners[1][k], corners[2][k]), clip_key(0, k, 0),
                           static_cast<std::uint16_t>(k)};
        }
        int count = 4;
        ClipVertex* in = buffer_a;
        ClipVertex* next = buffer_b;
        for (std::uint32_t s = 0; s < 4; ++s) {
            const auto distance = [&](const Vec3& p) { return side_distance(static_cast<int>(s), p); };
            const auto past = [&](const ClipVertex& v) { return !(distance(v.p) <= 0); };  // NaN too
            if (std::any_of(in, in + count, past)) {
                count = clip_polygon_by(in, count, distance, s, next);
                std::swap(in, next);
            }
        }
        for (int k = 0; k < count; ++k) {
            const Real separation = sign * in[k].p[axis] - hr[axis];  // n . p: n has one non-zero coordinate
            if (separation > speculative) continue;
            out[n_out++] = {in[k].p - n * (Real(0.5) * separation), separation,
                            face_contact_id(reference_is_b, reference_face, incident_face, in[k].key)};
        }
    }
    if (n_out > 0) return n_out;
    // Nothing over the reference face is within reach, yet the face axis says the boxes
    // touch (it won over an edge pair by the bias towards faces): the incident corner
    // deepest along the normal stands for the contact, so the pair is never left without one.
    const Vec3 down = ri.transpose() * -n;
    std::uint32_t corner = 0;
    Vec3 local;
    for (int k = 0; k < 3; ++k) {
        local[k] = down[k] >= 0 ? hi[k] : -hi[k];
        corner |= down[k] >= 0 ? 1u << k : 0u;
    }
    const Vec3 deepest = ri * local + ti;
    const Real separation = n.dot(deepest) - hr[axis];
    if (separation > speculative) return 0;
    out[0] = {deepest - n * (Real(0.5) * separation), separation,
              face_contact_id(reference_is_b, reference_face, incident_face, clip_key(3, corner, 0))};
    return 1;
}

// Where a face of each box ties for the least overlap and the faces are not parallel (two
// edges meeting in a wedge, as the two cards at a card house's apex), a sharp edge has no
// one normal: taking one face's tilts the push by up to the wedge's angle, and friction
// must carry that share (at a card house's apex 0.40 of the push in a 0.5 cone). As if
// the edges were rounded, the normal turns from one face's to the other's across a band
// of the two separations, so it is the bisector at a tie and never jumps. The band is a
// quarter of the rounding Jolt gives a box by default (its convex radius: 5 cm, at most
// the box's thinnest half extent): much narrower, the jittered card houses still lose
// their top pair; twice as wide, it turns the normal where a box's face truly carries an
// edge (a ragdoll's pelvis slides off its bench). Each point's separation is measured
// along the turned normal against the reference box's support.
void wedge_normal(const Vec3& ha, const Vec3& hb, const Mat3& r, const Vec3& t, const BoxAxis& face_a,
                  const BoxAxis& face_b, bool on_b, Vec3& normal, ContactCandidate* c, int count) {
    constexpr Real kRounding = 0.05;
    const Real band = Real(0.25) * std::min({kRounding, ha.minCoeff(), hb.minCoeff()});
    const Real w = std::clamp(Real(0.5) + (face_b.separation - face_a.separation) / (2 * band), Real(0), Real(1));
    if (w == 0 && !on_b) return;
    if (w == 1 && on_b) return;
    // Only edges meeting within the rounding: deeper, the faces' overlaps say nothing of an edge.
    if (std::min(face_a.separation, face_b.separation) < -band) return;
    Vec3 na = Vec3::Zero();
    na[face_a.index] = t[face_a.index] < 0 ? -1 : 1;
    const Vec3 axis_b = r.col(face_b.index);
    const Vec3 nb = axis_b.dot(t) > 0 ? axis_b : Vec3(-axis_b);  // B's face normal turned to point from A to B
    const Real cos_wedge = na.dot(nb);
    if (cos_wedge > Real(1) - Real(1e-9) || cos_wedge <= 0) return;  // parallel faces, or no wedge
    const Vec3 n = ((1 - w) * na + w * nb).normalized();
    for (int k = 0; k < count; ++k) {
        if (on_b) {
            const Vec3 q = c[k].point - normal * (Real(0.5) * c[k].separation);  // on A
            const Real separation = n.dot(t) - hb.dot((r.transpose() * n).cwiseAbs()) - n.dot(q);
            c[k].point = q + n * (Real(0.5) * separation);
            c[k].separation = separation;
        } else {
            const Vec3 q = c[k].point + normal * (Real(0.5) * c[k].separation);  // on B
            const Real separation = n.dot(q) - ha.dot(n.cwiseAbs());
            c[k].point = q - n * (Real(0.5) * separation);
            c[k].separation = separation;
        }
    }
    normal = n;
}

}  // namespace

int collide_box_box(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                    Manifold* out, int) {
    const Vec3& ha = a.half_extents;
    const Vec3& hb = b.half_extents;
    // Everything in A's frame: r's columns are B's axes, t is B's centre.
    const Mat3 r = (xa.q.conjugate() * xb.q).toRotationMatrix();
    const Vec3 t = xa.apply_inverse(xb.p);
    // r's rows and columns in lanes, lane 3 a copy of lane 2 (never read: every test below
    // masks it off; a zero there was a register vmovq that valgrind cannot decode).
    const Lanes rows[3] = {Lanes{r(0, 0), r(0, 1), r(0, 2), r(0, 2)}, Lanes{r(1, 0), r(1, 1), r(1, 2), r(1, 2)},
                           Lanes{r(2, 0), r(2, 1), r(2, 2), r(2, 2)}};
    const Lanes columns[3] = {Lanes{r(0, 0), r(1, 0), r(2, 0), r(2, 0)}, Lanes{r(0, 1), r(1, 1), r(2, 1), r(2, 1)},
                              Lanes{r(0, 2), r(1, 2), r(2, 2), r(2, 2)}};
    const Lanes t_lanes{t.x(), t.y(), t.z(), t.z()};

    BoxAxis face_a, face_b, edge;
    // A's axis i: |t_i| - ha_i - |r|.row(i) . hb; B's axis j: |r.col(j) . t| - hb_j - |r|.col(j) . ha
    // (a dot product sums x + (y + z)).
    const Lanes faces_a =
        lane_abs(t_lanes) - Lanes{ha.x(), ha.y(), ha.z(), ha.z()} -
        (lane_abs(columns[0]) * hb[0] + (lane_abs(columns[1]) * hb[1] + lane_abs(columns[2]) * hb[2]));
    const Lanes faces_b = lane_abs(rows[0] * t[0] + (rows[1] * t[1] + rows[2] * t[2])) -
                          Lanes{hb.x(), hb.y(), hb.z(), hb.z()} -
                          (lane_abs(rows[0]) * ha[0] + (lane_abs(rows[1]) * ha[1] + lane_abs(rows[2]) * ha[2]));
    if ((lane_bits(faces_a > speculative) & 7u) != 0 || (lane_bits(faces_b > speculative) & 7u) != 0) return 0;
    for (int i = 0; i < 3; ++i) {
        if (faces_a[i] > face_a.separation) face_a = {faces_a[i], i};
        if (faces_b[i] > face_b.separation) face_b = {faces_b[i], i};
    }
    // Edge axes e_i x r_j, the three of an i in lanes (lane j; the fourth left out). The
    // cross product's i-th coordinate is zero, and the products with it add nothing: each
    // sum below is the same two terms, in the same order, that the whole vectors' dot
    // products add (the bits are those of Vec3::cross and dot).
    // Where B's axes are A's (r the identity, up to the signs of its zeros: boxes square to
    // each other, as every pair of a pile is before anything turns), axis e_i x e_j is A's face
    // axis k and its separation is faces_a[k] to the bit (each sum adds only zeros to it): no
    // edge is past the speculative distance nor clearly deeper than a face, so none is asked.
    const bool square = r(0, 0) == 1 && r(1, 1) == 1 && r(2, 2) == 1 && r(0, 1) == 0 && r(0, 2) == 0 && r(1, 0) == 0 &&
                        r(1, 2) == 0 && r(2, 0) == 0 && r(2, 1) == 0;
    for (int i = 0; i < 3 && !square; ++i) {
        const int p = i == 0 ? 1 : 0, q = i == 2 ? 1 : 2;  // the other two coordinates, ascending
        // (e_i x c)[p], [q]: (-c2, c1), (c2, -c0), (-c1, c0) for i = 0, 1, 2.
        const Lanes ap = i == 1 ? rows[2] : -rows[i == 0 ? 2 : 1];
        const Lanes aq = i == 1 ? -rows[0] : rows[i == 0 ? 1 : 0];
        const Lanes length = lane_sqrt(ap * ap + aq * aq);
        const Lanes ra = ha[p] * lane_abs(ap) + ha[q] * lane_abs(aq);
        // |r' axis|, B's three axes.
        const Lanes on_b0 = lane_abs(r(p, 0) * ap + r(q, 0) * aq);
        const Lanes on_b1 = lane_abs(r(p, 1) * ap + r(q, 1) * aq);
        const Lanes on_b2 = lane_abs(r(p, 2) * ap + r(q, 2) * aq);
        const Lanes rb = hb[0] * on_b0 + (hb[1] * on_b1 + hb[2] * on_b2);
        const Lanes s = (lane_abs(ap * t[p] + aq * t[q]) - ra - rb) / length;
        // Parallel edges: the face axes cover them (and `& 7u` leaves the fourth lane out).
        const unsigned axes = lane_bits(!(length < Real(1e-6))) & 7u;
        if ((lane_bits(s > speculative) & axes) != 0) return 0;
        for (int j = 0; j < 3; ++j) {
            if ((axes >> j & 1u) != 0 && s[j] > edge.separation) edge = {s[j], 3 * i + j};
        }
    }

    Manifold& m = out[0];
    if (edge.index >= 0 && clearly_greater(edge.separation, std::max(face_a.separation, face_b.separation))) {
        const int i = edge.index / 3, j = edge.index % 3;
        Vec3 axis = Vec3::Unit(i).cross(r.col(j)).normalized();
        if (axis.dot(t) < 0) axis = -axis;
        // The edge of A farthest along the axis and the edge of B farthest against it.
        Vec3 pa = Vec3::Zero(), qb = Vec3::Zero();
        std::uint32_t edge_a = 4 * i, edge_b = 4 * j, bit = 1;
        for (int k = 0; k < 3; ++k) {
            if (k == i) continue;
            pa[k] = axis[k] < 0 ? -ha[k] : ha[k];
            edge_a |= axis[k] < 0 ? 0 : bit;
            bit <<= 1;
        }
        const Vec3 axis_b = r.transpose() * axis;
        bit = 1;
        for (int k = 0; k < 3; ++k) {
            if (k == j) continue;
            qb[k] = axis_b[k] > 0 ? -hb[k] : hb[k];
            edge_b |= axis_b[k] > 0 ? 0 : bit;
            bit <<= 1;
        }
        const Vec3 a0 = pa - Vec3::Unit(i) * ha[i], da = Vec3::Unit(i) * (2 * ha[i]);
        const Vec3 b0 = r * (qb - Vec3::Unit(j) * hb[j]) + t, db = r.col(j) * (2 * hb[j]);
        Real s = 0, u = 0;
        closest_segment_parameters(a0, da, b0, db, s, u);
        const Vec3 on_a = a0 + s * da, on_b = b0 + u * db;
        const Real separation = axis.dot(on_b - on_a);
        m.normal = axis;
        m.points[0] = {Real(0.5) * (on_a + on_b), separation, edge_contact_id(edge_a, edge_b)};
        m.point_count = 1;
        manifold_to_world(m, xa);
        return 1;
    }

    ContactCandidate candidates[8];  // a quad clipped by four planes
    int count = 0;
    const bool on_b = clearly_greater(face_b.separation, face_a.separation);
    if (on_b) {
        // Reference face on B: clip in B's frame, then bring the points back to A's.
        const Mat3 rt = r.transpose();
        Vec3 normal_b;
        count = box_face_contact(hb, ha, rt, -(rt * t), face_b.index, speculative, true, square, normal_b, candidates);
        for (int k = 0; k < count; ++k) candidates[k].point = r * candidates[k].point + t;
        m.normal = -(r * normal_b);
    } else {
        count = box_face_contact(ha, hb, r, t, face_a.index, speculative, false, square, m.normal, candidates);
    }
    if (count == 0) return 0;
    // (Square boxes meet in no wedge: B's face normal is one of A's, parallel or at right angles.)
    if (!square) wedge_normal(ha, hb, r, t, face_a, face_b, on_b, m.normal, candidates, count);
    if (count <= kMaxManifoldPoints) {
        candidates_to_world(candidates, count, m, xa);
    } else {
        reduce_to_manifold(candidates, count, m);
        manifold_to_world(m, xa);
    }
    return 1;
}

}  // namespace spindle::detail
