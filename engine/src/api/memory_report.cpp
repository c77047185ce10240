// The heap a Space holds, by structure (memory_report.hpp).
#include "api/memory_report.hpp"

#include "api/space_internals.hpp"
#include "query/query_scene.hpp"
#include "solver/constraints.hpp"
#include "stages/broadphase_state.hpp"

namespace spindle {
namespace {

template <typename T, typename A>
std::size_t held(const std::vector<T, A>& v) {
    return v.capacity() * sizeof(T);
}

std::size_t body_bytes(const Bodies& b) {
    std::size_t bytes = held(b.free_slots);
    Bodies::for_each_slot_array(b, [&bytes](const auto& array) { bytes += held(array); });
    return bytes;
}

std::size_t solver_other_bytes(const SolverScratch& s) {
    std::size_t bytes =
        held(s.bodies) + held(s.manifolds) + held(s.colored_manifolds) + held(s.overflow) + held(s.joints) +
        held(s.joint_refs) + held(s.colored_joints) + held(s.wide_joints) + held(s.wide_swing_twists) +
        held(s.wide_hinges) + held(s.joint_overflow) + held(s.body_colors) + held(s.support_scales) +
        held(s.support_edges) + held(s.support_first) + held(s.support_by_lower) + held(s.support_queue) +
        held(s.supported) + held(s.phases) + held(s.plan) + held(s.push_velocities) + held(s.warm_velocities) +
        held(s.gravity_scales) + held(s.rolling) + held(s.manifold_colors) + held(s.body_starts) + held(s.sorted_refs) +
        held(s.body_chunks) + held(s.first_touch) + held(s.first_touched) + held(s.untouched) + held(s.kinematic) +
        held(s.touched) + held(s.overflow_touches) + held(s.touch_counts) + held(s.tail_plan) + held(s.lead_blocked) +
        held(s.lead_free) + held(s.in_tail) + held(s.tail_bodies);
    for (int c = 0; c < kColorCount; ++c) bytes += held(s.colors[c]) + held(s.joint_colors[c]);
    for (const auto& range : s.listed) bytes += held(range.refs);
    bytes += held(s.listed);
    return bytes;
}

}  // namespace

MemoryReport memory_report(const Space& space) {
    const World& world = SpaceInternals::world(space);
    MemoryReport report;
    report.bodies = body_bytes(world.bodies) + held(world.awake) + held(world.awake_pending);
    for (int k = 0; k < 2; ++k) {
        report.histories += held(world.bodies.history_position[k]) + held(world.bodies.history_orientation[k]);
    }
    report.published = world.motion_states.buffer_bytes();
    report.contacts = held(world.contacts);
    for (const Contact& contact : world.contacts) {
        if (contact.extra) {
            report.contact_extras += sizeof(ContactExtra) + held(contact.extra->manifolds) +
                                     held(contact.extra->triangle_features) + held(contact.extra->mesh_queries.parts) +
                                     held(contact.extra->mesh_queries.triangles) +
                                     held(contact.extra->mesh_queries.manifolds);
        }
    }
    report.contact_lookup = world.contact_index.heap_bytes() + held(world.contact_keys) +
                            held(world.contact_summaries) + held(world.awake_contact_list);
    const SolverScratch& solver = *world.solver;
    report.wide_contacts = held(solver.wide);
    report.push_rows = held(solver.push_anchors);
    report.solver_other = solver_other_bytes(solver);
    const BroadphaseState& bp = *world.broadphase;
    report.broadphase = bp.tree.heap_bytes() + held(bp.proxy) + held(bp.pairs) + held(bp.refit) + held(bp.refit_slots) +
                        held(bp.last_velocity) + held(bp.refit_marked) + held(bp.moved_ids) +
                        bp.part_boxes.heap_bytes();
    for (const std::shared_ptr<QueryScene>& scene : world.query_scenes) {
        if (scene) report.query_scenes += scene->heap_bytes();
    }
    report.page_stock = world.stocked_pages * kHugePageBytes;
    return report;
}

}  // namespace spindle
