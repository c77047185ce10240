// Continuous stage: bodies flagged `fast` get a swept test against static geometry
// after the solver has moved them. Speculative contacts reach only as far as the
// linear closing speed, so a fast-spinning body's far end can sweep through a thin
// wall within one step; conservative advancement (translation plus angle times the
// farthest reach) finds the first time of impact and stops the body there.
#include <algorithm>

#include <spindle/platform/assert.hpp>

#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

constexpr int kMaxIterations = 32;

struct Sweep {
    Vec3 x0, x1;  // centre of mass
    Quat q0, q1;
    Vec3 local_com;
    Transform at(Real t) const {
        const Quat q = q0.slerp(t, q1);
        return {x0 + t * (x1 - x0) - q * local_com, q};
    }
};

// Smallest separation and its normal (from the body to the static) at a pose; false
// when the shapes are farther apart than `reach`.
bool distance(const Shape& body, const Transform& xb, const Shape& wall, const Transform& xw, Real reach, Real& d,
              Vec3& normal) {
    Manifold found[4];
    const int n = collide(body, xb, wall, xw, reach, found, 4);
    bool any = false;
    d = kHuge;
    for (int m = 0; m < n; ++m) {
        for (int j = 0; j < found[m].point_count; ++j) {
            if (found[m].points[j].separation < d) {
                d = found[m].points[j].separation;
                normal = found[m].normal;
                any = true;
            }
        }
    }
    return any;
}

// First time of impact in [0, 1) of the swept body against one static body, or 1.
Real time_of_impact(const Sweep& s, const Shape& shape, Real reach_radius, const Shape& wall, const Transform& xw,
                    Real target) {
    const Vec3 moved = s.x1 - s.x0;
    const Real turned = s.q0.angularDistance(s.q1);
    const Real reach = moved.norm() + turned * reach_radius + target;
    Real t = 0;
    for (int iter = 0; iter < kMaxIterations; ++iter) {
        Real d;
        Vec3 normal;
        if (!distance(shape, s.at(t), wall, xw, reach, d, normal)) return 1;  // never within reach
        if (d < target) return iter == 0 ? 1 : t;  // touching at the start: contacts handle it
        const Real bound = std::max(Real(0), moved.dot(normal)) + turned * reach_radius;
        if (bound < 1e-12) return 1;      // not closing in
        t += (d - 0.5 * target) / bound;  // the surfaces cannot meet before this
        if (t >= 1) return 1;
    }
    return t;
}

}  // namespace

void record_fast_starts(World& world) {
    world.fast_starts.clear();
    const Bodies& b = world.bodies;
    for (std::uint32_t i : world.awake) {
        if (b.is_fast(i) && !b.traits[i].sensor) world.fast_starts.push_back({i, b.x[i], b.q[i]});
    }
    SPINDLE_ASSERT(world.fast_starts.size() <= world.fast_bodies, "continuous: more fast bodies awake than counted");
}

void sweep_fast_bodies(World& world) {
    Bodies& b = world.bodies;
    BroadphaseState& bp = *world.broadphase;
    const Real target = world.settings.solver.linear_slop;
    std::vector<std::uint32_t>& candidates = world.scratch_candidates;
    for (const FastStart& start : world.fast_starts) {
        const std::uint32_t i = start.slot;
        const Sweep sweep{start.x0, b.x[i], start.q0, b.q[i], b.local_com[i]};
        const Shape& shape = b.traits[i].shape;
        const Aabb local = shape.bounds(Transform{});
        const Real reach_radius = std::max((local.min - b.local_com[i]).norm(), (local.max - b.local_com[i]).norm());
        const Aabb swept = shape.bounds(sweep.at(0)).merged(shape.bounds(sweep.at(1))).fattened(reach_radius);
        candidates.clear();
        bp.tree.query(swept, [&](ProxyId id) {
            // A static sensor stops nothing.
            if (id.is_static() && !b.traits[bp.tree.user(id)].sensor)
                candidates.push_back(static_cast<std::uint32_t>(bp.tree.user(id)));
            return true;
        });
        std::sort(candidates.begin(), candidates.end());  // the same order whatever the tree's shape
        Real first = 1;
        for (std::uint32_t wall : candidates) {
            first = std::min(first, time_of_impact(sweep, shape, reach_radius, b.traits[wall].shape, b.transform(wall),
                                                   target));
            world.counters.swept_tests += 1;
        }
        if (first >= 1) continue;
        // Stop at the impact pose; the velocity stays, and next step's contact (now
        // within reach) takes it out.
        const Transform pose = sweep.at(first);
        b.q[i] = pose.q;
        Vec3 x = pose.p + pose.q * b.local_com[i];
        // A locked coordinate is the same at both ends of the sweep: kept exactly, not
        // rebuilt from the pose with its rounding.
        for (int k = 0; k < 3; ++k) {
            if ((b.locks[i] & (1u << k)) != 0) x[k] = b.x[i][k];
        }
        b.x[i] = x;
    }
    // Used up: a step that records none (no fast body left) must not sweep these.
    world.fast_starts.clear();
}

}  // namespace spindle
