// Narrowphase stage: new manifolds for every awake contact, as parallel jobs; each
// new point takes the impulses of the old point with the same feature id, so the
// solver warm starts. A pair whose relative pose has barely changed since its manifolds
// were computed keeps them, moved with the bodies (Jolt's body pair cache): a resting
// pile skips almost all of its collision tests.
#include <cmath>

#include "stages/stages.hpp"

namespace spindle {
namespace {

constexpr int kMaxManifolds = 4;
static_assert(kMaxManifolds <= 4, "contact_summary (world.hpp) packs the point counts of at most 4 manifolds");

// Within this distance an old point stands for a new one whose feature id changed.
constexpr Real kCarryDistance = 0.02;

// Old and new manifolds whose normals are closer than this (cosine) are the same face;
// below it, a different face of a mesh.
constexpr Real kSameFace = 0.9;

// A contact keeps its manifolds while B's pose in A's frame stays within 0.2 mm and half
// a degree (|cos| of half the angle between the rotations) of the pose they were computed
// at. Jolt's 1 mm and 2 degrees let a 20-cube stack at 4 substeps drift 5 cm.
constexpr Real kCacheDistance = 0.0002;
constexpr Real kCacheCosHalfAngle = 0.99999048;  // cos(0.25 degrees)

bool cache_holds(const Contact& contact, const Vec3& position, const Quat& rotation) {
    return contact.cached && (position - contact.cached_position).squaredNorm() < kCacheDistance * kCacheDistance &&
           std::abs(rotation.dot(contact.cached_rotation)) > kCacheCosHalfAngle;
}

// Moves the cached manifolds with the bodies: surface points and normal from the body
// frames they were kept in, separation between them, the point midway.
void follow_bodies(Contact& contact, const Transform& ta, const Transform& tb) {
    for (int m = 0; m < contact.manifold_count; ++m) {
        ContactManifold& manifold = contact.manifold_at(m);
        manifold.normal = ta.q * manifold.local_normal;
        for (int j = 0; j < manifold.point_count; ++j) {
            ContactPoint& p = manifold.points[j];
            const Vec3 on_a = ta.apply(p.local_a);
            const Vec3 on_b = tb.apply(p.local_b);
            p.geometry.separation = manifold.normal.dot(on_b - on_a);
            p.geometry.point = Real(0.5) * (on_a + on_b);
        }
    }
}

// Keeps what follow_bodies needs: each point's two surface points and the normal in the
// body frames, and the pose they were computed at.
void remember(Contact& contact, const Transform& ta, const Transform& tb, const Vec3& position, const Quat& rotation) {
    for (int m = 0; m < contact.manifold_count; ++m) {
        ContactManifold& manifold = contact.manifold_at(m);
        manifold.local_normal = ta.q.conjugate() * manifold.normal;
        for (int j = 0; j < manifold.point_count; ++j) {
            ContactPoint& p = manifold.points[j];
            const Vec3 half = Real(0.5) * p.geometry.separation * manifold.normal;
            p.local_a = ta.apply_inverse(p.geometry.point - half);
            p.local_b = tb.apply_inverse(p.geometry.point + half);
        }
    }
    contact.cached = true;
    contact.cached_position = position;
    contact.cached_rotation = rotation;
}

// Each new point takes the normal impulse of the old point with the same feature id or,
// when the id changed (two faces aligned exactly flip between reference features from
// step to step), of the nearest old point within kCarryDistance: losing the warm start
// there makes a tall stack jitter and walk. The manifold takes the friction and twist
// impulses of the old manifold facing the same way.
void carry_impulses(const Contact& old_contact, ContactManifold& fresh) {
    const ContactManifold* facing = nullptr;
    Real best_alignment = kSameFace;
    for (int m = 0; m < old_contact.manifold_count; ++m) {
        const ContactManifold& old = old_contact.manifold_at(m);
        const Real alignment = old.normal.dot(fresh.normal);
        if (alignment > best_alignment) best_alignment = alignment, facing = &old;
    }
    if (facing) {
        fresh.friction_impulse = facing->friction_impulse - facing->friction_impulse.dot(fresh.normal) * fresh.normal;
        fresh.twist_impulse = facing->twist_impulse;
    }
    for (int j = 0; j < fresh.point_count; ++j) {
        ContactPoint& p = fresh.points[j];
        const ContactPoint* match = nullptr;
        Real nearest = kCarryDistance * kCarryDistance;
        for (int m = 0; m < old_contact.manifold_count && !(match && match->geometry.id == p.geometry.id); ++m) {
            const ContactManifold& old = old_contact.manifold_at(m);
            if (old.normal.dot(fresh.normal) < kSameFace) continue;
            for (int k = 0; k < old.point_count; ++k) {
                const ContactPoint& o = old.points[k];
                if (o.geometry.id == p.geometry.id) {
                    match = &o;
                    break;
                }
                const Real d2 = (o.geometry.point - p.geometry.point).squaredNorm();
                if (d2 < nearest) {
                    nearest = d2;
                    match = &o;
                }
            }
        }
        if (match) p.normal_impulse = match->normal_impulse;
    }
}

}  // namespace

void update_narrowphase(World& world) {
    const Bodies& b = world.bodies;
    const SolverSettings& settings = world.settings.solver;
    const Real dt = world.settings.time_step.duration;
    const std::vector<std::uint32_t>& awake = awake_contacts(world);
    const auto count = static_cast<std::uint32_t>(awake.size());
    // Counted per worker while the contacts are at hand (a sum: it does not matter who
    // counted which), not in a second pass over every contact.
    world.contact_counts.assign(world.jobs->worker_count(), ContactCounts{});
    // A parallel_for, not a run_phases phase: a mesh or hull pair costs a thousand times
    // a resting box pair, and parallel_for splits the busy worker's range on demand,
    // where a phase's first block (half a share) could hold all the expensive pairs.
    world.jobs->parallel_for("Narrowphase", 0, count, 16, [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
        Manifold found[kMaxManifolds];
        ContactCounts& counts = world.contact_counts[worker];
        for (std::uint32_t k = lo; k < hi; ++k) {
            Contact& contact = world.contacts[awake[k]];
            const std::uint32_t a = contact.body_a, bb = contact.body_b;
            const Transform ta = b.transform(a), tb = b.transform(bb);
            const Vec3 position = ta.apply_inverse(tb.p);
            const Quat rotation = ta.q.conjugate() * tb.q;
            if (cache_holds(contact, position, rotation)) {
                follow_bodies(contact, ta, tb);
                counts.reused += 1;
                counts.touching += contact.manifold_count > 0 ? 1u : 0u;
                continue;
            }
            // Speculative contacts reach as far as the bodies can close in one step.
            const Real closing = (b.v[bb] - b.v[a]).norm() * dt;
            const Real speculative = settings.speculative_distance + closing;
            const int n = collide(b.desc[a].shape, ta, b.desc[bb].shape, tb, speculative, found, kMaxManifolds);
            ContactManifold fresh[kMaxManifolds];
            for (int m = 0; m < n; ++m) {
                fresh[m].normal = found[m].normal;
                fresh[m].point_count = found[m].point_count;
                for (int j = 0; j < found[m].point_count; ++j) fresh[m].points[j].geometry = found[m].points[j];
                carry_impulses(contact, fresh[m]);
            }
            contact.manifold_count = n;
            if (n > 0) contact.manifold = fresh[0];
            if (n > 1) contact.extra.assign(fresh + 1, fresh + n);
            remember(contact, ta, tb, position, rotation);
            // New manifolds, new summary (a cached pair, above, keeps both).
            world.contact_summaries[awake[k]] = contact_summary(contact);
            counts.touching += n > 0 ? 1u : 0u;
        }
    });
    std::uint32_t touching = 0, reused = 0;
    for (const ContactCounts& c : world.contact_counts) {
        touching += c.touching;
        reused += c.reused;
    }
    world.stats.contacts = touching;
    world.counters.contacts_updated += count;
    world.counters.manifolds_reused += reused;
}

}  // namespace spindle
