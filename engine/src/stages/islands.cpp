// Islands and sleeping: bodies linked by touching contacts or joints form islands
// (union-find over the awake bodies each step); an island whose bodies all rested long enough
// goes to sleep as a whole and costs nothing until something wakes it. Also the awake list.
#include <algorithm>
#include <iterator>
#include <numeric>

#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {
namespace {

std::uint32_t find(std::vector<std::uint32_t>& parent, std::uint32_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

// Joins two sets; the lower root wins, so islands do not depend on the link order.
void unite(std::vector<std::uint32_t>& parent, std::uint32_t a, std::uint32_t b) {
    const std::uint32_t ra = find(parent, a);
    const std::uint32_t rb = find(parent, b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
}

// A sensor's contact pushes nothing: it neither links bodies into an island nor wakes one.
bool touching(const Contact& c) { return c.manifold_count > 0 && (c.events & kContactSensor) == 0; }

}  // namespace

void set_awake(World& world, std::uint32_t slot, bool awake) {
    Bodies& b = world.bodies;
    const std::int32_t index = b.awake_index[slot];
    if (awake) {
        if (index >= 0) return;
        b.awake_index[slot] = kAwakePending;
        world.awake_pending.push_back(slot);
        b.sleep_time[slot] = 0;
        b.island[slot] = -1;
    } else {
        if (index < 0) return;
        b.awake_index[slot] = -1;  // its entry (listed or pending) is dropped by settle_awake
        if (index != kAwakePending) {
            world.awake_left_from = std::min(world.awake_left_from, static_cast<std::size_t>(index));
        }
    }
}

void settle_awake(World& world) {
    std::vector<std::uint32_t>& pending = world.awake_pending;
    if (pending.empty() && world.awake_left_from == kNoPosition) return;
    Bodies& b = world.bodies;
    std::vector<std::uint32_t>& list = world.awake;
    // The woken bodies still awake, once each, ascending: the list's order never depends
    // on the order bodies woke in (determinism across runs and worker counts).
    std::erase_if(pending, [&](std::uint32_t slot) { return b.awake_index[slot] != kAwakePending; });
    std::sort(pending.begin(), pending.end());
    pending.erase(std::unique(pending.begin(), pending.end()), pending.end());
    // Nothing before the first left position or the first woken body's place changes.
    std::size_t start = std::min(world.awake_left_from, list.size());
    if (!pending.empty()) {
        const auto first = std::lower_bound(list.begin(), list.end(), pending.front());
        start = std::min(start, static_cast<std::size_t>(first - list.begin()));
    }
    // The rest: the bodies still at their positions (not left, nor woken again since they
    // left), merged with the woken.
    std::vector<std::uint32_t>& tail = world.scratch_awake_tail;
    tail.clear();
    for (std::size_t k = start; k < list.size(); ++k) {
        if (b.awake_index[list[k]] == static_cast<std::int32_t>(k)) tail.push_back(list[k]);
    }
    list.resize(start);
    std::merge(tail.begin(), tail.end(), pending.begin(), pending.end(), std::back_inserter(list));
    for (std::size_t k = start; k < list.size(); ++k) b.awake_index[list[k]] = static_cast<std::int32_t>(k);
    pending.clear();
    world.awake_left_from = kNoPosition;
}

void wake_body(World& world, std::uint32_t slot) {
    Bodies& b = world.bodies;
    if (b.type[slot] == MotionType::Static) return;
    b.sleep_time[slot] = 0;
    if (b.awake_index[slot] >= 0) return;
    const std::int32_t island = b.island[slot];
    if (island < 0) {
        set_awake(world, slot, true);
        return;
    }
    SleepingIsland& sleeping = world.sleeping_islands[static_cast<std::size_t>(island)];
    for (std::uint32_t member : sleeping.bodies) {
        set_awake(world, member, true);
        world.changed_now.push_back(member);
    }
    for (std::uint64_t key : sleeping.contacts) {
        if (const std::uint32_t* position = world.contact_index.find(key)) world.contacts[*position].sleeping = false;
    }
    world.awake_contacts_dirty = true;
    for (JointHandle joint : sleeping.joints) {
        if (world.joints.is_live(joint)) world.joints.joint[joint.index].sleeping = false;
    }
    if (!sleeping.joints.empty()) world.joints.awake_dirty = true;
    sleeping.bodies.clear();
    sleeping.contacts.clear();
    sleeping.joints.clear();
    world.free_islands.push_back(island);
}

void wake_touching(World& world, std::uint32_t slot) {
    wake_body(world, slot);
    // Contact partners are among the proxies whose fat boxes overlap the body's: a contact
    // ends when the fat boxes part (and a sleeping contact's bodies do not move).
    const BroadphaseState& bp = *world.broadphase;
    if (slot < bp.proxy.size() && bp.proxy[slot].valid()) {
        bp.tree.query(bp.tree.fat_aabb(bp.proxy[slot]), [&](ProxyId id) {
            const auto other = static_cast<std::uint32_t>(bp.tree.user(id));
            if (other != slot && world.contact_index.contains(pair_key(slot, other))) wake_body(world, other);
            return true;
        });
    }
    // A static body has no island to keep its joints; a moving body's island holds its joints,
    // and its awake joints wake their partners in the Islands stage.
    Joints& joints = world.joints;
    if (world.bodies.type[slot] != MotionType::Static || joints.live == 0) return;
    for (std::uint32_t j = 0; j < joints.capacity(); ++j) {
        if (!joints.alive[j]) continue;
        const Joint& joint = joints.joint[j];
        if (joint.body_a == slot) wake_body(world, joint.body_b);
        if (joint.body_b == slot) wake_body(world, joint.body_a);
    }
}

void update_islands(World& world, Real dt) {
    Bodies& b = world.bodies;
    const SleepSettings& sleep = world.settings.sleep;

    // Contacts between an awake body and a sleeping one wake the sleeper's island (none
    // to wake while no island sleeps). So does a static body's awake contact with a sleeper:
    // a new one, made by a static body moved or created against it.
    const bool any_asleep = world.sleeping_islands.size() > world.free_islands.size();
    for (std::size_t k = 0; any_asleep && k < awake_contacts(world).size(); ++k) {  // wake_body may rebuild the list
        const Contact& contact = world.contacts[awake_contacts(world)[k]];
        if (!touching(contact)) continue;
        const std::uint32_t ca = contact.body_a, cb = contact.body_b;
        const bool awake_a = b.awake_index[ca] >= 0 || b.type[ca] == MotionType::Static;
        const bool awake_b = b.awake_index[cb] >= 0 || b.type[cb] == MotionType::Static;
        if (awake_a && !awake_b && b.type[cb] == MotionType::Dynamic) wake_body(world, cb);
        if (awake_b && !awake_a && b.type[ca] == MotionType::Dynamic) wake_body(world, ca);
    }
    // So do joints: a joint cannot hold a body that does not move.
    Joints& joints = world.joints;
    for (std::size_t k = 0; any_asleep && k < awake_joints(world).size(); ++k) {  // wake_body may rebuild the list
        const Joint& joint = joints.joint[awake_joints(world)[k]];
        const std::uint32_t ja = joint.body_a, jb = joint.body_b;
        const bool awake_a = b.awake_index[ja] >= 0, awake_b = b.awake_index[jb] >= 0;
        if (awake_a && !awake_b && b.type[jb] == MotionType::Dynamic) wake_body(world, jb);
        if (awake_b && !awake_a && b.type[ja] == MotionType::Dynamic) wake_body(world, ja);
    }
    settle_awake(world);
    if (!sleep.enabled) return;

    // Rest timers. A kinematic body that moves at all never rests, however slowly it moves:
    // it is driven, and sleeping would stop it.
    const Real lin2 = sleep.linear_threshold * sleep.linear_threshold;
    const Real ang2 = sleep.angular_threshold * sleep.angular_threshold;
    Real longest_rest = 0;
    for (std::uint32_t i : world.awake) {
        const bool driven = b.type[i] == MotionType::Kinematic && (b.v[i] != Vec3::Zero() || b.w[i] != Vec3::Zero());
        const bool resting = b.traits[i].allow_sleep && !driven && b.v[i].squaredNorm() < lin2 &&
                             b.w[i].squaredNorm() < ang2;
        b.sleep_time[i] = resting ? b.sleep_time[i] + dt : 0;
        longest_rest = std::max(longest_rest, b.sleep_time[i]);
    }
    // An island sleeps only when all its bodies rested long enough: while no body has,
    // there is no island to find.
    if (longest_rest < sleep.time_to_sleep) return;

    // Islands over the awake bodies (positions in world.awake).
    const auto n = static_cast<std::uint32_t>(world.awake.size());
    std::vector<std::uint32_t>& parent = world.scratch_parent;
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0u);
    // Kinematic bodies join no island (they would join everything they carry into one);
    // their links to dynamic bodies are kept to hold those islands awake while they move.
    std::vector<std::pair<std::uint32_t, std::uint32_t>>& kinematic_links = world.scratch_kinematic_links;
    kinematic_links.clear();
    auto link = [&](std::uint32_t slot_a, std::uint32_t slot_b) {
        const std::int32_t ia = b.awake_index[slot_a], ib = b.awake_index[slot_b];
        if (ia < 0 || ib < 0) return;
        const auto pa = static_cast<std::uint32_t>(ia), pb = static_cast<std::uint32_t>(ib);
        const MotionType ta = b.type[slot_a], tb = b.type[slot_b];
        if (ta == MotionType::Dynamic && tb == MotionType::Dynamic) {
            unite(parent, pa, pb);
        } else if (ta == MotionType::Dynamic && tb == MotionType::Kinematic) {
            kinematic_links.emplace_back(pa, pb);
        } else if (ta == MotionType::Kinematic && tb == MotionType::Dynamic) {
            kinematic_links.emplace_back(pb, pa);
        }
    };
    for (std::uint32_t c : awake_contacts(world)) {
        const Contact& contact = world.contacts[c];
        if (touching(contact)) link(contact.body_a, contact.body_b);
    }
    for (std::uint32_t j : awake_joints(world)) link(joints.joint[j].body_a, joints.joint[j].body_b);
    // An island sleeps when its least-rested body has rested long enough.
    std::vector<Real>& min_rest = world.scratch_rest;
    min_rest.assign(n, kHuge);
    for (std::uint32_t k = 0; k < n; ++k) {
        const std::uint32_t r = find(parent, k);
        min_rest[r] = std::min(min_rest[r], b.sleep_time[world.awake[k]]);
    }
    // An island touching a kinematic body sleeps only when that body sleeps too (so, never
    // while it moves): a kinematic body alone is an island, its rest is its own.
    for (const auto& [dynamic, kinematic] : kinematic_links) {
        const std::uint32_t r = find(parent, dynamic);
        min_rest[r] = std::min(min_rest[r], b.sleep_time[world.awake[kinematic]]);
    }
    std::vector<std::uint32_t>& sleepers = world.scratch_sleepers;
    sleepers.clear();
    for (std::uint32_t k = 0; k < n; ++k) {
        if (min_rest[find(parent, k)] >= sleep.time_to_sleep) sleepers.push_back(k);
    }
    if (sleepers.empty()) return;

    // Group sleepers by island root; each becomes a SleepingIsland.
    std::vector<std::int32_t>& island_of_root = world.scratch_island_of_root;
    island_of_root.assign(n, -1);
    std::vector<std::uint32_t> slots;
    for (std::uint32_t k : sleepers) slots.push_back(world.awake[k]);
    for (std::size_t s = 0; s < sleepers.size(); ++s) {
        const std::uint32_t root = find(parent, sleepers[s]);
        if (island_of_root[root] < 0) {
            std::int32_t id;
            if (!world.free_islands.empty()) {
                id = world.free_islands.back();
                world.free_islands.pop_back();
            } else {
                id = static_cast<std::int32_t>(world.sleeping_islands.size());
                world.sleeping_islands.emplace_back();
            }
            island_of_root[root] = id;
        }
        const std::uint32_t slot = slots[s];
        world.sleeping_islands[static_cast<std::size_t>(island_of_root[root])].bodies.push_back(slot);
        b.island[slot] = island_of_root[root];
    }
    for (std::uint32_t slot : slots) {
        set_awake(world, slot, false);
        b.v[slot] = Vec3::Zero();
        b.w[slot] = Vec3::Zero();
        b.reset_history(slot);  // blend nothing while asleep: both steps hold the resting pose
        world.changed_now.push_back(slot);
    }
    settle_awake(world);
    // Contacts with no awake partner left sleep with their island.
    for (std::uint32_t c : awake_contacts(world)) {
        Contact& contact = world.contacts[c];
        if (b.awake_index[contact.body_a] >= 0 || b.awake_index[contact.body_b] >= 0) continue;
        contact.sleeping = true;
        // Recorded in both islands when they differ, so waking either revives it.
        const std::int32_t ia = b.island[contact.body_a], ib = b.island[contact.body_b];
        if (ia >= 0) world.sleeping_islands[static_cast<std::size_t>(ia)].contacts.push_back(world.contact_keys[c]);
        if (ib >= 0 && ib != ia) {
            world.sleeping_islands[static_cast<std::size_t>(ib)].contacts.push_back(world.contact_keys[c]);
        }
    }
    world.awake_contacts_dirty = true;
    // Joints likewise, so a sleeping island's joints cost nothing until it wakes.
    for (std::uint32_t j : awake_joints(world)) {
        Joint& joint = joints.joint[j];
        if (b.awake_index[joint.body_a] >= 0 || b.awake_index[joint.body_b] >= 0) continue;
        joint.sleeping = true;
        joints.awake_dirty = true;  // read on the next call: this loop's list stays as it is
        const std::int32_t ia = b.island[joint.body_a], ib = b.island[joint.body_b];
        if (ia >= 0) world.sleeping_islands[static_cast<std::size_t>(ia)].joints.push_back(joints.handle(j));
        if (ib >= 0 && ib != ia)
            world.sleeping_islands[static_cast<std::size_t>(ib)].joints.push_back(joints.handle(j));
    }
}

}  // namespace spindle
