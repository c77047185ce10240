// Compounds in the narrowphase: each part whose bounds come within the speculative
// distance of the other shape (or its part) is collided through the pair table as if
// it were a body of its own, and its manifolds are labelled with the part indices.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "collision/clipping.hpp"
#include "collision/compound.hpp"
#include "collision/manifold_slots.hpp"
#include "collision/pair_functions.hpp"

namespace spindle::detail {
namespace {

// Manifolds kept while walking part pairs; past this one that ranks deeper (rank) replaces
// the one that ranks shallowest.
constexpr int kMaxGathered = 64;
constexpr int kPerPair = 4;               // a mesh may give several manifolds per part
constexpr std::size_t kInlineParts = 32;  // parts posed on the stack; more go to the heap
// Far above the relative rounding of a part's bounds computed two ways (about 1e-15).
constexpr Real kLooseRelative = 1e-9;

// How deep manifold m (normal from the compound pair's a to b) would be after a step at
// the bodies' velocities: the least over its points of the separation less what the
// points close along the normal in that time. Without motion, its depth now. A resting
// part keeps its depth; a part about to land ranks as deep as it would go.
Real rank(const Manifold& m, const PairMotion* motion) {
    if (!motion) return deepest(m);
    Real least = kHuge;
    for (int i = 0; i < m.point_count; ++i) {
        const Vec3& p = m.points[i].point;
        const Vec3 va = motion->v_a + motion->w_a.cross(p - motion->centre_a);
        const Vec3 vb = motion->v_b + motion->w_b.cross(p - motion->centre_b);
        least = std::min(least, m.points[i].separation + motion->dt * m.normal.dot(vb - va));
    }
    return least;
}

// How much farther than the pair's reach a part can close in one step. The narrowphase
// reaches as far as the bodies' centres of mass close, but a part far from its body's
// centre moves faster as the body turns: a tree tipped over comes down at its top several
// times faster than at its centre. With the centres' reach only the parts near the base
// came into reach as it landed; they alone were stopped, and the tree pivoted on them and
// bounced metres up. So each part reaches as far as the bodies close at its centre.
// (Box3D's speculative distance is a few slops; its continuous stage moves such a body
// back to where it first touched, and the next step meets every part.)
class PartReach {
public:
    explicit PartReach(const PairMotion* motion)
        : m_motion(motion && (motion->w_a.squaredNorm() > 0 || motion->w_b.squaredNorm() > 0) ? motion : nullptr),
          m_centres2(m_motion ? (motion->v_b - motion->v_a).squaredNorm() : 0) {}

    // The reach past the centres' of a part centred at c.
    Real operator()(const Vec3& c) const {
        if (!m_motion) return 0;
        const PairMotion& m = *m_motion;
        const Vec3 closing = m.v_b - m.v_a + m.w_b.cross(c - m.centre_b) - m.w_a.cross(c - m.centre_a);
        const Real closing2 = closing.squaredNorm();
        if (closing2 <= m_centres2) return 0;
        return (std::sqrt(closing2) - std::sqrt(m_centres2)) * m.dt;
    }

private:
    const PairMotion* m_motion;  // null: neither body turns
    Real m_centres2;             // the centres' closing speed, squared
};

struct Gathered {
    explicit Gathered(const PairMotion* m) : motion(m) {}
    ManifoldSlots<kMaxGathered> list;
    Real ranks[kMaxGathered];  // each manifold's rank, made once
    int count = 0;
    const PairMotion* motion;
};

void keep(Gathered& g, const Manifold& m) {
    const Real r = rank(m, g.motion);
    if (g.count < kMaxGathered) {
        g.ranks[g.count] = r;
        g.list.fill(static_cast<std::size_t>(g.count++), m);
        return;
    }
    int shallowest = 0;
    for (int i = 1; i < kMaxGathered; ++i) {
        if (g.ranks[i] > g.ranks[shallowest]) shallowest = i;
    }
    if (r >= g.ranks[shallowest]) return;
    // Out of its place, and m at the end: the list stays in the order of the walk.
    Manifold* const begin = g.list.data();
    std::move(begin + shallowest + 1, begin + kMaxGathered, begin + shallowest);
    std::move(g.ranks + shallowest + 1, g.ranks + kMaxGathered, g.ranks + shallowest);
    begin[kMaxGathered - 1] = m;
    g.ranks[kMaxGathered - 1] = r;
}

// Compound b's parts posed in the world, and their bounds: worked out once per pair, not
// once for every part of the other shape they are tested against. A part's exact bounds
// (its hull's vertices moved into the world) are what decide whether it meets the other
// shape, as they did when each pair was tested alone; its compound-frame box turned with
// the compound is a cheap superset that rules most parts out first. Exact bounds given
// (the broadphase's, made by the same expression) stand for both.
class PosedParts {
public:
    PosedParts(const Compound& parts, const Transform& x, std::span<const Aabb> given = {})
        : m_compound(parts),
          m_x(x),
          m_rotation(x.q.toRotationMatrix()),
          m_abs_rotation(m_rotation.cwiseAbs()),
          m_given(given.empty() ? nullptr : given.data()),
          m_poses(parts.size()),
          m_exact(m_given ? 0 : parts.size()),
          m_loose(m_given ? 0 : parts.size()),
          m_has_pose(parts.size()),
          m_has_exact(m_given ? 0 : parts.size()) {
        for (std::uint32_t i = 0; i < parts.size(); ++i) m_has_pose[i] = false;
        if (m_given) return;
        for (std::uint32_t i = 0; i < parts.size(); ++i) {
            m_loose[i] = turned(parts.part_bounds(i));
            m_has_exact[i] = false;
        }
    }

    std::uint32_t size() const { return m_compound.size(); }
    const Shape& shape(std::uint32_t i) const { return m_compound.shape(i); }

    // Part i's world pose and exact bounds, made the first time they are asked for.
    const Transform& pose(std::uint32_t i) {
        if (!m_has_pose[i]) {
            m_poses[i] = m_x * m_compound.pose(i);
            m_has_pose[i] = true;
        }
        return m_poses[i];
    }
    const Aabb& exact(std::uint32_t i) {
        if (m_given) return m_given[i];
        if (!m_has_exact[i]) {
            m_exact[i] = m_compound.shape(i).bounds(pose(i));
            m_has_exact[i] = true;
        }
        return m_exact[i];
    }
    // A box holding part i's exact bounds: its compound-frame bounds turned into the world,
    // widened by far more than the two computations' rounding can differ.
    const Aabb& loose(std::uint32_t i) { return m_given ? m_given[i] : m_loose[i]; }
    Aabb loose_all() const { return turned(m_compound.local_bounds()); }

private:
    Aabb turned(const Aabb& local) const {
        const Vec3 c = m_x.p + m_rotation * local.center();
        const Vec3 e = m_abs_rotation * local.extents();
        const Real pad = kLooseRelative * (c.cwiseAbs().maxCoeff() + e.maxCoeff());
        return Aabb::from_center_extents(c, e.array() + pad);
    }

    const Compound& m_compound;
    Transform m_x;
    Mat3 m_rotation;
    Mat3 m_abs_rotation;  // turns each part's extents: made once, not once a part
    const Aabb* m_given;  // each part's exact bounds, or null
    ScratchBuffer<Transform, kInlineParts> m_poses;
    ScratchBuffer<Aabb, kInlineParts> m_exact;
    ScratchBuffer<Aabb, kInlineParts> m_loose;
    ScratchBuffer<std::uint8_t, kInlineParts> m_has_pose;
    ScratchBuffer<std::uint8_t, kInlineParts> m_has_exact;
};

// Each part's reach past the centres' (PartReach) at its centre, into out[i]; returns
// the largest.
Real part_reaches(const PartReach& reach, PosedParts& parts, Real* out) {
    Real most = 0;
    for (std::uint32_t i = 0; i < parts.size(); ++i) {
        out[i] = reach(parts.loose(i).center());
        most = std::max(most, out[i]);
    }
    return most;
}

// The parts of b whose loose boxes overlap `box`, in part order; returns their count.
std::uint32_t parts_near(PosedParts& b, const Aabb& box, std::uint32_t* out) {
    std::uint32_t n = 0;
    for (std::uint32_t i = 0; i < b.size(); ++i) {
        if (box.overlaps(b.loose(i))) out[n++] = i;
    }
    return n;
}

// Shape a (part `part_a` of its body, 0 if it is whole) against each of compound b's
// parts listed in `near` (in part order) that comes near it; a_box is a's exact bounds
// fattened by the speculative distance, and `near` must hold every part whose loose box
// it overlaps, a_box widened by `wider(i)`. `pair(i, found, extra)` collides a with part i
// as collide() does, reaching `extra` farther than the speculative distance.
template <class WiderFn, class PairFn>
void collide_parts(std::uint32_t part_a, const Aabb& a_box, PosedParts& b, std::span<const std::uint32_t> near,
                   Gathered& g, WiderFn&& wider, PairFn&& pair) {
    Manifold found[kPerPair];
    for (const std::uint32_t i : near) {
        const Real extra = wider(i);
        const Aabb box = extra > 0 ? a_box.fattened(extra) : a_box;
        if (!box.overlaps(b.loose(i)) || !box.overlaps(b.exact(i))) continue;
        const int n = pair(i, found, extra);
        for (int m = 0; m < n; ++m) {
            found[m].part_a = part_a;
            found[m].part_b = i;
            keep(g, found[m]);
        }
    }
}

// The `capacity` manifolds kept of more: half of them those that rank deepest, then one at
// a time the one farthest from every manifold kept (the deepest first where as far), so
// that what is kept spans the support. The deepest alone lie where the body sinks most: a
// flat slab of 16 balls on the ground was held on its lower side only, tipped, and then
// held on the other, for ever. In part-pair order (the order of the walk), so the order
// does not depend on which were kept.
int emit(Gathered& g, Manifold* out, int capacity) {
    const Manifold* begin = g.list.data();
    if (g.count <= capacity) {
        std::copy(begin, begin + g.count, out);
        return g.count;
    }
    std::array<int, kMaxGathered> order;
    for (int i = 0; i < g.count; ++i) order[static_cast<std::size_t>(i)] = i;
    std::stable_sort(order.begin(), order.begin() + g.count, [&](int x, int y) { return g.ranks[x] < g.ranks[y]; });
    // Each manifold's centre (the mean of its points), and its squared distance to the
    // nearest kept one (-1: no point to place it by).
    std::array<Vec3, kMaxGathered> centres;
    std::array<Real, kMaxGathered> nearest;
    for (int i = 0; i < g.count; ++i) {
        const Manifold& m = g.list[static_cast<std::size_t>(i)];
        Vec3 c = Vec3::Zero();
        for (int j = 0; j < m.point_count; ++j) c += m.points[j].point;
        centres[static_cast<std::size_t>(i)] = m.point_count > 0 ? Vec3(c / m.point_count) : c;
        nearest[static_cast<std::size_t>(i)] = m.point_count > 0 ? kHuge : -1;
    }
    // order[0, slot) is kept; order[slot, count) the rest, still by rank.
    const int deepest = std::max(1, capacity / 2);
    for (int slot = 0; slot < capacity; ++slot) {
        int pick = slot;  // the deepest of the rest, or the farthest from those kept
        if (slot >= deepest) {
            for (int r = slot + 1; r < g.count; ++r) {
                if (nearest[static_cast<std::size_t>(order[static_cast<std::size_t>(r)])] >
                    nearest[static_cast<std::size_t>(order[static_cast<std::size_t>(pick)])])
                    pick = r;
            }
        }
        std::rotate(order.begin() + slot, order.begin() + pick, order.begin() + pick + 1);
        const auto kept = static_cast<std::size_t>(order[static_cast<std::size_t>(slot)]);
        if (nearest[kept] < 0) continue;
        for (int r = slot + 1; r < g.count; ++r) {
            const auto k = static_cast<std::size_t>(order[static_cast<std::size_t>(r)]);
            if (nearest[k] >= 0) nearest[k] = std::min(nearest[k], (centres[k] - centres[kept]).squaredNorm());
        }
    }
    std::sort(order.begin(), order.begin() + capacity);
    for (int i = 0; i < capacity; ++i) out[i] = g.list[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
    return capacity;
}

// Shape a against each of compound b's parts near it, through `pair(part, pose, exact
// bounds, i, found, reach)` (as collide_parts, `reach` the part's speculative distance);
// with more than `capacity` manifolds, those ranking deepest.
template <class PairFn>
int collide_shape_parts(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                        std::span<const Aabb> b_boxes, Real speculative, Manifold* out, int capacity,
                        const PairMotion* motion, PairFn&& pair) {
    Gathered g(motion);
    const Aabb a_box = a.bounds(xa).fattened(std::max(speculative, Real(0)));
    PosedParts parts(*b.parts, xb, b_boxes);
    const PartReach reach(motion);
    ScratchBuffer<Real, kInlineParts> extra(parts.size());
    const Real most = part_reaches(reach, parts, extra.data());
    ScratchBuffer<std::uint32_t, kInlineParts> near(parts.size());
    const std::uint32_t count = parts_near(parts, most > 0 ? a_box.fattened(most) : a_box, near.data());
    collide_parts(
        0, a_box, parts, {near.data(), count}, g, [&](std::uint32_t i) { return extra[i]; },
        [&](std::uint32_t i, Manifold* found, Real more) {
            return pair(parts.shape(i), parts.pose(i), parts.exact(i), i, found, speculative + more);
        });
    return emit(g, out, capacity);
}

// Whether a compound's part, collided with a mesh where `was` says, has since moved so little
// that its manifolds then still serve (contact recycling, narrowphase.cpp, for one part): its
// centre has moved less than `tolerance`, less the swing of its points about it (the body's
// turn since, in the body's frame, over the part's half-extents there), the body has turned
// less than 10 degrees, and its tilt against each manifold's normal has moved the part's
// core points along it less than `tilt_tolerance` (tilt_reach; as a whole contact's,
// holds_its_features in narrowphase.cpp: a rolling prism part's next edge must not come
// down unheld). The mesh has not moved (met_at).
bool part_recycles(const MeshQuery& was, std::span<const Manifold> kept, const Vec3& centre, const Quat& turn,
                   const Vec3& extents, Real radius, Real tolerance, Real tilt_tolerance) {
    if (!was.has_manifolds) return false;
    const Real distance = (centre - was.centre).norm();
    if (distance >= tolerance) return false;
    const Real cos_half = turn.dot(was.turn);
    if (cos_half * cos_half <= kRecycleCosHalfAngleSq) return false;
    // sin(angle / 2) times the axis, in the body's frame: twice its cross with a point's
    // offset from the centre is how far the point has swung.
    const Vec3 local = (was.turn.conjugate() * turn).vec().cwiseAbs();
    if (!(distance + 2 * modified_cross(local, extents).norm() < tolerance)) return false;
    const Vec3 core = (extents.array() - radius).cwiseMax(0);
    const Quat world_turn = turn * was.turn.conjugate();
    if (!may_tilt(world_turn, core, tilt_tolerance)) return true;
    for (const Manifold& m : kept) {
        if (tilt_reach(world_turn, was.turn, core, m.normal) >= tilt_tolerance) return false;
    }
    return true;
}

// A recycled part's manifold, as recycle() moves a contact's (narrowphase.cpp): each point
// stays where it was on the part (its offset from the part's centre kept in the world's axes,
// as a recycled contact keeps its anchors), and its separation grows by how far the part's
// point has come away from the mesh along the normal as the part moved and turned, a round
// part's surface point staying on the normal.
class PartMove {
public:
    PartMove(const MeshQuery& was, const Vec3& centre, const Quat& turn)
        : m_was(was.centre), m_moved(centre - was.centre), m_turn(turn * was.turn.conjugate()) {}

    Manifold moved(const Manifold& kept, Real radius) const {
        Manifold m = kept;
        const Vec3& n = m.normal;                  // from the mesh to the part
        const Vec3 back = m_turn.conjugate() * n;  // n.(turn r) = (turn^-1 n).r
        const Real base = n.dot(m_moved) + radius * (back.dot(n) - 1);
        for (int j = 0; j < m.point_count; ++j) {
            ManifoldPoint& p = m.points[j];
            const Vec3 offset = p.point - m_was;
            p.separation += base + back.dot(offset) - n.dot(offset);
            p.point += m_moved;
        }
        return m;
    }

private:
    Vec3 m_was, m_moved;
    Quat m_turn;  // the body's turn in the world since
};

}  // namespace

int collide_shape_compound(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                           Manifold* out, int capacity, const PartBoxes& boxes, const PairMotion* motion) {
    return collide_shape_parts(a, xa, b, xb, boxes.b, speculative, out, capacity, motion,
                               [&](const Shape& part, const Transform& x, const Aabb&, std::uint32_t, Manifold* found,
                                   Real reach) { return collide(a, xa, part, x, reach, found, kPerPair); });
}

int collide_mesh_compound_cached(const Shape& mesh, const Transform& xm, const Shape& b, const Transform& xb,
                                 Real speculative, Manifold* out, int capacity, TriangleFeatureWalk& walk,
                                 std::span<const Aabb> b_boxes, const PairMotion* motion, Real recycle_distance) {
    const bool recycling = walk.met_at(*mesh.mesh, xm) && recycle_distance > 0;
    const Real tilt_tolerance = kRecycleTiltSlops * walk.slop();
    const Compound& parts = *b.parts;
    return collide_shape_parts(
        mesh, xm, b, xb, b_boxes, speculative, out, capacity, motion,
        [&](const Shape& part, const Transform& x, const Aabb& box, std::uint32_t i, Manifold* found, Real reach) {
            const Vec3 centre = xb.apply(parts.part_bounds(i).center());
            const MeshQuery* const was = recycling ? walk.last(i) : nullptr;
            if (was && part_recycles(*was, walk.kept(*was), centre, xb.q, parts.part_bounds(i).extents(),
                                     round_radius(part), recycle_distance, tilt_tolerance)) {
                const PartMove move(*was, centre, xb.q);  // before carry() moves the record `was` is in
                const std::span<const Manifold> kept = walk.carry(i);
                for (std::size_t m = 0; m < kept.size(); ++m) found[m] = move.moved(kept[m], round_radius(part));
                return static_cast<int>(kept.size());
            }
            // The mesh's pair function has the part as A: turned round as collide() does.
            // The part's exact box, which the walk's cull has made or was given.
            const int n = collide_convex_mesh_cached(part, x, mesh, xm, reach, found, kPerPair, i, walk, &box);
            for (int m = 0; m < n; ++m) flip_manifold(found[m]);
            if (walk.keeps_queries()) walk.keep_manifolds(centre, xb.q, {found, static_cast<std::size_t>(n)});
            return n;
        });
}

int collide_compound_compound(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb,
                              Real speculative, Manifold* out, int capacity, const PartBoxes& boxes,
                              const PairMotion* motion) {
    Gathered g(motion);
    const Compound& parts = *a.parts;
    const Real margin = std::max(speculative, Real(0));
    PosedParts a_parts(parts, xa, boxes.a), b_parts(*b.parts, xb, boxes.b);
    // Each part's reach past the centres' (PartReach) at its centre; a pair of parts
    // reaches the farther of its two parts', which bounds it at any point between them.
    const PartReach reach(motion);
    ScratchBuffer<Real, kInlineParts> a_extra(a_parts.size()), b_extra(b_parts.size());
    const Real a_most = part_reaches(reach, a_parts, a_extra.data());
    const Real b_most = part_reaches(reach, b_parts, b_extra.data());
    const Aabb b_box = b_parts.loose_all();
    // Each of a's parts lies inside a's whole loose box (padded as each part's is), so a
    // part of b whose loose box misses that box, fattened as a part's box is, meets none of
    // them: it is left out once here instead of once for each of a's parts.
    ScratchBuffer<std::uint32_t, kInlineParts> near(b_parts.size());
    const std::uint32_t count = parts_near(b_parts, a_parts.loose_all().fattened(margin + std::max(a_most, b_most)),
                                           near.data());
    for (std::uint32_t j = 0; j < parts.size() && count > 0; ++j) {
        if (!a_parts.loose(j).fattened(margin + std::max(a_extra[j], b_most)).overlaps(b_box)) continue;
        const Aabb part_box = a_parts.exact(j).fattened(margin);
        const Shape& part = parts.shape(j);
        const Transform& pose = a_parts.pose(j);
        collide_parts(
            j, part_box, b_parts, {near.data(), count}, g,
            [&](std::uint32_t i) { return std::max(a_extra[j], b_extra[i]); },
            [&](std::uint32_t i, Manifold* found, Real more) {
                return collide(part, pose, b_parts.shape(i), b_parts.pose(i), speculative + more, found, kPerPair);
            });
    }
    return emit(g, out, capacity);
}

}  // namespace spindle::detail
