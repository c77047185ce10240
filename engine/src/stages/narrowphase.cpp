// Narrowphase stage: new manifolds for every awake contact, as parallel jobs; each
// new point takes the impulses of the old point with the same feature id, so the
// solver warm starts. A pair whose relative pose has changed little since its manifolds
// were computed recycles them (Box3D's contact recycling): their points stay anchored to
// the bodies, which skips almost every collision test of a resting pile and, more, holds
// each resting contact where it was made. A column of boxes on soft contacts with fresh
// manifolds every step buckles (the support under a box follows the overlap as the box
// shifts); with recycled ones it stands, as it does in Box3D. A compound against a mesh that
// is collided again recycles part by part (collide_compound.cpp), as Box3D recycles each
// shape's contact: a part lying still keeps its manifolds while another part swings.
#include <algorithm>
#include <cmath>
#include <iterator>

#include "collision/compound.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

constexpr int kMaxManifolds = kMaxContactManifolds;

// Within this distance an old point stands for a new one whose feature id changed.
constexpr Real kCarryDistance = 0.02;

// Old and new manifolds whose normals are closer than this (cosine) are the same face;
// below it, a different face of a mesh.
constexpr Real kSameFace = 0.9;

// Contact recycling (Box3D's): a pair keeps its manifolds while B's centre has moved less
// than the recycle distance in A's frame, counting the reach of the relative turn (a body's
// extent times the angle), and neither body has turned more than 10 degrees (the normal
// stays fixed in the world). As Box3D's, the recycle distance is 10 linear slops (5 cm at
// the default slop) for a pair with manifolds and, for one without, never more than the
// speculative distance: a feature that was beyond the speculative distance when collided
// cannot have come into touch. A touching pair has its features within reach and its
// solver holding them (Box3D's touching pairs move 6 slops past its speculative distance,
// here 2). A compound's part against a mesh recycles only with manifolds: its distance is
// the touching one. (At 2 cm a 50-cube column leant and fell.)
constexpr Real kRecycleSlops = 10;

// How far a point of the body can be from its centre of mass (0 for a static body: only
// the other body's turn moves the contact): the length of its reach along its own axes
// (Box3D's maxExtent), the same however the body lies. (Its world bounds' corner, used
// before, reached up to 3 half sizes for a tilted cube where its corners reach 1.73.)
Real reach(const Bodies& b, std::uint32_t i) { return b.extents[i].reach_length; }

// |v x r| over the points r of body i, v its turn since it was at `then` (sin(angle / 2)
// times the axis), bounded axis by axis by its reach along its own axes (Box3D's modified
// cross, in the body's frame as Box3D's): a long body turning about its long axis swings its
// points by its girth, not its length, however it lies across the world's axes. Out of line:
// the recycling test's common path stays small.
[[gnu::noinline]] Real swing_bound(const Bodies& b, std::uint32_t i, const Quat& then) {
    const Vec3 turn = (then.conjugate() * b.q[i]).vec();  // in the body's frame
    return modified_cross(turn.cwiseAbs(), b.extents[i].reach).norm();
}

// Tight bounds further apart than the speculative reach by more than this rule a pair out:
// a guard against the rounding of the bounds and of the pair test's distance.
constexpr Real kReachGuard = 1e-6;

// Whether contact c, which has no manifold, is still out of reach: its bodies' tight
// bounds (this step's) are further apart along an axis than the speculative reach (the
// speculative distance and the step's closing, as the pair test keeps points within). The
// shapes are at least that far apart, whatever they are. Reads the packed key and the
// bodies' bounds, not the contact record: a tumbling pile keeps a contact for every pair
// whose fat boxes touch, most of them never near, and reading their records was most of
// the narrowphase.
bool out_of_reach(const World& world, std::uint32_t c, Real speculative_distance, Real dt) {
    const Bodies& b = world.bodies;
    const std::uint64_t key = world.contact_keys[c];
    const auto a = static_cast<std::uint32_t>(key >> 32);
    const auto bb = static_cast<std::uint32_t>(key & 0xffffffffu);
    const Aabb& box_a = b.bounds[a];
    const Aabb& box_b = b.bounds[bb];
    const Real gap = (box_b.min - box_a.max).cwiseMax(box_a.min - box_b.max).maxCoeff();
    if (!(gap > speculative_distance + kReachGuard)) return false;  // cheap before the closing speed
    const Real reach = speculative_distance + (b.v[bb] - b.v[a]).norm() * dt + kReachGuard;
    return gap > reach;
}

// How each body has turned since the manifolds were collided.
struct Turns {
    Quat dqa, dqb;
};

// Whether the contact's manifolds can be recycled, within `touching` if it has manifolds,
// else within `apart`; its bodies' turns in `turns` if so. The cheap checks first: the
// reach of both bodies only for a pair that passes them.
bool recycles(const Contact& contact, const Bodies& b, Real touching, Real apart, Turns& turns) {
    if (!contact.cached) return false;
    const Real tolerance = contact.manifold_count > 0 ? touching : apart;
    const std::uint32_t a = contact.body_a, bb = contact.body_b;
    const Real turn_a = b.q[a].dot(contact.cached_qa), turn_b = b.q[bb].dot(contact.cached_qb);
    if (std::min(turn_a * turn_a, turn_b * turn_b) <= kRecycleCosHalfAngleSq) return false;
    const Vec3 position = b.q[a].conjugate() * (b.x[bb] - b.x[a]);  // B's centre in A's frame
    const Real distance = (position - contact.cached_position()).norm();
    if (distance >= tolerance) return false;
    turns.dqa = b.q[a] * contact.cached_qa.conjugate();
    turns.dqb = b.q[bb] * contact.cached_qb.conjugate();
    // The relative turn dqa^-1 dqb (the same angle as the turn of B in A's frame):
    // 2 |sin(angle / 2)| ~ the angle, so this is how far a point at the reach has swung.
    const Vec3 turn = (turns.dqa.conjugate() * turns.dqb).vec();
    const Real reach_a = reach(b, a), reach_b = reach(b, bb);
    if (distance + 2 * turn.norm() * std::max(reach_a, reach_b) < tolerance) return true;
    // Against a static body the turn is the other body's own: its points swing no further
    // than its reach along each of its axes allows (asked only when the whole reach is too
    // far: most resting pairs pass above).
    if (reach_a != 0 && reach_b != 0) return false;
    const bool a_static = reach_a == 0;
    return distance + 2 * swing_bound(b, a_static ? bb : a, a_static ? contact.cached_qb : contact.cached_qa) <
           tolerance;
}

// Box3D's test above bounds how far any point has moved, up to 10 slops, not whether a point
// that no manifold holds can have come into touch. Against a mesh a compound's manifolds miss
// points: a rolling hexagonal prism part's next edge, past the speculative distance when
// collided, or a log's edge across a mesh's ridge whose middle point a manifold's reduction
// to four had left out (its ends kept), came down as the log turned within the budget and
// sank up to 2.2 cm before the next collide; the push-out then lifted the log. A point comes
// nearer the other shape than the manifold's points only as the body tilts against the
// normal; a slide, a fall or a spin about the normal moves every point alike. So where one
// shape is a mesh (whose ridges no manifold of another triangle sees) or a compound (whose
// parts may have no manifold among the pair's few), a turned body (may_tilt) keeps the
// manifolds only while its tilt against each one's normal has moved its points along it
// less than kRecycleTiltSlops slops (tilt_reach). Two convex shapes keep Box3D's test alone:
// asked whether a corner had come lower than the manifold's points (the other shape taken
// flat under them), a pyramid's boxes, each half on two below, tipped a corner over the gap
// as it settled and were collided again for nothing (39 % more narrowphase), and a ragdoll's
// capsules hanging over a bench's edge, collided again as they swung, slid it off the bench.
// A rolling ball's core is its centre, which no turn moves. Out of line: only mesh and
// compound pairs (Contact::meshy) ask.
[[gnu::noinline]] bool holds_its_features(const Contact& contact, const Bodies& b, const Turns& turns, Real tolerance) {
    if (contact.manifold_count == 0) return true;
    for (int side = 0; side < 2; ++side) {
        const std::uint32_t i = side ? contact.body_b : contact.body_a;
        const Vec3& core = b.extents[i].core_reach;  // zero for a static body
        const Quat& turn = side ? turns.dqb : turns.dqa;
        if (!may_tilt(turn, core, tolerance)) continue;
        const Quat& then = side ? contact.cached_qb : contact.cached_qa;
        for (int m = 0; m < contact.manifold_count; ++m) {
            if (tilt_reach(turn, then, core, contact.manifold_at(m).normal) >= tolerance) return false;
        }
    }
    return true;
}

// dq^-1 v, as Eigen's product makes it, inlined: Eigen's own call was left out of line in
// the narrowphase's loop, a call for every recycled manifold.
[[gnu::always_inline]] inline Vec3 turned_back(const Quat& dq, const Vec3& v) {
    const Vec3 u = -dq.vec();
    Vec3 uv = u.cross(v);
    uv += uv;
    return v + dq.w() * uv + u.cross(uv);
}

// A recycled manifold keeps its points, normal and impulses; each point's separation is
// the one it was collided with plus how far its anchors, each moved and turned with its
// body, have since come apart along the normal. Round parts keep their surface point on
// the normal as they turn (as in the solver's substeps), so a rolling ball does not sink.
void recycle(Contact& contact, const Bodies& b, const Turns& turns) {
    const Quat& dqa = turns.dqa;
    const Quat& dqb = turns.dqb;
    const Vec3 moved = b.x[contact.body_b] - b.x[contact.body_a];
    for (int m = 0; m < contact.manifold_count; ++m) {
        ContactManifold& manifold = contact.manifold_at(m);
        const Vec3& n = manifold.normal;
        // n.(dq r) = (dq^-1 n).r: each rotation applied once per manifold.
        const Vec3 na = turned_back(dqa, n), nb = turned_back(dqb, n);
        const Real base = n.dot(moved) + manifold.radius_a * (na.dot(n) - 1) + manifold.radius_b * (nb.dot(n) - 1);
        for (int j = 0; j < manifold.point_count; ++j) {
            ContactPoint& p = manifold.points[j];
            p.separation = p.base_separation + base + nb.dot(contact.anchor_b(p)) - na.dot(contact.anchor_a(p));
        }
    }
}

// The solver takes a manifold's points one after another (Gauss-Seidel): a point taken first
// keeps its push until the later ones make it separate. A log pivoting on an edge as its next
// face lands, with the edge taken first, keeps pushing there through the landing, which then
// takes less of the roll than an impact about the new edge does; which edge a collide lists
// first is its own affair (a mesh's merge lists the deepest first, a plane its face's vertices).
// So where one point lands while another rests, pivots or leaves, the points go fastest
// approaching first. Where the speeds differ by less than kApproachSpread (a resting stack's
// noise), or every point closes at more than half the fastest one's speed (one hard impact,
// where the deepest first holds a tumbling plate up better), the collide's order stays.
constexpr Real kApproachSpread = 0.1;  // m/s

// Out of line: inlined in the narrowphase's loop, it pushed the loop's own quaternion turns
// (recycling's) out of line, and every recycled pair paid for calls.
[[gnu::noinline]] void order_by_approach(Manifold& m, const PairMotion& motion) {
    if (m.point_count < 2) return;
    Real approach[kMaxManifoldPoints];  // along the normal, from a to b: negative closes
    Real fastest = kHuge, slowest = -kHuge;
    for (int j = 0; j < m.point_count; ++j) {
        const Vec3& p = m.points[j].point;
        const Vec3 va = motion.v_a + motion.w_a.cross(p - motion.centre_a);
        const Vec3 vb = motion.v_b + motion.w_b.cross(p - motion.centre_b);
        approach[j] = m.normal.dot(vb - va);
        fastest = std::min(fastest, approach[j]);
        slowest = std::max(slowest, approach[j]);
    }
    if (!(slowest - fastest > kApproachSpread) || !(slowest > Real(0.5) * fastest)) return;
    // Insertion sort of at most four: stable, so equal speeds keep the collide's order.
    for (int j = 1; j < m.point_count; ++j) {
        const ManifoldPoint point = m.points[j];
        const Real speed = approach[j];
        int k = j;
        for (; k > 0 && speed < approach[k - 1]; --k) {
            m.points[k] = m.points[k - 1];
            approach[k] = approach[k - 1];
        }
        m.points[k] = point;
        approach[k] = speed;
    }
}

// A collided manifold as the record keeps it: every field a new ContactManifold has, but
// no impulse yet (carry_impulses gives the old ones), and each point's separation kept as
// the one it was collided with (recycling measures from it). The points past the count
// are left as they were: nothing reads them.
void make_manifold(const Manifold& found, const Shape& shape_a, const Shape& shape_b, ContactManifold& made) {
    made.normal = found.normal;
    made.part_a = found.part_a;
    made.part_b = found.part_b;
    made.point_count = static_cast<std::uint8_t>(found.point_count);
    made.pushed_point = -1;
    made.pushed_speed = 0;
    made.twist_impulse = 0;
    made.support_scale = 1;
    std::fill(std::begin(made.rolling_impulse), std::end(made.rolling_impulse), 0.0f);
    made.radius_a = round_radius(part_shape(shape_a, found.part_a));
    made.radius_b = round_radius(part_shape(shape_b, found.part_b));
    for (int j = 0; j < found.point_count; ++j) {
        ContactPoint& p = made.points[j];
        p.point = found.points[j].point;
        p.separation = found.points[j].separation;
        p.base_separation = p.separation;
        p.normal_impulse = 0;
        p.id = found.points[j].id;
    }
    made.friction_impulse = Vec3::Zero();
}

// Keeps the poses the fresh manifolds were collided at: their points are anchored to the
// bodies from there.
void remember(Contact& contact, const Bodies& b) {
    const std::uint32_t a = contact.body_a, bb = contact.body_b;
    contact.cached = true;
    contact.cached_xa = b.x[a];  // both anchors meet at the point now
    contact.cached_xb = b.x[bb];
    contact.cached_qa = b.q[a];
    contact.cached_qb = b.q[bb];
}

// Each new point takes the normal impulse of the old point with the same feature id or,
// when the id changed (two faces aligned exactly flip between reference features from
// step to step), of the nearest old point within kCarryDistance: losing the warm start
// there makes a tall stack jitter and walk. The manifold takes the friction and twist
// impulses of the old manifold facing the same way. Only manifolds of the same part pair
// match: two legs of a compound table stand on the same face with the same feature ids.
bool same_parts(const ContactManifold& x, const ContactManifold& y) {
    return x.part_a == y.part_a && x.part_b == y.part_b;
}

void carry_impulses(const Contact& old_contact, ContactManifold& fresh) {
    const ContactManifold* facing = nullptr;
    Real best_alignment = kSameFace;
    for (int m = 0; m < old_contact.manifold_count; ++m) {
        const ContactManifold& old = old_contact.manifold_at(m);
        if (!same_parts(old, fresh)) continue;
        const Real alignment = old.normal.dot(fresh.normal);
        if (alignment > best_alignment) best_alignment = alignment, facing = &old;
    }
    if (facing) {
        fresh.friction_impulse = facing->friction_impulse - facing->friction_impulse.dot(fresh.normal) * fresh.normal;
        fresh.twist_impulse = facing->twist_impulse;
        fresh.support_scale = facing->support_scale;
        if (old_contact.rolling_resistance > 0) {
            std::copy(std::begin(facing->rolling_impulse), std::end(facing->rolling_impulse), fresh.rolling_impulse);
        }
    }
    for (int j = 0; j < fresh.point_count; ++j) {
        ContactPoint& p = fresh.points[j];
        const ContactPoint* match = nullptr;
        Real nearest = kCarryDistance * kCarryDistance;
        for (int m = 0; m < old_contact.manifold_count && !(match && match->id == p.id); ++m) {
            const ContactManifold& old = old_contact.manifold_at(m);
            if (!same_parts(old, fresh) || old.normal.dot(fresh.normal) < kSameFace) continue;
            for (int k = 0; k < old.point_count; ++k) {
                const ContactPoint& o = old.points[k];
                if (o.id == p.id) {
                    match = &o;
                    break;
                }
                const Real d2 = (o.point - p.point).squaredNorm();
                if (d2 < nearest) {
                    nearest = d2;
                    match = &o;
                }
            }
        }
        if (match) p.normal_impulse = match->normal_impulse;
    }
}

// What a compound's collide with a mesh did with its parts. Out of line: only those pairs
// count them, and the narrowphase's loop stays small.
[[gnu::noinline]] void count_parts(const MeshQueries& queries, ContactCounts& counts) {
    counts.parts_collided += queries.parts_collided;
    counts.parts_recycled += queries.parts_recycled;
}

// Where a worker's pairs are collided: the manifolds found and those made from them. One a
// thread, kept from range to range (a range is 16 pairs, most recycled or ruled out, and
// making the room, every field set, cost more than the ranges' own loop control). Nothing
// is read that the pair collided now did not write (make_manifold).
struct CollideRoom {
    Manifold found[kMaxManifolds];
    ContactManifold fresh[kMaxManifolds];
};

CollideRoom& collide_room() {
    thread_local CollideRoom room;
    return room;
}

}  // namespace

void update_narrowphase(World& world) {
    const Bodies& b = world.bodies;
    const SolverSettings& settings = world.settings.solver;
    const Real dt = world.settings.time_step.duration;
    const Real touching_recycle_distance = kRecycleSlops * settings.linear_slop;
    const Real recycle_distance = std::min(touching_recycle_distance, settings.speculative_distance);
    const Real tilt_tolerance = kRecycleTiltSlops * settings.linear_slop;
    const bool any_fast = world.fast_bodies > 0;
    const bool any_reporting = world.events->reporting > 0;
    const std::vector<std::uint32_t>& awake = awake_contacts(world);
    const auto count = static_cast<std::uint32_t>(awake.size());
    // Counted per worker while the contacts are at hand (a sum: it does not matter who
    // counted which), not in a second pass over every contact.
    world.contact_counts.assign(world.jobs->worker_count(), ContactCounts{});
    // Reporting contacts whose touch changed or that may push, per worker; none while no
    // contact reports events.
    std::vector<std::vector<std::uint32_t>>& event_candidates = world.events->found;
    if (world.events->reporting > 0) event_candidates.resize(world.jobs->worker_count());
    auto note_events = [&](Contact& contact, std::uint32_t position, unsigned worker, ContactCounts& counts) {
        if (contact.events == 0) return;
        counts.event_checks += 1;
        if (contact.manifold_count == 0) contact.pushed = false;  // apart: the next push is a new impact
        if (contact_event_candidate(contact)) event_candidates[worker].push_back(position);
    };
    // Collides the pair at position k again (recycling did not keep it), by `worker` with its
    // scratch: new manifolds, impulses carried, a new summary.
    auto collide_pair = [&](std::uint32_t k, Contact& contact, bool recyclable, unsigned worker, ContactCounts& counts,
                            Manifold* found, ContactManifold* fresh, TriangleFeatures& no_triangles) {
        const std::uint32_t a = contact.body_a, bb = contact.body_b;
        const Transform ta = b.transform(a), tb = b.transform(bb);
        // Speculative contacts reach as far as the bodies can close in one step.
        const Real closing = (b.v[bb] - b.v[a]).norm() * dt;
        const Real speculative = settings.speculative_distance + closing;
        const Shape& shape_a = b.traits[a].shape;
        const Shape& shape_b = b.traits[bb].shape;
        // A compound's part boxes, where the broadphase made them this step.
        const auto part_boxes = [&](const Shape& shape, std::uint32_t i) {
            return shape.type == ShapeType::Compound ? world.broadphase->part_boxes.made_in(i, world.steps)
                                                     : std::span<const Aabb>();
        };
        const PartBoxes boxes{part_boxes(shape_a, a), part_boxes(shape_b, bb)};
        // Only a mesh pair keeps triangle features; the others' record has no room for them.
        const bool mesh = shape_a.type == ShapeType::TriangleMesh || shape_b.type == ShapeType::TriangleMesh;
        TriangleFeatures& triangles = mesh ? contact.made_extra().triangle_features : no_triangles;
        MeshQueries* const queries = mesh ? &contact.made_extra().mesh_queries : nullptr;
        // A compound pair with more part manifolds than room keeps those deepest a step
        // ahead, not the deepest now: the parts about to land before those resting. Every
        // manifold's points are put in the order the solver takes them by the same motion.
        const bool compound = shape_a.type == ShapeType::Compound || shape_b.type == ShapeType::Compound;
        // Where neither body turns, every point approaches at the relative velocity: no spread,
        // the collide's order stays, and neither the motion nor the speeds are worked out (every
        // pair of a first step from rest, where gravity has given speed and no turn).
        const bool turning = !(b.w[a] == Vec3::Zero() && b.w[bb] == Vec3::Zero());
        PairMotion motion;
        if (compound || turning) motion = {b.x[a], b.v[a], b.w[a], b.x[bb], b.v[bb], b.w[bb], dt};
        const int n = collide_cached(shape_a, ta, shape_b, tb, speculative, found, kMaxManifolds, contact.feature,
                                     triangles, settings.linear_slop, boxes, compound ? &motion : nullptr, queries,
                                     recyclable ? touching_recycle_distance : 0);
        if (compound && queries) count_parts(*queries, counts);
        for (int m = 0; m < n && turning; ++m) order_by_approach(found[m], motion);
        // A pair with no manifolds (every pair of a first step) has no impulses to carry:
        // its first manifold is made in the record itself, not in `fresh` and copied.
        const bool carries = contact.manifold_count > 0;
        for (int m = 0; m < n; ++m) {
            ContactManifold& made = carries || m > 0 ? fresh[m] : contact.manifold;
            make_manifold(found[m], shape_a, shape_b, made);
            if (carries) carry_impulses(contact, made);
        }
        if (n > 0 && carries) contact.manifold = fresh[0];
        contact.manifold_count = static_cast<std::uint8_t>(n);
        if (n > 1) contact.made_extra().manifolds.assign(fresh + 1, fresh + n);
        remember(contact, b);
        // New manifolds, new summary (a cached pair, above, keeps both).
        world.contact_summaries[awake[k]] = contact_summary(contact);
        counts.touching += n > 0 ? 1u : 0u;
        note_events(contact, awake[k], worker, counts);
    };
    // A mesh's or a compound's pair costs hundreds of times a box pair's, and such pairs sit
    // together in the contact list (a mesh is one body of each of its pairs): in chunks of
    // 16 they were one worker's alone while the other waited. With two workers or more the
    // first pass puts those it must collide aside, and a second collides them one to a
    // chunk. Each pair is collided alone: which pass or worker does it changes nothing.
    // A pair put aside keeps in its position's top bit whether it may recycle, as the first
    // pass found it: the second does not ask the bodies again (no space holds 2^31 contacts).
    constexpr std::uint32_t kRecyclableBit = 1u << 31;
    std::vector<std::vector<std::uint32_t>>& heavy = world.heavy_contacts;
    heavy.resize(world.jobs->worker_count());
    for (std::vector<std::uint32_t>& list : heavy) list.clear();
    std::vector<std::uint32_t>* const put_aside = world.jobs->worker_count() > 1 ? heavy.data() : nullptr;
    // A parallel_for, not a run_phases phase: a mesh or hull pair costs a thousand times
    // a resting box pair, and parallel_for splits the busy worker's range on demand,
    // where a phase's first block (half a share) could hold all the expensive pairs.
    world.jobs->parallel_for("Narrowphase", 0, count, 16, [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
        CollideRoom& room = collide_room();
        Manifold* const found = room.found;
        ContactManifold* const fresh = room.fresh;
        TriangleFeatures no_triangles;  // what a pair of no mesh is given (it only clears them)
        ContactCounts& counts = world.contact_counts[worker];
        for (std::uint32_t k = lo; k < hi; ++k) {
            // Only a pair without points is ruled out. The packed summary says so unless
            // some contact reports events (a sensor's manifolds have no summary): then the
            // record says, and the pair's events are noted as for any other (ruling out must
            // not depend on who listens).
            const bool apart = (world.contact_summaries[awake[k]] & kSummaryPointCounts) == 0;
            if (apart && out_of_reach(world, awake[k], settings.speculative_distance, dt) &&
                (!any_reporting || world.contacts[awake[k]].manifold_count == 0)) {
                counts.out_of_reach += 1;
                if (any_reporting) note_events(world.contacts[awake[k]], awake[k], worker, counts);
                continue;
            }
            Contact& contact = world.contacts[awake[k]];
            const std::uint32_t a = contact.body_a, bb = contact.body_b;
            // Not for a swept body: its contacts must see where it went. Asked only when
            // the space has one: is_fast reads the cold description.
            const bool recyclable = !any_fast || (!b.is_fast(a) && !b.is_fast(bb));
            Turns turns;
            if (recyclable && recycles(contact, b, touching_recycle_distance, recycle_distance, turns) &&
                (!contact.meshy || holds_its_features(contact, b, turns, tilt_tolerance))) {
                recycle(contact, b, turns);
                counts.reused += 1;
                counts.touching += contact.manifold_count > 0 ? 1u : 0u;
                note_events(contact, awake[k], worker, counts);
                continue;
            }
            if (put_aside != nullptr && contact.extra) {  // a mesh's or compound's: the second pass
                put_aside[worker].push_back(k | static_cast<std::uint32_t>(recyclable) * kRecyclableBit);
                continue;
            }
            collide_pair(k, contact, recyclable, worker, counts, found, fresh, no_triangles);
        }
    });
    std::vector<std::uint32_t>& positions = world.heavy_positions;
    positions.clear();
    for (const std::vector<std::uint32_t>& list : heavy) positions.insert(positions.end(), list.begin(), list.end());
    world.jobs->parallel_for("Narrowphase heavy", 0, static_cast<std::uint32_t>(positions.size()), 1,
                             [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
                                 CollideRoom& room = collide_room();
                                 TriangleFeatures no_triangles;
                                 ContactCounts& counts = world.contact_counts[worker];
                                 for (std::uint32_t i = lo; i < hi; ++i) {
                                     const std::uint32_t k = positions[i] & ~kRecyclableBit;
                                     Contact& contact = world.contacts[awake[k]];
                                     const bool recyclable = (positions[i] & kRecyclableBit) != 0;
                                     collide_pair(k, contact, recyclable, worker, counts, room.found, room.fresh,
                                                  no_triangles);
                                 }
                             });
    std::uint32_t touching = 0, reused = 0, ruled_out = 0;
    for (const ContactCounts& c : world.contact_counts) {
        touching += c.touching;
        reused += c.reused;
        ruled_out += c.out_of_reach;
        world.counters.contact_event_checks += c.event_checks;
        world.counters.mesh_parts_collided += c.parts_collided;
        world.counters.mesh_parts_recycled += c.parts_recycled;
    }
    note_touch_changes(world);  // Begin and End in contact order, whichever worker found them
    world.stats.contacts = touching;
    world.counters.contacts_updated += count;
    world.counters.manifolds_reused += reused;
    world.counters.contacts_out_of_reach += ruled_out;
}

}  // namespace spindle
