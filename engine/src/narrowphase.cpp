// Narrowphase stage: new manifolds for every awake contact, as parallel jobs; each
// new point takes the impulses of the old point with the same feature id, so the
// solver warm starts.
#include <cmath>

#include "stages.hpp"

namespace spindle {
namespace {

constexpr int kMaxManifolds = 4;

// Within this distance an old point stands for a new one whose feature id changed.
constexpr Real kCarryDistance = 0.02;

// Each new point takes the impulses of the old point with the same feature id or, when
// the id changed (two faces aligned exactly flip between reference features from step
// to step), of the nearest old point within kCarryDistance: losing the warm start there
// makes a tall stack jitter and walk.
void carry_impulses(const Contact& old_contact, ContactManifold& fresh) {
    for (int j = 0; j < fresh.point_count; ++j) {
        ContactPoint& p = fresh.points[j];
        const ContactPoint* match = nullptr;
        Real nearest = kCarryDistance * kCarryDistance;
        for (int m = 0; m < old_contact.manifold_count && !(match && match->geometry.id == p.geometry.id); ++m) {
            const ContactManifold& old = old_contact.manifold_at(m);
            if (old.normal.dot(fresh.normal) < 0.9) continue;  // a different face of a mesh
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
        if (!match) continue;
        p.normal_impulse = match->normal_impulse;
        p.tangent_impulse[0] = match->tangent_impulse[0];
        p.tangent_impulse[1] = match->tangent_impulse[1];
    }
}

}  // namespace

void update_narrowphase(World& world) {
    const Bodies& b = world.bodies;
    const SolverSettings& settings = world.settings.solver;
    const Real dt = world.settings.time_step.duration;
    const std::vector<std::uint32_t>& awake = awake_contacts(world);
    const auto count = static_cast<std::uint32_t>(awake.size());
    world.jobs->parallel_for("Narrowphase", 0, count, 16, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        Manifold found[kMaxManifolds];
        for (std::uint32_t k = lo; k < hi; ++k) {
            Contact& contact = world.contacts[awake[k]];
            const std::uint32_t a = contact.body_a, bb = contact.body_b;
            // Speculative contacts reach as far as the bodies can close in one step.
            const Real closing = (b.v[bb] - b.v[a]).norm() * dt;
            const Real speculative = settings.speculative_distance + closing;
            const int n = collide(b.desc[a].shape, b.transform(a), b.desc[bb].shape, b.transform(bb), speculative,
                                  found, kMaxManifolds);
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
        }
    });
    std::uint32_t touching = 0;
    for (std::uint32_t c : awake) touching += world.contacts[c].manifold_count > 0 ? 1u : 0u;
    world.stats.contacts = touching;
    world.counters.contacts_updated += count;
}

}  // namespace spindle
