// The constraint solver (soft step, as Box2D v3 and Box3D): per step, list the
// touching manifolds and the joints, colour them, and prepare them (contact_solver.cpp,
// joint_solver.cpp); per substep, integrate velocities, warm start (after the first
// substep, made by the relax pass before it: SolverScratch::warm_in_relax), solve with soft
// position bias, integrate positions, relax without bias; then restitution and storing
// impulses for the next step's warm start. The substeps run as one list of phases
// (JobSystem::run_phases), a phase per pass over the bodies or over one colour: no two
// constraints of a colour share a dynamic body, so however a phase is split between
// workers the result is bitwise the same.
#include "solver/constraints.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <span>
#include <type_traits>
#include <utility>

#include <spindle/platform/assert.hpp>

#include "solver/speed_limit.hpp"
#include "stages/capacity.hpp"
#include "stages/continuous.hpp"
#include "stages/stages.hpp"

namespace spindle {

Softness make_softness(Real hertz, Real damping_ratio, Real h) {
    if (hertz == 0) return {0, 1, 0};
    const Real omega = 2 * kPi * hertz;
    const Real a1 = 2 * damping_ratio + h * omega;
    const Real a2 = h * omega * a1;
    if (!std::isfinite(a2)) {
        // So stiff or so damped that a2 overflows (a finite hertz or ratio near the largest
        // double): the limit as it grows, a rigid row (mass scale 1, no impulse scale), not
        // inf * 0. The bias rate omega / a1 written as 1 / (2 zeta / omega + h), which holds
        // when omega overflows too.
        return {1 / (2 * (damping_ratio / omega) + h), 1, 0};
    }
    const Real a3 = 1 / (1 + a2);
    return {omega / a1, a2 * a3, a3};
}

namespace {

// The last block of a phase is the one the other workers wait for at its barrier, and
// block sizes halve down to the grain, so the grains of run_phases' passes are small: a
// few claims more per phase, a shorter wait at every barrier.
constexpr std::uint32_t kBodyGrain = 128;  // bodies per chunk of PrepareBodies
// Bodies per block of a pass over the bodies in run_phases.
constexpr std::uint32_t kBodyPassGrain = 32;
// Joints or wide contacts (kLanes manifolds each) per block of a colour.
constexpr std::uint32_t kConstraintGrain = 1;
// A colour with at most this many is one block (Box3D's smallest block of wide contacts):
// run_phases runs consecutive one-block phases back to back on one worker with one barrier
// after them, so a pass's tail colours cost one barrier, not one each.
constexpr std::uint32_t kOneBlockColor = 4;
// Wide contacts per block when preparing them (the longest per item) and storing their
// impulses.
constexpr std::uint32_t kWideGrain = 1;
// Joints per block when storing their impulses.
constexpr std::uint32_t kJointGrain = 32;
// Awake contacts per range when listing their manifolds.
constexpr std::uint32_t kListGrain = 512;

// PrepareBodies' chunk of awake bodies [lo, hi): their solver bodies, and the chunk's
// least and greatest inverse mass of its dynamic bodies (chunks are fixed by the grain).
void prepare_body_chunk(const World& world, SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi) {
    const Bodies& b = world.bodies;
    const Real max_linear = world.settings.solver.max_linear_speed;
    const Real max_angular = world.settings.solver.max_angular_speed;
    SolverScratch::BodyChunk& chunk = scratch.body_chunks[lo / kBodyGrain];
    chunk = SolverScratch::BodyChunk{};
    for (std::uint32_t k = lo; k < hi; ++k) {
        const std::uint32_t i = world.awake[k];
        SolverBody& sb = scratch.bodies[k];
        sb.dynamic = b.type[i] == MotionType::Dynamic;
        // A kinematic body moves by its velocities alone, limited all the same: once, as
        // nothing changes them within the step (integrate_velocities passes it by).
        sb.v = sb.dynamic ? b.v[i] : limit_speed(b.v[i], max_linear);
        sb.w = sb.dynamic ? b.w[i] : limit_speed(b.w[i], max_angular);
        scratch.push_velocities[k] = PushVelocity{};
        scratch.warm_velocities[k] = PushVelocity{};
        sb.dp = Vec3::Zero();
        sb.dq = Quat::Identity();
        sb.locks = b.locks[i];
        const BodyTraits& d = b.traits[i];
        sb.gyroscopic = sb.dynamic && (d.gyroscopic || b.elongated[i] != 0) && (sb.locks & kLockRotation) == 0;
        sb.sweep = !sb.dynamic || d.sensor ? kSweepNever : d.fast ? kSweepAlways : kSweepWhenFast;
        scratch.gravity_scales[k] = sb.dynamic ? d.gravity_scale : 0;
        sb.damped = sb.dynamic && (d.linear_damping > 0 || d.angular_damping > 0);
        sb.inv_mass = b.inv_mass[i];
        sb.inv_inertia = sb.dynamic ? b.inv_inertia_world(i) : Mat3::Zero();
        // The same about every axis: diagonal (it is symmetric) with equal entries.
        const Mat3& local = b.inv_inertia_local[i];
        sb.isotropic = !sb.dynamic || (local(0, 1) == 0 && local(0, 2) == 0 && local(1, 2) == 0 &&
                                       local(0, 0) == local(1, 1) && local(1, 1) == local(2, 2));
        if (sb.dynamic) {
            chunk.least_inv_mass = std::min(chunk.least_inv_mass, sb.inv_mass);
            chunk.greatest_inv_mass = std::max(chunk.greatest_inv_mass, sb.inv_mass);
        }
    }
}

// ListManifolds' range of awake contacts [lo, hi): one ref per touching manifold, in
// contact order, into the range's own buffer. Reads only the packed keys and summaries,
// never a contact.
void list_range(const World& world, std::span<const std::uint32_t> contacts, SolverScratch& scratch, std::uint32_t lo,
                std::uint32_t hi) {
    const Bodies& b = world.bodies;
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    auto solver_index = [&](std::uint32_t slot) {
        const std::int32_t k = b.awake_index[slot];
        return k >= 0 ? static_cast<std::uint32_t>(k) : n;
    };
    SolverScratch::ListedRange& range = scratch.listed[lo / kListGrain];
    range.refs.clear();
    std::uint32_t materials = 0;
    for (std::uint32_t k = lo; k < hi; ++k) {
        const std::uint32_t c = contacts[k];
        const std::uint32_t summary = world.contact_summaries[c];
        SPINDLE_ASSERT(summary == contact_summary(world.contacts[c]), "solver: a contact's packed summary is stale");
        const std::uint64_t key = world.contact_keys[c];
        const std::uint32_t a = solver_index(static_cast<std::uint32_t>(key >> 32));
        const std::uint32_t bb = solver_index(static_cast<std::uint32_t>(key & 0xffffffffu));
        constexpr std::uint32_t kCountMask = (1u << kSummaryBitsPerManifold) - 1;
        std::uint32_t point_counts = summary & kSummaryPointCounts;
        for (std::uint32_t m = 0; point_counts != 0; ++m, point_counts >>= kSummaryBitsPerManifold) {
            if ((point_counts & kCountMask) == 0) continue;
            range.refs.push_back({c, m, a, bb});
            materials |= summary & ~kSummaryPointCounts;
        }
    }
    range.materials = materials;
}

// JoinManifolds' range: its refs into the step's list, and into the last colouring's list
// where they differ from it (compared only where the lists are as long: else every ref moved),
// so that list is always this step's and comparing it costs no serial pass.
void join_range(SolverScratch& scratch, SolverScratch::ListedRange& range, bool same_count) {
    const auto at = static_cast<std::ptrdiff_t>(range.first);
    std::copy(range.refs.begin(), range.refs.end(), scratch.manifolds.begin() + at);
    static_assert(std::has_unique_object_representations_v<ManifoldRef>, "compared as bytes");
    range.same = same_count &&
                 (range.refs.empty() || std::memcmp(range.refs.data(), scratch.colored_manifolds.data() + at,
                                                    range.refs.size() * sizeof(ManifoldRef)) == 0);
    if (!range.same) std::copy(range.refs.begin(), range.refs.end(), scratch.colored_manifolds.begin() + at);
}

// The step's solver bodies (PrepareBodies) and its list of touching manifolds of awake
// contacts, in contact order (ListManifolds, then JoinManifolds), in one run_phases: one
// fork and join, not three. Fixed chunks of bodies and ranges of contacts are listed in
// parallel, each into its own slots, and the ranges joined in range order, so neither
// depends on who ran what. Their contacts' material bits go to listed_materials.
void prepare_bodies_and_list_manifolds(World& world, SolverScratch& scratch) {
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    // A first step's are megabytes of new pages: mapped in jobs, then first written by the
    // PrepareBodies blocks (raw room: the resizes write nothing).
    reserve_for(scratch.bodies, n + 1);
    map_room(*world.jobs, scratch.bodies, n + 1);
    scratch.bodies.resize(n + 1);
    scratch.push_velocities.resize(n + 1);
    scratch.warm_velocities.resize(n + 1);
    scratch.gravity_scales.resize(n + 1);
    const std::uint32_t chunks = (n + kBodyGrain - 1) / kBodyGrain;
    scratch.body_chunks.resize(chunks);  // each written whole by its chunk
    scratch.bodies[n] = SolverBody{};    // the immovable partner of static and sleeping bodies
    scratch.push_velocities[n] = PushVelocity{};
    scratch.warm_velocities[n] = PushVelocity{};
    scratch.gravity_scales[n] = 0;

    const std::vector<std::uint32_t>& contacts = awake_contacts(world);
    const auto count = static_cast<std::uint32_t>(contacts.size());
    const std::uint32_t ranges = (count + kListGrain - 1) / kListGrain;
    if (scratch.listed.size() < ranges) scratch.listed.resize(ranges);  // capacity kept from step to step
    const std::span<SolverScratch::ListedRange> listed(scratch.listed.data(), ranges);

    // Items of the first phase: the chunks of bodies, then the ranges of contacts; the range
    // listed last places the ranges and sizes the list (a countdown: not a round of its own
    // and the barrier after it). The second copies them in, in jobs: a first step's list is
    // hundreds of new pages, each a fault on its first write.
    const Phase phases[] = {{"PrepareBodiesAndListManifolds", chunks + ranges, 1}, {"JoinManifolds", ranges, 1}};
    scratch.listed_materials = 0;  // the ranges' say, as they are placed
    if (chunks + ranges == 0) {    // no awake body: nothing to list, no jobs at all
        scratch.manifolds.clear();
        scratch.same_manifolds = scratch.colored_manifolds.empty();
        scratch.colored_manifolds.clear();
        return;
    }
    bool same_count = false;  // as many manifolds as the last colouring's
    auto place = [&] {
        std::size_t total = 0;
        for (SolverScratch::ListedRange& range : listed) {
            range.first = total;
            total += range.refs.size();
            scratch.listed_materials |= range.materials;
        }
        scratch.manifolds.resize(total);
        same_count = scratch.colored_manifolds.size() == total;
        scratch.colored_manifolds.resize(total);  // capacity kept: no allocation once grown
    };
    if (ranges == 0) place();
    std::atomic<std::uint32_t> unlisted{ranges};  // ranges not listed yet: the last to be listed places them
    world.jobs->run_phases("SolverLists", phases, [&](std::uint32_t p, std::uint32_t lo, std::uint32_t hi, unsigned) {
        if (p == 1) {
            for (std::uint32_t r = lo; r < hi; ++r) join_range(scratch, listed[r], same_count);
            return;
        }
        for (std::uint32_t item = lo; item < hi; ++item) {
            if (item < chunks) {
                prepare_body_chunk(world, scratch, item * kBodyGrain, std::min(n, (item + 1) * kBodyGrain));
                continue;
            }
            const std::uint32_t r = item - chunks;
            list_range(world, contacts, scratch, r * kListGrain, std::min(count, (r + 1) * kListGrain));
            // Every other range's list happened before its count down, and so before this.
            if (unlisted.fetch_sub(1, std::memory_order_acq_rel) == 1) place();
        }
    });
    scratch.same_manifolds = same_count &&
                             std::all_of(listed.begin(), listed.end(), [](const auto& range) { return range.same; });
    // Equal least and greatest inverse mass over every chunk: no body is lighter than
    // another it carries.
    Real least = kHuge, greatest = -kHuge;
    for (const SolverScratch::BodyChunk& chunk : scratch.body_chunks) {
        least = std::min(least, chunk.least_inv_mass);
        greatest = std::max(greatest, chunk.greatest_inv_mass);
    }
    scratch.one_dynamic_mass = !(least < greatest);
}

// Greedy colouring (Box2D v3's graph colouring): the first colour whose bodies include
// neither dynamic body of the constraint; -1 when none is free. Static, kinematic and
// sleeping partners are shared freely: constraints never write them. Each body keeps a
// mask of the colours it is in, so the first free colour is one bit scan.
int assign_color(SolverScratch& scratch, std::uint32_t a, std::uint32_t b) {
    static_assert(kColorCount <= 32, "one bit per colour in a 32-bit mask");
    constexpr std::uint32_t kAllColors = kColorCount == 32 ? ~0u : (1u << kColorCount) - 1;
    const bool dyn_a = scratch.bodies[a].dynamic;
    const bool dyn_b = scratch.bodies[b].dynamic;
    std::uint32_t* used = scratch.body_colors.data();
    const std::uint32_t free = kAllColors & ~((dyn_a ? used[a] : 0u) | (dyn_b ? used[b] : 0u));
    if (free == 0) return -1;
    const int c = std::countr_zero(free);
    if (dyn_a) used[a] |= 1u << c;
    if (dyn_b) used[b] |= 1u << c;
    return c;
}

// Each colour's manifolds in the order of their lower dynamic body (then their ref), so a
// share of a colour's wide contacts (run_phases cuts a phase's items into one share per
// worker, in order) touches the bodies of about the same part of the body order in every
// colour: a worker meets again the bodies it wrote in the last colour, still in its own
// cache. A colour's manifolds share no dynamic body, so their order within it changes no
// result. One counting sort of every coloured manifold by that body (stable: refs in
// order within a body), dealt back to the colours (SolverScratch::manifold_colors).
void sort_colors(SolverScratch& scratch) {
    const auto none = static_cast<std::uint32_t>(scratch.bodies.size());  // a manifold without a dynamic body
    auto lower_dynamic = [&](const ManifoldRef& m) {
        return std::min(scratch.bodies[m.a].dynamic ? m.a : none, scratch.bodies[m.b].dynamic ? m.b : none);
    };
    std::vector<std::uint32_t>& starts = scratch.body_starts;
    starts.assign(std::size_t{none} + 2, 0);
    const auto count = static_cast<std::uint32_t>(scratch.manifolds.size());
    for (std::uint32_t k = 0; k < count; ++k) {
        if (scratch.manifold_colors[k] >= 0) ++starts[lower_dynamic(scratch.manifolds[k]) + 1];
    }
    for (std::size_t i = 1; i < starts.size(); ++i) starts[i] += starts[i - 1];
    scratch.sorted_refs.resize(starts.back());
    for (std::uint32_t k = 0; k < count; ++k) {
        if (scratch.manifold_colors[k] >= 0) scratch.sorted_refs[starts[lower_dynamic(scratch.manifolds[k])]++] = k;
    }
    for (std::vector<std::uint32_t>& refs : scratch.colors) refs.clear();
    for (std::uint32_t k : scratch.sorted_refs) scratch.colors[scratch.manifold_colors[k]].push_back(k);
}

// Joints first, then contacts, in list order (deterministic), sharing the colours'
// body sets: a colour's joints and contacts together touch each dynamic body once.
void color(SolverScratch& scratch) {
    for (int c = 0; c < kColorCount; ++c) {
        scratch.colors[c].clear();
        scratch.joint_colors[c].clear();
    }
    scratch.body_colors.assign(scratch.bodies.size(), 0);
    scratch.overflow.clear();
    scratch.joint_overflow.clear();
    for (std::uint32_t k = 0; k < scratch.joints.size(); ++k) {
        const int c = assign_color(scratch, scratch.joints[k].a, scratch.joints[k].b);
        (c >= 0 ? scratch.joint_colors[c] : scratch.joint_overflow).push_back(k);
    }
    // The colours first, counted, then each colour's list given its room at once and filled
    // in manifold order: grown by doubling, each of a first step's lists (many_pyramids'
    // 28,420 refs) took a dozen blocks, each on fresh pages, and copies.
    const auto count = static_cast<std::uint32_t>(scratch.manifolds.size());
    scratch.manifold_colors.resize(count);
    std::array<std::uint32_t, kColorCount + 1> sizes{};  // the overflow's last
    for (std::uint32_t k = 0; k < count; ++k) {
        const int c = assign_color(scratch, scratch.manifolds[k].a, scratch.manifolds[k].b);
        scratch.manifold_colors[k] = static_cast<std::int8_t>(c);
        ++sizes[c >= 0 ? c : kColorCount];
    }
    for (int c = 0; c < kColorCount; ++c) scratch.colors[c].reserve(sizes[c]);
    scratch.overflow.reserve(sizes[kColorCount]);
    for (std::uint32_t k = 0; k < count; ++k) {
        const int c = scratch.manifold_colors[k];
        (c >= 0 ? scratch.colors[c] : scratch.overflow).push_back(k);
    }
}

template <typename T, typename A>
bool same_bytes(const std::vector<T, A>& x, const std::vector<T, A>& y) {
    return x.size() == y.size() && (x.empty() ||  // memcmp may not see the null data of an empty vector
                                    std::memcmp(x.data(), y.data(), x.size() * sizeof(T)) == 0);
}

// Whether the colours and packing of the last colouring hold for this step's
// constraints: the same manifolds of the same bodies (compared range by range as they
// were joined: join_range), no body made or destroyed (a reused slot could change from
// kinematic to dynamic, which the colours depend on), the same awake count (the
// immovable body is the last) and the same joints of the same bodies. A resting pile
// keeps its manifold list from step to step, a jointed scene its joint list, and
// comparing them is far cheaper than colouring.
bool same_constraints(const World& world, SolverScratch& scratch) {
    static_assert(std::has_unique_object_representations_v<JointRef>, "compared as bytes");
    const bool same = scratch.reuse_colors && scratch.same_manifolds &&
                      same_bytes(scratch.colored_joints, scratch.joint_refs) &&
                      scratch.colored_body_set == world.body_set_version &&
                      scratch.colored_bodies == scratch.bodies.size();
    if (!same) {
        scratch.colored_bodies = scratch.bodies.size();
        scratch.colored_body_set = world.body_set_version;
        scratch.colored_joints = scratch.joint_refs;
    }
    return same;
}

// Runs ball_socket_fn, joint_fn and contact_fn over constraints [lo, hi) of colour
// `color`: its wide joints (joint_lanes.cpp) and other joints (if kJoints), then its wide
// contacts. The overflow (color == kColorCount) is one block, run serially, joints first.
template <bool kJoints, typename BallSocketFn, typename JointFn, typename ContactFn>
void for_colored(SolverScratch& scratch, int color, std::uint32_t lo, std::uint32_t hi, BallSocketFn&& ball_socket_fn,
                 JointFn&& joint_fn, ContactFn&& contact_fn) {
    if (color == kColorCount) {
        if (kJoints) {
            for (std::uint32_t k : scratch.joint_overflow) joint_fn(scratch.joints[k]);
        }
        for (std::size_t k = scratch.wide_begin[kColorCount]; k < scratch.wide.size(); ++k) contact_fn(scratch.wide[k]);
        return;
    }
    const std::vector<std::uint32_t>& joints = scratch.joint_colors[color];
    const std::uint32_t ball_sockets = kJoints ? scratch.wide_joint_begin[color + 1] - scratch.wide_joint_begin[color]
                                               : 0u;
    const auto joint_count = kJoints ? ball_sockets + static_cast<std::uint32_t>(joints.size()) : 0u;
    WideJoint* wide_joints = scratch.wide_joints.data() + scratch.wide_joint_begin[color];
    WideContact* contacts = scratch.wide.data() + scratch.wide_begin[color];
    for (std::uint32_t k = lo; k < hi; ++k) {
        if (k < ball_sockets) {
            ball_socket_fn(wide_joints[k]);
        } else if (k < joint_count) {
            joint_fn(scratch.joints[joints[k - ball_sockets]]);
        } else {
            contact_fn(contacts[k - joint_count]);
        }
    }
}

// Calls fn(k) for each body constraint item `item` of colour `color` touches (the overflow:
// every body of its block), in the order a pass touches them: a wide joint's or wide
// contact's lanes (A, then B, lane by lane), or a joint's A and B.
template <typename Fn>
void for_item_bodies(SolverScratch& scratch, int color, std::uint32_t item, Fn&& fn) {
    const std::uint32_t k = item - scratch.first_item[color];
    auto lanes = [&](const auto& wide) {  // a WideJoint or a WideContact
        for (int l = 0; l < wide.lanes; ++l) {
            fn(wide.a[l]);
            fn(wide.b[l]);
        }
    };
    auto joint = [&](const JointConstraint& j) {
        fn(j.a);
        fn(j.b);
    };
    for_colored<true>(scratch, color, k, k + 1, lanes, joint, lanes);
}

// Items (constraints of the colours, in pass order) and awake bodies per block of
// find_first_touches' phases.
constexpr std::uint32_t kTouchItemGrain = 256;
constexpr std::uint32_t kTouchBodyGrain = 1024;

// Which bodies each constraint is the first of its pass to touch, and the awake bodies no
// constraint touches (SolverScratch::first_touch, untouched); the kinematic bodies apart
// (SolverScratch::kinematic), as if touched already. A pass runs the colours in
// order, each as for_colored does (its wide joints, its other joints, its wide contacts),
// and the overflow last (its joints, then its wide contacts); within a colour no two
// constraints share a dynamic body. Bodies n and up (the immovable one) are never
// integrated.
//
// So a dynamic body's first toucher is the one constraint of the first colour it is in
// (the lowest bit of its body_colors mask, set by the colouring), or, in none, the overflow
// (one item, after every colour). Each item's first touches are then counted and written
// in jobs, apart from the others': the lists are those of a walk through the pass in
// order, made without one. In one run_phases: items and chunks of bodies counted, the
// counts placed (one block), the lists written.
void find_first_touches(JobSystem& jobs, SolverScratch& scratch, std::uint32_t n) {
    std::uint32_t items = 0;
    for (int c = 0; c < kColorCount; ++c) {
        scratch.first_item[c] = items;
        items += scratch.wide_joint_begin[c + 1] - scratch.wide_joint_begin[c] +
                 static_cast<std::uint32_t>(scratch.joint_colors[c].size()) + scratch.wide_begin[c + 1] -
                 scratch.wide_begin[c];
    }
    scratch.first_item[kColorCount] = items;
    // Per item its count, then (placed) its offset; the overflow's item, and one past it.
    scratch.first_touch.resize(std::size_t{items} + 2);
    const std::uint32_t* colors = scratch.body_colors.data();
    auto first_touched_by = [&](int color, std::uint32_t k) {
        return k < n && std::countr_zero(colors[k]) == color;  // 32 for a body in no colour
    };
    // The overflow is one block, run serially after every colour: its first touches are the
    // bodies in no colour, in the order it touches them. Rare; marked to be met once.
    std::vector<std::uint32_t>& overflow_touches = scratch.overflow_touches;
    overflow_touches.clear();
    const bool overflow = !scratch.joint_overflow.empty() || scratch.wide.size() > scratch.wide_begin[kColorCount];
    if (overflow) {
        scratch.touched.assign(n, 0);
        auto touch = [&](std::uint32_t k) {
            if (k >= n || colors[k] != 0 || scratch.touched[k] != 0 || !scratch.bodies[k].dynamic) return;
            scratch.touched[k] = 1;
            overflow_touches.push_back(k);
        };
        for_item_bodies(scratch, kColorCount, scratch.first_item[kColorCount], touch);
    }
    // A body no colour holds: kinematic, untouched, or the overflow's.
    auto untouched_body = [&](std::uint32_t k) {
        return scratch.bodies[k].dynamic && colors[k] == 0 && !(overflow && scratch.touched[k] != 0);
    };

    const std::uint32_t item_blocks = (items + kTouchItemGrain - 1) / kTouchItemGrain;
    const std::uint32_t body_blocks = (n + kTouchBodyGrain - 1) / kTouchBodyGrain;
    // Per chunk of bodies: its untouched and kinematic counts, then their offsets.
    std::vector<std::uint32_t>& body_counts = scratch.touch_counts;
    body_counts.assign(2 * std::size_t{body_blocks}, 0);
    auto color_of = [&](std::uint32_t item) {
        return static_cast<int>(std::upper_bound(scratch.first_item, scratch.first_item + kColorCount, item) -
                                scratch.first_item) -
               1;
    };
    auto each_item = [&](std::uint32_t block, auto&& fn) {
        const std::uint32_t last = std::min(items, (block + 1) * kTouchItemGrain);
        int c = color_of(block * kTouchItemGrain);
        for (std::uint32_t i = block * kTouchItemGrain; i < last; ++i) {
            while (i >= scratch.first_item[c + 1]) ++c;  // past empty colours too
            fn(c, i);
        }
    };
    if (item_blocks + body_blocks == 0) {  // no awake body, no constraint: no jobs at all
        scratch.first_touch.assign(2, 0);
        scratch.first_touched.clear();
        scratch.untouched.clear();
        scratch.kinematic.clear();
        return;
    }
    const Phase phases[] = {{"CountFirstTouches", item_blocks + body_blocks, 1},
                            {"PlaceFirstTouches", 1, 1},
                            {"ListFirstTouches", item_blocks + body_blocks, 1}};
    jobs.run_phases("FirstTouches", phases, [&](std::uint32_t p, std::uint32_t lo, std::uint32_t hi, unsigned) {
        if (p == 1) {
            std::uint32_t total = 0;
            for (std::uint32_t i = 0; i < items; ++i) total += std::exchange(scratch.first_touch[i], total);
            scratch.first_touch[items] = total;
            total += static_cast<std::uint32_t>(overflow_touches.size());
            scratch.first_touch[std::size_t{items} + 1] = total;
            scratch.first_touched.resize(total);
            std::copy(overflow_touches.begin(), overflow_touches.end(),
                      scratch.first_touched.begin() + scratch.first_touch[items]);
            std::uint32_t untouched = 0, kinematic = 0;
            for (std::uint32_t b = 0; b < body_blocks; ++b) {
                untouched += std::exchange(body_counts[2 * b], untouched);
                kinematic += std::exchange(body_counts[2 * b + 1], kinematic);
            }
            scratch.untouched.resize(untouched);
            scratch.kinematic.resize(kinematic);
            return;
        }
        for (std::uint32_t block = lo; block < hi; ++block) {
            if (block < item_blocks) {
                each_item(block, [&](int c, std::uint32_t i) {
                    if (p == 0) {
                        std::uint32_t count = 0;
                        for_item_bodies(scratch, c, i, [&](std::uint32_t k) { count += first_touched_by(c, k); });
                        scratch.first_touch[i] = count;
                    } else {
                        std::uint32_t* out = scratch.first_touched.data() + scratch.first_touch[i];
                        for_item_bodies(scratch, c, i, [&](std::uint32_t k) {
                            if (first_touched_by(c, k)) *out++ = k;
                        });
                    }
                });
                continue;
            }
            const std::uint32_t chunk = block - item_blocks;
            const std::uint32_t last = std::min(n, (chunk + 1) * kTouchBodyGrain);
            std::uint32_t* untouched = scratch.untouched.data() + body_counts[2 * chunk];
            std::uint32_t* kinematic = scratch.kinematic.data() + body_counts[2 * chunk + 1];
            for (std::uint32_t k = chunk * kTouchBodyGrain; k < last; ++k) {
                const bool moving = !scratch.bodies[k].dynamic;
                const bool alone = untouched_body(k);
                if (p == 0) {
                    body_counts[2 * chunk] += alone;
                    body_counts[2 * chunk + 1] += moving;
                } else if (alone) {
                    *untouched++ = k;
                } else if (moving) {
                    *kinematic++ = k;
                }
            }
        }
    });
}

// Calls integrate(list) on the bodies that constraints [lo, hi) of colour `color` are the
// first of their pass to touch (one span), before the phase's block runs them:
// no other constraint of the colour touches those bodies, so all of them may go first (and
// the overflow, one block, has the first touches of its whole pass).
template <typename IntegrateFn>
void integrate_first_touched(const SolverScratch& scratch, int color, std::uint32_t lo, std::uint32_t hi,
                             IntegrateFn&& integrate) {
    const std::size_t first = scratch.first_item[color] + (color == kColorCount ? 0 : lo);
    const std::size_t last = color == kColorCount ? first + 1 : scratch.first_item[color] + hi;
    const std::uint32_t from = scratch.first_touch[first];
    const std::uint32_t to = scratch.first_touch[last];
    if (to > from) integrate(std::span<const std::uint32_t>(scratch.first_touched.data() + from, to - from));
}

// Whether plan entry p is a colour of a few wide contacts (one block: a round of run_phases).
bool tail_color(const SolverScratch& scratch, std::size_t p) {
    return scratch.plan[p].color < kColorCount && scratch.phases[p].count <= kOneBlockColor;
}

// SolverScratch::lead_blocked and lead_free: colour `lead`'s wide contacts that share a
// dynamic body with colours [tail, kColorCount), and the others, in colour order; and those
// bodies (in_tail, tail_bodies).
void split_lead(SolverScratch& scratch, int lead, int tail) {
    scratch.in_tail.assign(scratch.bodies.size(), 0);
    auto mark = [&](std::uint32_t k) {
        if (scratch.bodies[k].dynamic) scratch.in_tail[k] = 1;
    };
    for (std::uint32_t w = scratch.wide_begin[tail]; w < scratch.wide_begin[kColorCount]; ++w) {
        const WideContact& wc = scratch.wide[w];
        for (int l = 0; l < wc.lanes; ++l) {
            mark(wc.a[l]);
            mark(wc.b[l]);
        }
    }
    scratch.tail_bodies.clear();
    for (std::uint32_t k = 0; k < scratch.in_tail.size(); ++k) {
        if (scratch.in_tail[k] != 0) scratch.tail_bodies.push_back(k);
    }
    scratch.lead_blocked.clear();
    scratch.lead_free.clear();
    for (std::uint32_t w = scratch.wide_begin[lead]; w < scratch.wide_begin[lead + 1]; ++w) {
        const WideContact& wc = scratch.wide[w];
        bool shares = false;
        for (int l = 0; l < wc.lanes; ++l)
            shares = shares || scratch.in_tail[wc.a[l]] != 0 || scratch.in_tail[wc.b[l]] != 0;
        (shares ? scratch.lead_blocked : scratch.lead_free).push_back(w - scratch.wide_begin[lead]);
    }
    scratch.lead_made = true;
}

// Where the tail of the constraint pass planned last before phase `first` begins (its last
// colours, one block each, after a bigger colour of that pass); `first` if it has none. Only
// for wide contacts alone: with joints or an overflow a tail stays a round of its own.
std::size_t tail_before(const SolverScratch& scratch, std::size_t first) {
    if (!scratch.carry_tails || first == 0 || !scratch.joints.empty() ||
        scratch.wide.size() > scratch.wide_begin[kColorCount])
        return first;
    const Pass pass = scratch.plan[first - 1].pass;
    if (pass != Pass::WarmStart && pass != Pass::Solve && pass != Pass::Relax && pass != Pass::Restitution)
        return first;
    std::size_t from = first;
    while (from > 0 && scratch.plan[from - 1].pass == pass && tail_color(scratch, from - 1)) --from;
    // The tail follows a bigger colour of its pass: a pass of small colours only is left alone.
    if (from == first || from == 0 || scratch.plan[from - 1].pass != pass || tail_color(scratch, from - 1) ||
        scratch.plan[from - 1].color >= scratch.plan[from].color)
        return first;
    return from;
}

// Moves plan entries [from, first) into SolverScratch::tail_plan; returns where they begin there.
std::uint32_t move_tail(SolverScratch& scratch, std::size_t from, std::size_t first) {
    const auto tail_begin = static_cast<std::uint32_t>(scratch.tail_plan.size());
    for (std::size_t p = from; p < first; ++p) scratch.tail_plan.push_back({scratch.plan[p], scratch.phases[p].count});
    scratch.plan.erase(scratch.plan.begin() + static_cast<std::ptrdiff_t>(from),
                       scratch.plan.begin() + static_cast<std::ptrdiff_t>(first));
    scratch.phases.erase(scratch.phases.begin() + static_cast<std::ptrdiff_t>(from),
                         scratch.phases.begin() + static_cast<std::ptrdiff_t>(first));
    return tail_begin;
}

// Moves the tail of the pass planned before phase `first` into item 0 of phase `first`, the
// next pass's first colour (SolverScratch::tail_plan says why). The tail runs after the
// barrier that ends the colour before it, the lead's blocked contacts after the tail (the same
// item), and the lead's free contacts share no dynamic body with the tail, so any worker may
// run them beside it.
void carry_tail(SolverScratch& scratch, std::size_t first) {
    if (first == scratch.phases.size()) return;
    const int lead = scratch.plan[first].color;
    if (lead == kColorCount || scratch.wide_begin[lead + 1] - scratch.wide_begin[lead] <= kOneBlockColor) return;
    const std::uint32_t lead_wides = scratch.wide_begin[lead + 1] - scratch.wide_begin[lead];
    const std::size_t from = tail_before(scratch, first);
    if (from == first) return;
    // Every pass has the same colours (wide contacts only): one split serves them all.
    if (!scratch.lead_made) split_lead(scratch, lead, scratch.plan[from].color);
    const std::uint32_t tail_begin = move_tail(scratch, from, first);
    SolverPhase& carrier = scratch.plan[from];
    Phase& carrier_phase = scratch.phases[from];
    carrier.tail_begin = tail_begin;
    carrier.tail_end = static_cast<std::uint32_t>(scratch.tail_plan.size());
    // Item 0, then the free contacts, then the chunks of bodies if it integrates.
    const std::uint32_t chunks = carrier_phase.count - lead_wides;
    carrier.constraints = 1 + static_cast<std::uint32_t>(scratch.lead_free.size());
    carrier_phase.count = carrier.constraints + chunks;
    carrier_phase.grain = kConstraintGrain;
}

// Adds the phases of one pass over the constraints: one per colour that has any (its
// joints, if with_joints, and wide contacts share no dynamic body), then the overflow.
// With `integrates`, each of its phases integrates the bodies it touches first, and the
// first one also the untouched bodies, in chunks after its constraints. With `warms` (a relax
// pass), each contact warm starts the next substep after it is relaxed.
void plan_constraint_pass(SolverScratch& scratch, Pass pass, const char* name, bool with_joints, int substep,
                          bool integrates = false, bool warms = false) {
    const std::size_t first = scratch.phases.size();
    auto add_phase = [&](int color, std::uint32_t count, std::uint32_t grain) {
        scratch.phases.push_back(Phase{name, count, grain});
        SolverPhase& phase = scratch.plan.emplace_back(SolverPhase{pass, color});
        phase.warms = warms;
        phase.substep = static_cast<std::uint32_t>(substep);
    };
    for (int c = 0; c < kColorCount; ++c) {
        const auto joints = with_joints ? static_cast<std::uint32_t>(scratch.joint_colors[c].size()) +
                                              (scratch.wide_joint_begin[c + 1] - scratch.wide_joint_begin[c])
                                        : 0u;
        const std::uint32_t count = joints + (scratch.wide_begin[c + 1] - scratch.wide_begin[c]);
        if (count == 0) continue;
        add_phase(c, count, count <= kOneBlockColor ? count : kConstraintGrain);
    }
    const bool overflow = (with_joints && !scratch.joint_overflow.empty()) ||
                          scratch.wide.size() > scratch.wide_begin[kColorCount];
    if (overflow) add_phase(kColorCount, 1, 1);
    if (integrates && first != scratch.phases.size()) {
        for (std::size_t p = first; p < scratch.phases.size(); ++p) {
            scratch.plan[p].integrates = true;
            scratch.plan[p].constraints = scratch.phases[p].count;
        }
        const auto chunks =
            static_cast<std::uint32_t>((scratch.untouched.size() + kBodyPassGrain - 1) / kBodyPassGrain);
        Phase& phase = scratch.phases[first];
        phase.count += chunks;
        phase.grain = phase.count <= kOneBlockColor ? phase.count : kConstraintGrain;
    }
    carry_tail(scratch, first);
}

void plan_body_pass(SolverScratch& scratch, Pass pass, const char* name, std::uint32_t bodies) {
    scratch.phases.push_back(Phase{name, bodies, kBodyPassGrain});
    scratch.plan.push_back(SolverPhase{pass, 0});
}

void plan_wide_pass(SolverScratch& scratch, Pass pass, const char* name) {
    scratch.phases.push_back(Phase{name, static_cast<std::uint32_t>(scratch.wide.size()), kWideGrain});
    scratch.plan.push_back(SolverPhase{pass, 0});
}

// The step's solver loop as a list of phases, each over the bodies, the wide contacts
// or one colour.
void plan_step(World& world, SolverScratch& scratch, bool restitution) {
    const SolverSettings& settings = world.settings.solver;
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    scratch.phases.clear();
    scratch.plan.clear();
    scratch.tail_plan.clear();
    plan_wide_pass(scratch, Pass::PrepareContacts, "PrepareContacts");
    if (!scratch.wide_joints.empty()) {
        scratch.phases.push_back(
            Phase{"PrepareJoints", static_cast<std::uint32_t>(scratch.wide_joints.size()), kWideGrain});
        scratch.plan.push_back(SolverPhase{Pass::PrepareJoints, 0});
    }
    const bool folded = scratch.folded;
    const auto kinematic = static_cast<std::uint32_t>(scratch.kinematic.size());
    for (int sub = 0; sub < settings.substeps; ++sub) {
        // Warm started by the relax pass before it (SolverScratch::warm_in_relax): its first
        // solve pass integrates the velocities and adds the warm start's changes.
        const bool warmed = scratch.warms && sub > 0;
        if (!folded) plan_body_pass(scratch, Pass::IntegrateVelocities, "IntegrateVelocities", n);
        if (!warmed) plan_constraint_pass(scratch, Pass::WarmStart, "WarmStart", true, sub, folded);
        for (int it = 0; it < settings.iterations; ++it)
            plan_constraint_pass(scratch, Pass::Solve, "Solve", true, sub, warmed && it == 0);
        if (!folded) plan_body_pass(scratch, Pass::IntegratePositions, "IntegratePositions", n);
        if (folded && kinematic != 0) {
            // Many constraints of a colour read a kinematic body at once: it moves between the
            // passes, in a phase of its own (its velocities do not change within a step).
            scratch.phases.push_back(Phase{"IntegrateKinematic", kinematic, kBodyPassGrain});
            scratch.plan.push_back(SolverPhase{Pass::IntegrateKinematic, 0});
        }
        const bool warms_next = scratch.warms && sub + 1 < settings.substeps;
        for (int it = 0; it < settings.relax_iterations; ++it)
            plan_constraint_pass(scratch, Pass::Relax, "Relax", true, sub, folded && it == 0,
                                 warms_next && it + 1 == settings.relax_iterations);
    }
    if (restitution) plan_constraint_pass(scratch, Pass::Restitution, "Restitution", false, settings.substeps - 1);
    if (scratch.fold_body_passes && scratch.joints.empty() && !scratch.wide.empty()) {
        // Storing the contacts' impulses and finalizing the bodies read and write nothing of
        // each other's: one phase, the bodies in chunks after the wide contacts.
        auto wide = static_cast<std::uint32_t>(scratch.wide.size());
        SolverPhase store{Pass::StoreImpulses, 0, true, wide};
        // The last pass's tail too, in item 0, then the tail's own contacts' impulses and its
        // bodies; the other contacts and bodies beside it (SolverScratch::tail_plan).
        const std::size_t last = scratch.phases.size();
        if (const std::size_t from = tail_before(scratch, last); from != last && scratch.lead_made) {
            store.color = scratch.plan[from].color;
            store.tail_begin = move_tail(scratch, from, last);
            store.tail_end = static_cast<std::uint32_t>(scratch.tail_plan.size());
            wide = 1 + scratch.wide_begin[store.color];
            store.constraints = wide;
        }
        scratch.phases.push_back(
            Phase{"StoreAndFinalize", wide + (n + kBodyPassGrain - 1) / kBodyPassGrain, kWideGrain});
        scratch.plan.push_back(store);
        return;
    }
    plan_wide_pass(scratch, Pass::StoreImpulses, "StoreImpulses");
    if (!scratch.joints.empty()) {
        // The lanes' impulses go back to their constraints before the joints keep them.
        if (!scratch.wide_joints.empty()) {
            scratch.phases.push_back(
                Phase{"StoreJointLanes", static_cast<std::uint32_t>(scratch.wide_joints.size()), kWideGrain});
            scratch.plan.push_back(SolverPhase{Pass::StoreJointLanes, 0});
        }
        scratch.phases.push_back(Phase{"StoreJoints", static_cast<std::uint32_t>(scratch.joints.size()), kJointGrain});
        scratch.plan.push_back(SolverPhase{Pass::StoreJoints, 0});
    }
    plan_body_pass(scratch, Pass::FinalizeBodies, "FinalizeBodies", n);
}

// The step's motion into the bodies, awake bodies [lo, hi); those it moved far for their
// size (or flagged fast) are listed, with their poses before it, for the Continuous stage.
void finalize_bodies(World& world, const SolverScratch& scratch, Real dt, std::uint32_t lo, std::uint32_t hi,
                     std::vector<FastStart>& to_sweep) {
    Bodies& b = world.bodies;
    const Real max_linear = world.settings.solver.max_linear_speed;
    const Real max_angular = world.settings.solver.max_angular_speed;
    for (std::uint32_t k = lo; k < hi; ++k) {
        const std::uint32_t i = world.awake[k];
        const SolverBody& sb = scratch.bodies[k];
        if (sb.sweep == kSweepAlways || (sb.sweep == kSweepWhenFast && moves_fast(sb, b.extents[i], b.q[i], dt)))
            to_sweep.push_back({i, b.x[i], b.q[i]});
        b.x[i] += sb.dp;
        b.q[i] = (sb.dq * b.q[i]).normalized();
        // Constraints may push a body past the limits its integration kept: the stored
        // velocity is held to them too.
        b.v[i] = limit_speed(sb.v, max_linear);
        b.w[i] = limit_speed(sb.w, max_angular);
        b.force[i] = Vec3::Zero();  // consumed by this step
        b.torque[i] = Vec3::Zero();
    }
}

}  // namespace

void solve(World& world, Real dt) {
    SolverScratch& scratch = *world.solver;
    const SolverSettings& settings = world.settings.solver;
    const int substeps = settings.substeps;
    const Real h = dt / substeps;

    world.fast_lists.resize(world.jobs->worker_count());
    for (std::vector<FastStart>& list : world.fast_lists) list.clear();
    prepare_bodies_and_list_manifolds(world, scratch);
    const bool restitution = (scratch.listed_materials & kSummaryRestitution) != 0;
    find_support_scales(world, scratch);  // light bodies carrying heavier ones; usually none
    prepare_joints(world, scratch, h);    // nothing to do in a scene without joints
    if (!same_constraints(world, scratch)) {
        color(scratch);
        // One worker meets every body in its own cache: nothing to keep apart.
        if (scratch.sort_colors && world.jobs->worker_count() > 1) sort_colors(scratch);
        pack_joint_lanes(scratch);  // nothing to do in a scene without joints
        pack_contacts(*world.jobs, scratch);
        find_first_touches(*world.jobs, scratch, static_cast<std::uint32_t>(world.awake.size()));
        scratch.lead_made = false;
        world.counters.constraint_colorings += 1;
    }
    size_rolling_rows(scratch);
    // Folded only where every phase that integrates has a constraint to carry it.
    scratch.folded = scratch.fold_body_passes && !(scratch.wide.empty() && scratch.joints.empty()) &&
                     settings.relax_iterations > 0;
    scratch.warms = scratch.folded && scratch.warm_in_relax && settings.iterations > 0;
    // A world at rest (every body asleep or static) has nothing to move or solve: no
    // passes at all, not a plan of empty ones each step.
    if (world.awake.empty() && scratch.wide.empty() && scratch.joints.empty()) return;
    SolverBody* bodies = scratch.bodies.data();
    PushVelocity* push = scratch.push_velocities.data();
    PushVelocity* warm = scratch.warm_velocities.data();
    const Real* gravity_scales = scratch.gravity_scales.data();

    ContactSolveParams solve_params;
    // The contact spring: an eighth of the substep rate unless set (Box3D's), never stiffer
    // than a quarter of it; against a static body twice as stiff, with half the damping
    // ratio, so a load presses less into the ground.
    const Real stiffest = Real(0.25) / h;
    const Real hertz = settings.contact_hertz > 0 ? std::min(settings.contact_hertz, stiffest) : stiffest / 2;
    solve_params.soft = make_softness(hertz, settings.damping_ratio, h);
    solve_params.static_soft = make_softness(std::min(2 * hertz, stiffest), settings.damping_ratio / 2, h);
    solve_params.held_per_impulse = held_per_impulse(solve_params.soft);
    solve_params.static_held_per_impulse = held_per_impulse(solve_params.static_soft);
    solve_params.inv_h = 1 / h;
    solve_params.push_out = settings.push_out_speed;
    solve_params.slop = settings.linear_slop;
    solve_params.recovery_depth = settings.recovery_depth;
    // A speed that would carry a point a tenth of the slop in a substep (0.12 m/s at the
    // defaults): below it, what one sweep of a manifold leaves is less than a player sees.
    solve_params.settled_speed = settings.linear_slop * solve_params.inv_h / 10;
    solve_params.step = dt;
    ContactSolveParams relax_params = solve_params;
    relax_params.use_bias = false;
    const JointSolveParams joint_solve{joint_softness(settings, h), 1 / h, true};
    const JointSolveParams joint_relax{joint_solve.soft, joint_solve.inv_h, false};

    // Preparing the contacts, every substep's passes, storing impulses and finalizing the
    // bodies in one run_phases: the workers meet at a barrier after each colour instead
    // of forking and joining about a hundred times per step. Effects are counted per
    // worker and summed (the sum does not depend on who counted what).
    plan_step(world, scratch, restitution);  // no pass at all over a scene without bouncy contacts
    world.scratch_counts.assign(world.jobs->worker_count(), EffectCounts{});
    const Real restitution_threshold = settings.restitution_threshold;
    const Real max_bounce = settings.max_linear_speed;
    auto push_anchors = [&](const WideContact& wc) {
        return scratch.push_anchors.data() + kLanes * static_cast<std::size_t>(&wc - scratch.wide.data());
    };
    // Items [lo, hi) of a phase that carries a body pass, past its own: chunks of `count`
    // bodies, fn(from, to) for each.
    auto body_chunks = [](const SolverPhase& phase, std::uint32_t lo, std::uint32_t hi, std::uint32_t count,
                          auto&& fn) {
        for (std::uint32_t c = std::max(lo, phase.constraints); c < hi; ++c) {
            const std::uint32_t from = (c - phase.constraints) * kBodyPassGrain;
            fn(from, std::min(count, from + kBodyPassGrain));
        }
    };
    // A folded phase's block [lo, hi): its constraints' first touches, then its chunks of
    // the untouched bodies.
    const std::span<const std::uint32_t> untouched(scratch.untouched);
    auto integrate_folded = [&](const SolverPhase& phase, std::uint32_t lo, std::uint32_t hi, auto&& integrate) {
        const std::uint32_t own = std::min(hi, phase.constraints);
        if (lo < own) integrate_first_touched(scratch, phase.color, lo, own, integrate);
        body_chunks(phase, lo, hi, static_cast<std::uint32_t>(untouched.size()),
                    [&](std::uint32_t from, std::uint32_t to) { integrate(untouched.subspan(from, to - from)); });
    };
    // Constraints [lo, hi) of a colour solved, with a pass's bias or without.
    auto solve_colored = [&](int color, std::uint32_t lo, std::uint32_t hi, const JointSolveParams& joint_params,
                             const ContactSolveParams& contact_params, EffectCounts& counts) {
        for_colored<true>(
            scratch, color, lo, hi,
            [&](WideJoint& wj) { solve_joint_lanes(scratch, wj, bodies, joint_params, counts); },
            [&](JointConstraint& jc) { solve_joint(jc, bodies, joint_params, counts); },
            [&](WideContact& wc) { solve_contact(wc, push_anchors(wc), bodies, push, contact_params, counts); });
    };
    // A warming relax phase's constraints [lo, hi) (SolverScratch::warm_in_relax).
    auto relax_and_warm_colored = [&](int color, std::uint32_t lo, std::uint32_t hi,
                                      const ContactSolveParams& contact_params, EffectCounts& counts) {
        for_colored<true>(
            scratch, color, lo, hi,
            [&](WideJoint& wj) { relax_and_warm_start_joint_lanes(scratch, wj, bodies, joint_relax, counts, warm); },
            [&](JointConstraint& jc) { relax_and_warm_start_joint(jc, bodies, joint_relax, counts, warm); },
            [&](WideContact& wc) {
                relax_and_warm_start_contact(wc, push_anchors(wc), bodies, push, warm, contact_params, counts);
            });
    };
    // A pass's parameters with the time in the step its friction reads the surfaces at
    // (ContactSolveParams::turn_time): the middle of a biased pass's substep, a relax pass's
    // end; and how long gravity has acted on its velocities (fall_time).
    auto timed = [h](ContactSolveParams params, const SolverPhase& phase, Real part) {
        params.turn_time = (static_cast<Real>(phase.substep) + part) * h;
        params.fall_time = static_cast<Real>(phase.substep + 1) * h;
        return params;
    };
    // Items [lo, hi) of a phase of the plan.
    auto run_items = [&](const SolverPhase& phase, std::uint32_t lo, std::uint32_t hi, unsigned worker) {
        EffectCounts& counts = world.scratch_counts[worker];
        switch (phase.pass) {
            case Pass::PrepareContacts: prepare_contacts(world, scratch, solve_params, lo, hi); break;
            case Pass::PrepareJoints: prepare_joint_lanes(scratch, lo, hi); break;
            case Pass::StoreImpulses:
                if (!phase.integrates) {
                    store_contact_impulses(world, scratch, lo, hi);
                    break;
                }
                store_contact_impulses(world, scratch, std::min(lo, phase.constraints),
                                       std::min(hi, phase.constraints));
                body_chunks(phase, lo, hi, static_cast<std::uint32_t>(world.awake.size()),
                            [&](std::uint32_t from, std::uint32_t to) {
                                finalize_bodies(world, scratch, dt, from, to, world.fast_lists[worker]);
                            });
                break;
            case Pass::StoreJointLanes: store_joint_lane_impulses(scratch, lo, hi); break;
            case Pass::StoreJoints: store_joint_impulses(world, scratch, lo, hi); break;
            case Pass::FinalizeBodies: finalize_bodies(world, scratch, dt, lo, hi, world.fast_lists[worker]); break;
            case Pass::IntegrateVelocities:
                integrate_velocities(world, bodies, gravity_scales, h, lo, hi, counts);
                break;
            case Pass::IntegratePositions: integrate_positions(world, bodies, push, h, lo, hi); break;
            case Pass::IntegrateKinematic:
                integrate_positions(world, bodies, push, h,
                                    std::span<const std::uint32_t>(scratch.kinematic).subspan(lo, hi - lo));
                break;
            case Pass::WarmStart: {
                if (phase.integrates) {
                    integrate_folded(phase, lo, hi, [&](std::span<const std::uint32_t> ks) {
                        integrate_velocities(world, bodies, gravity_scales, h, ks, counts);
                    });
                }
                const std::uint32_t own = phase.integrates ? std::min(hi, phase.constraints) : hi;
                if (lo >= own) break;
                for_colored<true>(
                    scratch, phase.color, lo, own, [&](WideJoint& wj) { warm_start_joint_lanes(scratch, wj, bodies); },
                    [&](JointConstraint& jc) { warm_start_joint(jc, bodies); },
                    [&](WideContact& wc) { warm_start_contact(wc, push_anchors(wc), bodies, push); });
                break;
            }
            case Pass::Solve: {
                if (phase.integrates) {  // then the warm start the relax pass before made
                    integrate_folded(phase, lo, hi, [&](std::span<const std::uint32_t> ks) {
                        integrate_velocities(world, bodies, gravity_scales, h, ks, counts, warm);
                    });
                }
                const std::uint32_t own = phase.integrates ? std::min(hi, phase.constraints) : hi;
                if (lo < own) solve_colored(phase.color, lo, own, joint_solve, timed(solve_params, phase, 0.5), counts);
                break;
            }
            case Pass::Relax: {
                if (phase.integrates) {
                    integrate_folded(phase, lo, hi, [&](std::span<const std::uint32_t> ks) {
                        integrate_positions(world, bodies, push, h, ks);
                    });
                }
                const std::uint32_t own = phase.integrates ? std::min(hi, phase.constraints) : hi;
                if (lo >= own) break;
                const ContactSolveParams params = timed(relax_params, phase, 1);
                if (phase.warms) {
                    relax_and_warm_colored(phase.color, lo, own, params, counts);
                } else {
                    solve_colored(phase.color, lo, own, joint_relax, params, counts);
                }
                break;
            }
            case Pass::Restitution:
                for_colored<false>(
                    scratch, phase.color, lo, hi, [](WideJoint&) {}, [](JointConstraint&) {},
                    [&](WideContact& wc) {
                        apply_restitution(wc, bodies, restitution_threshold, max_bounce, h, counts);
                    });
                break;
        }
    };
    // The tail a carrier's item 0 runs first.
    auto run_tail = [&](const SolverPhase& carrier, unsigned worker) {
        for (std::uint32_t t = carrier.tail_begin; t < carrier.tail_end; ++t)
            run_items(scratch.tail_plan[t].phase, 0, scratch.tail_plan[t].items, worker);
    };
    // Items [lo, hi) of a first colour that carries the tail of the pass before it: item 0 the
    // tail and then the colour's blocked contacts, then its free ones, then chunks of bodies.
    const std::span<const std::uint32_t> lead_free(scratch.lead_free);
    auto run_carrier = [&](const SolverPhase& carrier, std::uint32_t lo, std::uint32_t hi, unsigned worker) {
        SolverPhase own = carrier;  // the colour as a phase of its own: its contacts, then the chunks
        own.constraints = scratch.wide_begin[carrier.color + 1] - scratch.wide_begin[carrier.color];
        if (lo == 0) {
            run_tail(carrier, worker);
            for (std::uint32_t k : scratch.lead_blocked) run_items(own, k, k + 1, worker);
            lo = 1;
        }
        // Free contacts in runs of consecutive ones.
        for (std::uint32_t i = lo; i < std::min(hi, carrier.constraints);) {
            const std::uint32_t from = lead_free[i - 1];
            std::uint32_t to = from + 1;
            for (++i; i < std::min(hi, carrier.constraints) && lead_free[i - 1] == to; ++i) ++to;
            run_items(own, from, to, worker);
        }
        const std::uint32_t chunks_from = std::max(lo, carrier.constraints);
        if (chunks_from < hi)
            run_items(own, own.constraints + chunks_from - carrier.constraints,
                      own.constraints + hi - carrier.constraints, worker);
    };
    // Items [lo, hi) of StoreAndFinalize carrying the last pass's tail: item 0 the tail, its
    // contacts' impulses and its bodies; then the other contacts, then chunks of the other bodies.
    const std::span<const std::uint8_t> in_tail(scratch.in_tail);
    auto run_store_carrier = [&](const SolverPhase& carrier, std::uint32_t lo, std::uint32_t hi, unsigned worker) {
        auto finalize = [&](std::uint32_t from, std::uint32_t to) {
            finalize_bodies(world, scratch, dt, from, to, world.fast_lists[worker]);
        };
        if (lo == 0) {
            run_tail(carrier, worker);
            store_contact_impulses(world, scratch, scratch.wide_begin[carrier.color],
                                   static_cast<std::uint32_t>(scratch.wide.size()));
            for (std::uint32_t k : scratch.tail_bodies) finalize(k, k + 1);
            lo = 1;
        }
        if (lo < carrier.constraints)
            store_contact_impulses(world, scratch, lo - 1, std::min(hi, carrier.constraints) - 1);
        body_chunks(carrier, lo, hi, static_cast<std::uint32_t>(world.awake.size()),
                    [&](std::uint32_t from, std::uint32_t to) {
                        for (std::uint32_t k = from; k < to;) {  // runs of bodies the tail does not touch
                            if (in_tail[k] != 0) {
                                ++k;
                                continue;
                            }
                            const std::uint32_t run = k;
                            while (k < to && in_tail[k] == 0) ++k;
                            finalize(run, k);
                        }
                    });
    };
    world.jobs->run_phases("Solver", scratch.phases,
                           [&](std::uint32_t p, std::uint32_t lo, std::uint32_t hi, unsigned worker) {
                               const SolverPhase& phase = scratch.plan[p];
                               if (phase.tail_end == phase.tail_begin) {
                                   run_items(phase, lo, hi, worker);
                               } else if (phase.pass == Pass::StoreImpulses) {
                                   run_store_carrier(phase, lo, hi, worker);
                               } else {
                                   run_carrier(phase, lo, hi, worker);
                               }
                           });
    for (const EffectCounts& c : world.scratch_counts) {
        world.counters.gravity_applied += c.gravity;
        world.counters.damping_applied += c.damping;
        world.counters.gyroscopic_applied += c.gyro;
        world.counters.contact_points_solved += c.contact_points;
        world.counters.friction_applied += c.friction;
        world.counters.rolling_applied += c.rolling;
        world.counters.restitution_applied += c.restitution;
        world.counters.joints_solved += c.joints;
    }
    world.counters.bodies_integrated += world.awake.size();
}

}  // namespace spindle
