// Broadphase stage: bounds of awake bodies, proxies moved in the AABB tree, new pairs
// -> contacts, contacts whose fat bounds separated -> removed.
#include <algorithm>
#include <atomic>
#include <optional>
#include <stdexcept>
#include <string>

#include "collision/compound.hpp"
#include "collision/convex_hull.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

bool can_collide(const Bodies& b, std::uint32_t i, std::uint32_t j) {
    // Two bodies that cannot move each other make no contact; two sensors do not sense each other.
    return (b.type[i] == MotionType::Dynamic || b.type[j] == MotionType::Dynamic) &&
           !(b.traits[i].sensor && b.traits[j].sensor);
}

void mark_refit(BroadphaseState& bp, std::uint32_t slot) {
    if (bp.refit[slot]) return;
    bp.refit[slot] = 1;
    bp.refit_slots.push_back(slot);
}

// Marks a body whose fat box changed at all (grown or shrunk: either can end an overlap).
void note_fat_change(BroadphaseState& bp, std::uint32_t slot, const Aabb& before, const Aabb& after) {
    if (after.min != before.min || after.max != before.max) mark_refit(bp, slot);
}

// The box a body's proxy must hold: its bounds (swept or not) grown by the speculative
// distance where the body can move.
Aabb reach_box(const BroadphaseState& bp, const Aabb& bounds, bool is_static) {
    return is_static ? bounds : bounds.fattened(bp.rule.speculative);
}

// Moves a body's proxy (its ancestors grown at once), with no stretch: a teleport.
void move_proxy(BroadphaseState& bp, std::uint32_t slot, const Aabb& box) {
    const Aabb before = bp.tree.fat_aabb(bp.proxy[slot]);
    bp.tree.move_proxy(bp.proxy[slot], reach_box(bp, box, bp.proxy[slot].is_static()), Vec3::Zero());
    note_fat_change(bp, slot, before, bp.tree.fat_aabb(bp.proxy[slot]));
}

// The box a body's fat box must hold: its bounds swept over this step's motion (a
// fast body near the edge of its fat box would otherwise cross a whole step into
// something before the pair is found).
Aabb swept_bounds(const Bodies& b, std::uint32_t i, const Vec3& displacement) {
    Aabb swept = b.bounds[i];
    swept.min += displacement.cwiseMin(Vec3::Zero());
    swept.max += displacement.cwiseMax(Vec3::Zero());
    return swept;
}

}  // namespace

Real fat_box_radius(const Shape& shape) {
    switch (shape.type) {
        case ShapeType::Sphere: return shape.radius;
        case ShapeType::Capsule: return shape.half_height + shape.radius;
        case ShapeType::Box: return shape.half_extents.norm();
        case ShapeType::ConvexHull: {
            Real reach = 0;
            for (const Vec3& v : shape.hull->vertices()) reach = std::max(reach, (v - shape.hull->centroid()).norm());
            return reach;
        }
        case ShapeType::Compound: {
            // One proxy for the whole body: the reach of its parts from the body's origin.
            Real reach = 0;
            for (const CompoundPart& part : shape.parts->parts()) {
                reach = std::max(reach, part.position.norm() + fat_box_radius(part.shape));
            }
            return reach;
        }
        default: return kHuge;  // static only: never given a margin
    }
}

void FatBoxRule::check() const {
    const auto require = [](Real value, const char* name) {
        if (!(value >= 0 && is_finite(value))) {
            throw std::invalid_argument(std::string("broadphase fat box rule: ") + name +
                                        " must be finite and >= 0, got " + std::to_string(value));
        }
    };
    require(speculative, "speculative");
    require(max_margin, "max_margin");
    require(margin_fraction, "margin_fraction");
    require(stretch, "stretch");
    require(free_tolerance, "free_tolerance");
}

// The trees stretch the displacements they are given; the stage gives a slow body's as none.
BroadphaseState::BroadphaseState(const FatBoxRule& fat_rule)
    : rule((fat_rule.check(), fat_rule)), tree(BroadphaseSettings{.displacement_multiplier = fat_rule.stretch}) {}

void CompoundPartBoxes::add(const Bodies& bodies, std::uint32_t slot) {
    if (bodies.traits[slot].shape.type != ShapeType::Compound || bodies.type[slot] == MotionType::Static) return;
    if (m_member_place.size() <= slot) m_member_place.resize(slot + 1, kNone);
    m_member_place[slot] = static_cast<std::uint32_t>(m_members.size());
    m_members.push_back(slot);
    m_changed = true;
}

void CompoundPartBoxes::remove(std::uint32_t slot) {
    if (slot >= m_member_place.size() || m_member_place[slot] == kNone) return;
    const std::uint32_t place = m_member_place[slot];
    m_member_place[m_members.back()] = place;
    m_members[place] = m_members.back();
    m_members.pop_back();
    m_member_place[slot] = kNone;
    m_changed = true;
}

void CompoundPartBoxes::lay_out(const Bodies& bodies) {
    if (!m_changed) return;
    m_changed = false;
    const std::uint32_t end = m_members.empty() ? 0 : *std::max_element(m_members.begin(), m_members.end()) + 1;
    m_index.assign(end, kNone);
    m_first.assign(m_members.size() + 1, 0);
    for (std::uint32_t k = 0; k < m_members.size(); ++k) {
        m_index[m_members[k]] = k;
        m_first[k + 1] = m_first[k] + bodies.traits[m_members[k]].shape.parts->size();
    }
    m_made.assign(m_members.size(), 0);  // a slot's compound may be another now
    m_boxes.resize(m_first.back());
}

std::size_t CompoundPartBoxes::heap_bytes() const noexcept {
    return (m_members.capacity() + m_member_place.capacity()) * sizeof(std::uint32_t) +
           m_index.capacity() * sizeof(std::uint32_t) + m_first.capacity() * sizeof(std::uint32_t) +
           m_made.capacity() * sizeof(std::uint64_t) + m_boxes.capacity() * sizeof(Aabb);
}

void add_proxy(World& world, std::uint32_t slot) {
    BroadphaseState& bp = *world.broadphase;
    const Bodies& b = world.bodies;
    if (bp.proxy.size() <= slot) bp.proxy.resize(slot + 1);
    if (bp.refit.size() <= slot) bp.refit.resize(slot + 1, 0);
    if (bp.last_velocity.size() <= slot) bp.last_velocity.resize(slot + 1);
    bp.last_velocity[slot] = b.v[slot];
    const bool is_static = b.type[slot] == MotionType::Static;
    bp.proxy[slot] = bp.tree.create_proxy(reach_box(bp, b.bounds[slot], is_static), slot, is_static,
                                          is_static ? Real(0) : bp.rule.margin(fat_box_radius(b.traits[slot].shape)));
    bp.part_boxes.add(b, slot);
    mark_refit(bp, slot);
}

void remove_proxy(World& world, std::uint32_t slot) {
    BroadphaseState& bp = *world.broadphase;
    bp.tree.destroy_proxy(bp.proxy[slot]);
    bp.proxy[slot] = ProxyId{};
    bp.part_boxes.remove(slot);
}

void refresh_proxy(World& world, std::uint32_t slot) { move_proxy(*world.broadphase, slot, world.bodies.bounds[slot]); }

namespace {

// Removes the contacts (positions ascending) that the filter rejects, among those
// `involves` accepts, waking both bodies of each first: what rested on the other may fall.
template <typename Involves>
void remove_filtered_contacts(World& world, Involves&& involves) {
    RawRoomVector<std::uint32_t>& filtered = world.scratch_lost;
    filtered.clear();
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        const std::uint64_t key = world.contact_keys[c];
        const auto i = static_cast<std::uint32_t>(key >> 32);
        const auto j = static_cast<std::uint32_t>(key & 0xffffffffu);
        if (involves(i, j) && filter_blocks_pair(world, i, j)) filtered.push_back(c);
    }
    for (std::uint32_t c : filtered) {
        wake_body(world, world.contacts[c].body_a);
        wake_body(world, world.contacts[c].body_b);
    }
    remove_contacts(world, filtered);
    filtered.clear();
}

}  // namespace

void refilter_bodies(World& world, std::span<const std::uint32_t> slots) {
    const auto changed = [slots](std::uint32_t i) { return std::binary_search(slots.begin(), slots.end(), i); };
    remove_filtered_contacts(world, [&](std::uint32_t i, std::uint32_t j) { return changed(i) || changed(j); });
    for (std::uint32_t slot : slots) world.broadphase->tree.touch(world.broadphase->proxy[slot]);
}

void refilter_all(World& world) {
    remove_filtered_contacts(world, [](std::uint32_t, std::uint32_t) { return true; });
    // Every pair has a moving proxy (static pairs are never reported): touching those finds them all.
    const Bodies& b = world.bodies;
    for (std::uint32_t slot = 0; slot < b.capacity(); ++slot) {
        if (!b.alive[slot] || b.type[slot] == MotionType::Static) continue;
        wake_body(world, slot);
        world.broadphase->tree.touch(world.broadphase->proxy[slot]);
    }
}

namespace {

// Pairs and contacts per job in the broadphase's passes over them.
constexpr std::uint32_t kPairGrain = 256;
constexpr std::uint32_t kContactGrain = 1024;

// Runs keep(k, out) -> bool over [0, n) in parallel ranges of `grain`, each range writing
// what it keeps to out from its own first index on; then closes the ranges up, in range
// order. `out` holds the kept values in index order, the same for any number of workers.
template <typename T, typename Allocator, typename Keep>
void select_in_order(JobSystem& jobs, const char* name, std::uint32_t n, std::uint32_t grain,
                     std::vector<std::uint32_t>& counts, std::vector<T, Allocator>& out, Keep&& keep) {
    out.resize(n);  // on raw room (RawRoomVector) left as it is: only kept values are read
    counts.assign((n + grain - 1) / grain, 0);
    jobs.parallel_for(name, 0, n, grain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        std::uint32_t kept = 0;
        for (std::uint32_t k = lo; k < hi; ++k) kept += keep(k, out[lo + kept]) ? 1u : 0u;
        counts[lo / grain] = kept;
    });
    std::size_t size = 0;
    for (std::size_t c = 0; c < counts.size(); ++c) {
        const auto from = out.begin() + static_cast<std::ptrdiff_t>(c * grain);
        std::copy(from, from + counts[c],
                  out.begin() + static_cast<std::ptrdiff_t>(size));  // down: never overlaps ahead
        size += counts[c];
    }
    out.resize(size);
}

// New pairs -> contacts, in pair order. The checks read the bodies' descriptions (cold),
// so they run in parallel ranges; the contacts are made from the keys kept.
void make_contacts(World& world, BroadphaseState& bp) {
    const Bodies& b = world.bodies;
    std::atomic<std::uint64_t> filtered{0};
    select_in_order(*world.jobs, "NewPairs", static_cast<std::uint32_t>(bp.pairs.size()), kPairGrain, bp.range_counts,
                    bp.new_keys, [&](std::uint32_t k, std::uint64_t& key) {
                        const auto i = static_cast<std::uint32_t>(bp.pairs[k].user_a);
                        const auto j = static_cast<std::uint32_t>(bp.pairs[k].user_b);
                        if (!can_collide(b, i, j)) return false;
                        if (filter_blocks_pair(world, i, j)) {
                            // No contact: the narrowphase never sees the pair.
                            filtered.fetch_add(1, std::memory_order_relaxed);
                            return false;
                        }
                        key = (std::uint64_t{std::min(i, j)} << 32) | std::max(i, j);
                        // Jointed bodies collide only if asked.
                        if (joint_blocks_pair(world.joints, i, j)) return false;
                        return true;
                    });
    world.counters.pairs_filtered += filtered.load(std::memory_order_relaxed);
    create_contacts(world, bp.new_keys);
}

// The awake contacts (positions ascending) whose fat boxes stopped overlapping; only a
// refitted box can have. Those from `made_from` on were made this stage from pairs whose
// fat boxes overlap as they are now: not read (a first step's are all of them).
void find_lost_contacts(World& world, BroadphaseState& bp, std::uint32_t made_from,
                        RawRoomVector<std::uint32_t>& lost) {
    const std::vector<std::uint32_t>& awake = awake_contacts(world);
    const auto older =
        static_cast<std::uint32_t>(std::lower_bound(awake.begin(), awake.end(), made_from) - awake.begin());
    select_in_order(*world.jobs, "LostPairs", older, kContactGrain, bp.range_counts, lost,
                    [&](std::uint32_t k, std::uint32_t& position) {
                        const std::uint64_t key = world.contact_keys[awake[k]];  // packed: no Contact is read
                        const auto i = static_cast<std::uint32_t>(key >> 32);
                        const auto j = static_cast<std::uint32_t>(key & 0xffffffffu);
                        if (!bp.refit[i] && !bp.refit[j]) return false;
                        if (bp.tree.test_overlap(bp.proxy[i], bp.proxy[j])) return false;
                        position = awake[k];
                        return true;
                    });
}

}  // namespace

void update_broadphase(World& world, Real dt) {
    Bodies& b = world.bodies;
    BroadphaseState& bp = *world.broadphase;
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    // The stage's parts are named in the trace (each its own serial time, "BroadphasePairs
    // outside jobs"), so the serial code of a first step can be told apart.
    std::optional<StageScope> part;
    const auto next_part = [&](const char* name) {
        part.reset();  // the last part ends before the next begins
        part.emplace(*world.jobs, name);
    };
    next_part("BroadphaseBounds");
    // Bounds, and whether each proxy must move and to which fat box, in parallel; the
    // proxies that left their fat boxes then get them in jobs too (set_fat_boxes). Raw
    // room: the Bounds jobs write each body's mark and id.
    bp.refit_marked.resize(n);
    bp.moved_ids.resize(n);
    bp.moved_boxes.resize(n);
    bp.part_boxes.lay_out(b);
    std::atomic<std::uint32_t> marked{0};
    std::atomic<std::uint32_t> moved{0};
    const Vec3 gravity_change = world.settings.gravity * dt;
    world.jobs->parallel_for("Bounds", 0, n, 128, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        std::uint32_t range_marked = 0, range_moved = 0;
        for (std::uint32_t k = lo; k < hi; ++k) {
            const std::uint32_t i = world.awake[k];
            const Shape& shape = b.traits[i].shape;
            if (shape.type == ShapeType::Compound) {
                // Kept for the narrowphase's part walks, which would make the same boxes again.
                b.bounds[i] = shape.parts->bounds(b.transform(i), bp.part_boxes.fill(i, world.steps));
            } else {
                b.bounds[i] = shape.bounds(b.transform(i));
            }
            const Vec3 d = b.v[i] * dt;
            const Real margin = bp.tree.margin(bp.proxy[i]);
            const Vec3 velocity_change = b.v[i] - bp.last_velocity[i];
            bp.last_velocity[i] = b.v[i];
            // A body carried by what touches it gets its bounds, unswept, as in Box3D; a
            // body in free flight, thrown or hit hard, and a kinematic one, its bounds swept
            // over the step, and a fast one in free flight a stretch ahead too.
            const bool dynamic = b.type[i] == MotionType::Dynamic;
            const bool free = dynamic && bp.rule.in_free_flight(velocity_change, gravity_change);
            const bool carried = dynamic && !free && FatBoxRule::carried(velocity_change, dt, margin);
            const Aabb swept = reach_box(bp, carried ? b.bounds[i] : swept_bounds(b, i, d), bp.proxy[i].is_static());
            bp.refit_marked[k] = 0;
            bp.moved_ids[k] = ProxyId{};
            const Vec3 stretch = free && FatBoxRule::fast(d, margin) ? d : Vec3::Zero();
            if (!bp.tree.needs_move(bp.proxy[i], swept, stretch)) continue;
            const Aabb fat = bp.tree.fat_box(bp.proxy[i], swept, stretch);
            bp.moved_ids[k] = bp.proxy[i];
            bp.moved_boxes[k] = fat;
            ++range_moved;
            // note_fat_change, for this job's own bodies (a slot is marked by one job).
            const Aabb& before = bp.tree.fat_aabb(bp.proxy[i]);
            if ((fat.min != before.min || fat.max != before.max) && !bp.refit[i]) {
                bp.refit[i] = 1;
                bp.refit_marked[k] = 1;
                ++range_marked;
            }
        }
        if (range_marked != 0) marked.fetch_add(range_marked, std::memory_order_relaxed);
        if (range_moved != 0) moved.fetch_add(range_moved, std::memory_order_relaxed);
    });
    // The moved leaves' ancestors are only flagged: update_pairs rebuilds them before its
    // searches, which are the next to read the tree. A resting pile moves no proxy for
    // steps on end: then there is nothing to set, and no jobs are forked for it.
    if (moved.load(std::memory_order_relaxed) != 0) bp.tree.set_fat_boxes(*world.jobs, bp.moved_ids, bp.moved_boxes);

    // A pair found again (one of its proxies grew) has its contact: left out by the pair
    // jobs, which only read the index meanwhile.
    const auto has_contact = [&world](std::uint64_t i, std::uint64_t j) {
        return world.contact_index.contains((i << 32) | j);  // user values are slots, i <= j
    };
    next_part("BroadphasePairs");
    // A level's first step expects the pairs its bodies counted (memory/page_stock.hpp).
    const std::size_t expected_pairs = world.building_level ? world.first_step_contact_count() : 0;
    // Sorted: the same order for any worker count.
    bp.tree.update_pairs(*world.jobs, bp.pairs, has_contact, expected_pairs);
    next_part("BroadphaseNewContacts");
    const auto made_from = static_cast<std::uint32_t>(world.contacts.size());
    make_contacts(world, bp);
    next_part("BroadphaseLostContacts");

    // Lost pairs: awake contacts whose fat bounds no longer overlap; only a refitted box
    // can have stopped overlapping.
    RawRoomVector<std::uint32_t>& lost = world.scratch_lost;
    lost.clear();
    const bool moves_marked = marked.load(std::memory_order_relaxed) != 0;
    if (!bp.refit_slots.empty() || moves_marked) find_lost_contacts(world, bp, made_from, lost);
    remove_contacts(world, lost);
    fit_contacts(world);
    // Only the marked slots are cleared: a sleeping pile's slots are not touched.
    for (std::uint32_t slot : bp.refit_slots) bp.refit[slot] = 0;
    bp.refit_slots.clear();
    if (moves_marked) {
        SPINDLE_ASSERT(world.awake.size() == n, "broadphase: the awake list changed within the stage");
        world.jobs->parallel_for("ClearRefit", 0, n, 1024, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
            for (std::uint32_t k = lo; k < hi; ++k) {
                if (bp.refit_marked[k]) bp.refit[world.awake[k]] = 0;
            }
        });
    }
}

}  // namespace spindle
