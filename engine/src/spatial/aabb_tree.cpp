// DynamicAabbTree incremental updates: node pool, SAH sibling search, insert/remove with
// rotations on the way up, moves in place, and the validation walk. rebuild() and
// rebuild_enlarged() are in aabb_tree_build.cpp.
#include "spatial/aabb_tree.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <tuple>

// Checks in validate() run in every build type: validate() is only called when asked for.
#define SPINDLE_TREE_CHECK(cond, message)                                          \
    do {                                                                           \
        if (!(cond)) ::spindle::assert_failed(#cond, message, __FILE__, __LINE__); \
    } while (false)

namespace spindle {
namespace {

// Child heights may differ by this much before a rotation must rebalance. 1 is AVL
// (height <= 1.44 log2 n); 2 leaves SAH rotations more room (a lower SAH cost for a
// slightly taller tree) and still bounds the height by about 1.8 log2 n.
constexpr int kMaxImbalance = 2;

bool is_finite_box(const Aabb& box) { return is_finite(box.min) && is_finite(box.max) && box.valid(); }

}  // namespace

DynamicAabbTree::DynamicAabbTree(AabbTreeSettings settings) : m_settings(settings) {
    SPINDLE_ASSERT(settings.margin >= 0 && settings.displacement_multiplier >= 0,
                   "DynamicAabbTree: margin and displacement multiplier must be >= 0");
}

std::int32_t DynamicAabbTree::allocate_node() {
    std::int32_t id;
    if (m_free_list != kNull) {
        id = m_free_list;
        m_free_list = m_nodes[static_cast<std::size_t>(id)].parent_or_next;
        --m_free_count;
    } else {
        id = static_cast<std::int32_t>(m_nodes.size());
        m_nodes.emplace_back();
        m_enlarged.push_back(0);
    }
    Node& node = m_nodes[static_cast<std::size_t>(id)];
    node.parent_or_next = kNull;
    node.height = 0;
    node.payload.children = {kNull, kNull};
    forget_child_boxes();
    return id;
}

void DynamicAabbTree::free_node(std::int32_t id) {
    Node& node = m_nodes[static_cast<std::size_t>(id)];
    node.height = kFreeHeight;
    node.parent_or_next = m_free_list;
    forget_child_boxes();
    if (m_enlarged[static_cast<std::size_t>(id)] != 0) {
        m_enlarged[static_cast<std::size_t>(id)] = 0;
        --m_enlarged_nodes;
    }
    m_free_list = id;
    ++m_free_count;
}

Aabb DynamicAabbTree::fatten(const Aabb& tight, const Vec3& displacement, Real margin) const {
    Aabb fat = tight.fattened(margin);
    const Vec3 d = displacement * m_settings.displacement_multiplier;
    for (int k = 0; k < 3; ++k) {
        if (d[k] < 0) {
            fat.min[k] += d[k];
        } else {
            fat.max[k] += d[k];
        }
    }
    return fat;
}

std::int32_t DynamicAabbTree::create_proxy(const Aabb& tight, std::uint64_t user, Real margin) {
    SPINDLE_ASSERT(is_finite_box(tight), "DynamicAabbTree::create_proxy: box must be finite with min <= max");
    SPINDLE_ASSERT(margin >= 0 && is_finite(margin), "DynamicAabbTree::create_proxy: margin must be finite and >= 0");
    const std::int32_t id = allocate_node();
    Node& node = m_nodes[static_cast<std::size_t>(id)];
    node.box = fatten(tight, Vec3::Zero(), margin);
    node.payload.user = user;
    node.height = 0;
    insert_leaf(id);
    ++m_proxy_count;
    validate_if_enabled();
    return id;
}

void DynamicAabbTree::create_proxies(std::span<const Aabb> tight, std::span<const std::uint64_t> user,
                                     std::span<std::int32_t> ids, JobSystem* jobs) {
    SPINDLE_ASSERT(user.size() == tight.size() && ids.size() == tight.size(),
                   "DynamicAabbTree::create_proxies: one user value and one id per box");
    for (const Aabb& box : tight) {
        SPINDLE_ASSERT(is_finite_box(box), "DynamicAabbTree::create_proxies: boxes must be finite with min <= max");
    }
    if (tight.empty()) return;
    // The build's leaves and internal nodes: the tree's own (read before any node is
    // allocated: a new one starts as a leaf), then the new ones.
    const std::size_t leaves = static_cast<std::size_t>(m_proxy_count) + tight.size();
    m_build_leaves.clear();
    m_build_pool.clear();
    m_build_leaves.reserve(leaves);
    m_build_pool.reserve(leaves - 1);
    for (std::size_t i = 0; i < m_nodes.size(); ++i) {
        const std::int32_t height = m_nodes[i].height;
        if (height == 0) m_build_leaves.push_back(static_cast<std::int32_t>(i));
        if (height > 0) m_build_pool.push_back(static_cast<std::int32_t>(i));
        m_enlarged[i] = 0;
    }
    m_enlarged_nodes = 0;
    m_stale_boxes = false;
    // One internal node per new leaf, one fewer in an empty tree.
    const std::size_t internal = m_proxy_count == 0 ? tight.size() - 1 : tight.size();
    m_nodes.reserve(m_nodes.size() + tight.size() + internal);
    m_enlarged.reserve(m_nodes.capacity());
    for (std::size_t k = 0; k < tight.size(); ++k) {
        const std::int32_t id = allocate_node();
        Node& node = m_nodes[static_cast<std::size_t>(id)];
        node.box = fatten(tight[k], Vec3::Zero(), m_settings.margin);
        node.payload.user = user[k];
        ids[k] = id;
        m_build_leaves.push_back(id);
    }
    for (std::size_t k = 0; k < internal; ++k) {
        const std::int32_t id = allocate_node();
        m_nodes[static_cast<std::size_t>(id)].height = 1;  // internal: the build fits it
        m_build_pool.push_back(id);
    }
    m_proxy_count += static_cast<std::int32_t>(tight.size());
    build_from_leaves(jobs);
    m_built_cost = build_cost();
    // Once, not every step: the scratch is not kept at the size of the whole tree.
    m_build_leaves = {};
    m_build_pool = {};
    m_build_order = {};
    validate_if_enabled();
}

void DynamicAabbTree::destroy_proxy(std::int32_t id) {
    check_proxy(id);
    remove_leaf(id);
    free_node(id);
    --m_proxy_count;
    validate_if_enabled();
}

bool DynamicAabbTree::needs_move(std::int32_t id, const Aabb& tight, const Vec3& displacement, Real margin) const {
    check_proxy(id);
    const Aabb& box = m_nodes[static_cast<std::size_t>(id)].box;
    if (!box.contains(tight)) return true;
    // Keep the old fat box unless it is far bigger than wanted (a fast body slowed
    // down): the slack scales with the motion so a steadily moving body re-inserts
    // only when it leaves its box, not every step.
    const Real slack = 4 * margin + m_settings.displacement_multiplier * displacement.cwiseAbs().maxCoeff();
    return !fatten(tight, displacement, margin).fattened(slack).contains(box);
}

bool DynamicAabbTree::move_proxy(std::int32_t id, const Aabb& tight, const Vec3& displacement, Real margin) {
    check_proxy(id);
    SPINDLE_ASSERT(is_finite_box(tight) && is_finite(displacement),
                   "DynamicAabbTree::move_proxy: box and displacement must be finite");
    SPINDLE_ASSERT(margin >= 0 && is_finite(margin), "DynamicAabbTree::move_proxy: margin must be finite and >= 0");
    if (!needs_move(id, tight, displacement, margin)) return false;
    m_nodes[static_cast<std::size_t>(id)].box = fatten(tight, displacement, margin);
    m_child_boxes_current = false;
    enlarge_ancestors(id);
    validate_if_enabled();
    return true;
}

void DynamicAabbTree::set_fat_box(std::int32_t id, const Aabb& fat) {
    check_proxy(id);
    SPINDLE_ASSERT(is_finite_box(fat), "DynamicAabbTree::set_fat_box: box must be finite with min <= max");
    m_nodes[static_cast<std::size_t>(id)].box = fat;
    m_child_boxes_current = false;
    flag_ancestors(id);
    m_stale_boxes = m_stale_boxes || id != m_root;  // a lone leaf has no ancestor to go stale
    validate_if_enabled();
}

// Flags the path from a leaf to the root; a flagged node's parent is flagged already, so
// the walk stops at the first one (many moves share the upper part of their paths).
void DynamicAabbTree::flag_ancestors(std::int32_t leaf) {
    for (std::int32_t id = m_nodes[static_cast<std::size_t>(leaf)].parent_or_next; id != kNull;
         id = m_nodes[static_cast<std::size_t>(id)].parent_or_next) {
        std::uint8_t& flag = m_enlarged[static_cast<std::size_t>(id)];
        if (flag != 0) return;
        flag = 1;
        ++m_enlarged_nodes;
    }
}

std::int32_t DynamicAabbTree::set_fat_box_shared(std::int32_t id, const Aabb& fat) {
    check_proxy(id);
    SPINDLE_ASSERT(is_finite_box(fat), "DynamicAabbTree::set_fat_box_shared: box must be finite with min <= max");
    m_nodes[static_cast<std::size_t>(id)].box = fat;
    return flag_ancestors_shared(id);
}

void DynamicAabbTree::end_shared_fat_boxes(std::int32_t flagged, std::int32_t boxes_set) {
    m_enlarged_nodes += flagged;
    if (boxes_set > 0) m_child_boxes_current = false;
    // As set_fat_box: only a lone leaf (the root) has no ancestor to go stale.
    if (boxes_set > 0 && m_nodes[static_cast<std::size_t>(m_root)].height > 0) m_stale_boxes = true;
    validate_if_enabled();
}

// flag_ancestors for many leaves on many threads: a node is flagged by the one walk whose
// exchange found it clear; a walk that finds it flagged stops, as the walk that flagged it
// goes on to the root.
std::int32_t DynamicAabbTree::flag_ancestors_shared(std::int32_t leaf) {
    std::int32_t flagged = 0;
    for (std::int32_t id = m_nodes[static_cast<std::size_t>(leaf)].parent_or_next; id != kNull;
         id = m_nodes[static_cast<std::size_t>(id)].parent_or_next) {
        std::atomic_ref<std::uint8_t> flag(m_enlarged[static_cast<std::size_t>(id)]);
        if (flag.load(std::memory_order_relaxed) != 0 || flag.exchange(1, std::memory_order_relaxed) != 0) break;
        ++flagged;
    }
    return flagged;
}

// Box2D v3's answer to many moving proxies (b2DynamicTree_EnlargeProxy): a remove and an
// SAH re-insert per proxy costs a sibling search and rotations each, while growing the
// ancestors costs a few box merges, and one rebuild of the flagged part per step sorts
// them all out together. Ancestors are flagged even when they already hold the box (a
// fat box that shrank): the rebuild refits them.
void DynamicAabbTree::enlarge_ancestors(std::int32_t leaf) {
    const Aabb box = m_nodes[static_cast<std::size_t>(leaf)].box;
    bool growing = true;
    for (std::int32_t id = m_nodes[static_cast<std::size_t>(leaf)].parent_or_next; id != kNull;
         id = m_nodes[static_cast<std::size_t>(id)].parent_or_next) {
        Node& node = m_nodes[static_cast<std::size_t>(id)];
        if (growing) {
            if (node.box.contains(box)) {
                growing = false;
            } else {
                node.box = node.box.merged(box);
            }
        }
        std::uint8_t& flag = m_enlarged[static_cast<std::size_t>(id)];
        if (flag != 0) {
            if (!growing) return;  // the ancestors above are flagged and hold this node's box
            continue;
        }
        flag = 1;
        ++m_enlarged_nodes;
    }
}

// Greedy branch and bound for the sibling that adds the least area to the tree. Making
// node S the sibling of the new box D costs area(S u D) plus the growth of every
// ancestor of S. Below a node with inherited growth I, no descendant of child C costs
// less than I + area(C u D) - area(C) + area(D), so a child whose bound is already worse
// than the best found is not entered. Follows one path; ties go to the nearer child.
std::int32_t DynamicAabbTree::find_best_sibling(const Aabb& box) const {
    const Real area_new = box.perimeter();
    const Vec3 center_new = box.center();

    std::int32_t best = m_root;
    Real best_cost = m_nodes[static_cast<std::size_t>(m_root)].box.merged(box).perimeter();
    Real inherited = 0;
    std::int32_t current = m_root;
    while (m_nodes[static_cast<std::size_t>(current)].height > 0) {
        const Node& node = m_nodes[static_cast<std::size_t>(current)];
        inherited += node.box.merged(box).perimeter() - node.box.perimeter();

        const std::int32_t child[2] = {node.payload.children.first, node.payload.children.second};
        Real lower_bound[2];
        for (int k = 0; k < 2; ++k) {
            const Node& c = m_nodes[static_cast<std::size_t>(child[k])];
            const Real direct = c.box.merged(box).perimeter();
            const Real cost = direct + inherited;
            if (cost < best_cost) {
                best_cost = cost;
                best = child[k];
            }
            lower_bound[k] = c.height == 0 ? kHuge
                                           : inherited + direct + std::min(area_new - c.box.perimeter(), Real(0));
        }
        if (best_cost <= lower_bound[0] && best_cost <= lower_bound[1]) break;
        if (lower_bound[0] == lower_bound[1]) {
            // Both children contain the box (equal bounds): go towards the nearer centre.
            lower_bound[0] = (m_nodes[static_cast<std::size_t>(child[0])].box.center() - center_new).squaredNorm();
            lower_bound[1] = (m_nodes[static_cast<std::size_t>(child[1])].box.center() - center_new).squaredNorm();
        }
        current = lower_bound[0] < lower_bound[1] ? child[0] : child[1];
    }
    return best;
}

void DynamicAabbTree::insert_leaf(std::int32_t leaf) {
    forget_child_boxes();
    if (m_root == kNull) {
        m_root = leaf;
        m_nodes[static_cast<std::size_t>(leaf)].parent_or_next = kNull;
        return;
    }
    const std::int32_t sibling = find_best_sibling(m_nodes[static_cast<std::size_t>(leaf)].box);
    const std::int32_t parent = allocate_node();  // may reallocate m_nodes: no references held across it
    Node& s = m_nodes[static_cast<std::size_t>(sibling)];
    Node& l = m_nodes[static_cast<std::size_t>(leaf)];
    Node& p = m_nodes[static_cast<std::size_t>(parent)];
    const std::int32_t grand = s.parent_or_next;
    p.parent_or_next = grand;
    p.payload.children = {sibling, leaf};
    p.box = s.box.merged(l.box);
    p.height = s.height + 1;
    // A flagged node's parent is flagged: the new parent takes the sibling's flag (the
    // grandparent has it already if the sibling had).
    if (m_enlarged[static_cast<std::size_t>(sibling)] != 0) {
        m_enlarged[static_cast<std::size_t>(parent)] = 1;
        ++m_enlarged_nodes;
    }
    s.parent_or_next = parent;
    l.parent_or_next = parent;
    if (grand == kNull) {
        m_root = parent;
    } else {
        Children& gc = m_nodes[static_cast<std::size_t>(grand)].payload.children;
        (gc.first == sibling ? gc.first : gc.second) = parent;
    }
    refit_upwards(parent);
}

void DynamicAabbTree::remove_leaf(std::int32_t leaf) {
    forget_child_boxes();
    if (leaf == m_root) {
        m_root = kNull;
        return;
    }
    const std::int32_t parent = m_nodes[static_cast<std::size_t>(leaf)].parent_or_next;
    const Node& p = m_nodes[static_cast<std::size_t>(parent)];
    const std::int32_t grand = p.parent_or_next;
    const std::int32_t sibling = p.payload.children.first == leaf ? p.payload.children.second
                                                                  : p.payload.children.first;
    m_nodes[static_cast<std::size_t>(sibling)].parent_or_next = grand;
    m_nodes[static_cast<std::size_t>(leaf)].parent_or_next = kNull;
    free_node(parent);
    if (grand == kNull) {
        m_root = sibling;
        return;
    }
    Children& gc = m_nodes[static_cast<std::size_t>(grand)].payload.children;
    (gc.first == parent ? gc.first : gc.second) = sibling;
    refit_upwards(grand);
}

void DynamicAabbTree::refit(std::int32_t id) {
    Node& node = m_nodes[static_cast<std::size_t>(id)];
    const Node& a = m_nodes[static_cast<std::size_t>(node.payload.children.first)];
    const Node& b = m_nodes[static_cast<std::size_t>(node.payload.children.second)];
    node.box = a.box.merged(b.box);
    node.height = 1 + std::max(a.height, b.height);
}

// Everything below `id` is fitted and balanced; fix each ancestor in turn. A rotation
// at a node looks only at its children and grandchildren, so once a node kept its box,
// height and children and so did the child below it, nothing above has new input and
// the walk stops (most moves change only the lowest few levels).
void DynamicAabbTree::refit_upwards(std::int32_t id) {
    bool below_changed = true;  // the walk starts at a node whose children were just replaced
    while (id != kNull) {
        Node& node = m_nodes[static_cast<std::size_t>(id)];
        const Aabb old_box = node.box;
        const std::int32_t old_height = node.height;
        const bool rotated = rotate(id);
        refit(id);
        const bool changed = node.height != old_height || node.box.min != old_box.min || node.box.max != old_box.max;
        if (!rotated && !changed && !below_changed) return;
        below_changed = changed;
        id = node.parent_or_next;
    }
}

// Node A = (B, C). A rotation swaps one child of A (X) with a grandchild (Y) under the
// other child (O = (Y, Z)), giving A = (Y, O'), O' = (X, Z). A's box is unchanged; O's
// area changes. BVH children have no order, so a single swap can always lift the taller
// grandchild: that gives AVL-like height bounds without double rotations.
//  - If A is out of balance (child heights differ by more than kMaxImbalance), take the
//    swap that lowers A's height, or else its imbalance; ties go to the smaller area.
//  - Otherwise take the swap that shrinks O's area the most (the SAH rotation), only if
//    it keeps A's height and leaves A and O' in balance, so area never costs height.
bool DynamicAabbTree::rotate(std::int32_t a) {
    const Node& node_a = m_nodes[static_cast<std::size_t>(a)];
    if (node_a.height < 2) return false;
    const std::int32_t b = node_a.payload.children.first;
    const std::int32_t c = node_a.payload.children.second;
    auto h = [this](std::int32_t id) { return m_nodes[static_cast<std::size_t>(id)].height; };
    const int height_now = 1 + std::max(h(b), h(c));
    const int imbalance_now = std::abs(h(b) - h(c));
    const bool must_balance = imbalance_now > kMaxImbalance;

    struct Swap {
        std::int32_t x, y, o;
        int height, imbalance;
        Real delta;
    };
    Swap best{kNull, kNull, kNull, 0, 0, 0};
    auto consider = [&](std::int32_t x, std::int32_t o) {
        const Node& node_o = m_nodes[static_cast<std::size_t>(o)];
        if (node_o.height == 0) return;
        const std::int32_t grand[2] = {node_o.payload.children.first, node_o.payload.children.second};
        for (int k = 0; k < 2; ++k) {
            const std::int32_t y = grand[k];
            const std::int32_t z = grand[1 - k];
            const int height_o = 1 + std::max(h(x), h(z));
            const Swap s{
                x,
                y,
                o,
                1 + std::max(h(y), height_o),
                std::abs(h(y) - height_o),
                m_nodes[static_cast<std::size_t>(x)].box.merged(m_nodes[static_cast<std::size_t>(z)].box).perimeter() -
                    node_o.box.perimeter()};
            bool acceptable;
            bool better;
            if (must_balance) {
                acceptable = s.height < height_now || (s.height == height_now && s.imbalance < imbalance_now);
                better = best.x == kNull ||
                         std::tie(s.height, s.imbalance, s.delta) < std::tie(best.height, best.imbalance, best.delta);
            } else {
                acceptable = s.delta < 0 && s.height <= height_now && s.imbalance <= kMaxImbalance &&
                             std::abs(h(x) - h(z)) <= kMaxImbalance;
                better = best.x == kNull || s.delta < best.delta;
            }
            if (acceptable && better) best = s;
        }
    };
    consider(b, c);
    consider(c, b);
    if (best.x == kNull) return false;

    Children& ac = m_nodes[static_cast<std::size_t>(a)].payload.children;
    (ac.first == best.x ? ac.first : ac.second) = best.y;
    Children& oc = m_nodes[static_cast<std::size_t>(best.o)].payload.children;
    (oc.first == best.y ? oc.first : oc.second) = best.x;
    m_nodes[static_cast<std::size_t>(best.x)].parent_or_next = best.o;
    m_nodes[static_cast<std::size_t>(best.y)].parent_or_next = a;
    // X now hangs under O: a flagged X needs a flagged O (A, X's old parent, is flagged).
    if (m_enlarged[static_cast<std::size_t>(best.x)] != 0 && m_enlarged[static_cast<std::size_t>(best.o)] == 0) {
        m_enlarged[static_cast<std::size_t>(best.o)] = 1;
        ++m_enlarged_nodes;
    }
    refit(best.o);
    return true;
}

std::size_t DynamicAabbTree::heap_bytes() const noexcept {
    std::size_t bytes = m_nodes.capacity() * sizeof(Node) + m_child_boxes.capacity() * sizeof(ChildBoxes) +
                        m_enlarged.capacity() * sizeof(std::uint8_t) +
                        m_build_leaves.capacity() * sizeof(std::int32_t) +
                        (m_build_tasks.capacity() + m_build_subtrees.capacity()) * sizeof(BuildTask) +
                        (m_build_order.capacity() + m_build_pool.capacity()) * sizeof(std::int32_t) +
                        m_build_stacks.capacity() * sizeof(std::vector<BuildTask>);
    for (const std::vector<BuildTask>& stack : m_build_stacks) bytes += stack.capacity() * sizeof(BuildTask);
    return bytes;
}

void DynamicAabbTree::make_child_boxes(JobSystem* jobs) {
    SPINDLE_ASSERT(!m_stale_boxes, "DynamicAabbTree::make_child_boxes: rebuild_enlarged has not run");
    m_child_boxes.resize(m_nodes.size());
    const auto make = [this](std::uint32_t begin, std::uint32_t end, unsigned) {
        for (std::uint32_t id = begin; id < end; ++id) {
            // Leaves and free nodes have none.
            if (m_nodes[id].height > 0) make_child_boxes_of(static_cast<std::int32_t>(id));
        }
    };
    run_child_box_pass(jobs, static_cast<std::uint32_t>(m_nodes.size()), make);
    m_child_boxes_kept = m_child_boxes_current = true;
    validate_if_enabled();
}

void DynamicAabbTree::run_child_box_pass(JobSystem* jobs, std::uint32_t count, RangeFn make) {
    if (jobs != nullptr && count > kChildBoxesGrain) {
        jobs->parallel_for("broadphase.child_boxes", 0, count, kChildBoxesGrain, make);
    } else {
        make(0, count, 0);
    }
}

Real DynamicAabbTree::area_cost() const {
    Real sum = 0;
    for (const Node& node : m_nodes) {
        if (node.height > 0) sum += node.box.perimeter();
    }
    return sum;
}

void DynamicAabbTree::validate() const {
    const auto node_count = static_cast<std::int32_t>(m_nodes.size());
    std::int32_t reached = 0;
    std::int32_t leaves = 0;
    std::int32_t flagged = 0;
    SPINDLE_TREE_CHECK(m_enlarged.size() == m_nodes.size(), "tree: flags and nodes differ in number");
    if (m_root != kNull) {
        SPINDLE_TREE_CHECK(m_root >= 0 && m_root < node_count, "tree: root out of range");
        SPINDLE_TREE_CHECK(m_nodes[static_cast<std::size_t>(m_root)].parent_or_next == kNull,
                           "tree: root has a parent");
        TraversalStack stack;
        stack.push(m_root);
        while (!stack.empty()) {
            const std::int32_t id = stack.pop();
            const Node& node = m_nodes[static_cast<std::size_t>(id)];
            ++reached;
            SPINDLE_TREE_CHECK(reached <= node_count, "tree: cycle (more nodes reached than exist)");
            SPINDLE_TREE_CHECK(node.height >= 0, "tree: a node on the free list is reachable from the root");
            SPINDLE_TREE_CHECK(node.box.valid(), "tree: node box has min > max");
            if (m_enlarged[static_cast<std::size_t>(id)] != 0) {
                ++flagged;
                SPINDLE_TREE_CHECK(node.height > 0, "tree: a leaf is flagged enlarged");
                SPINDLE_TREE_CHECK(node.parent_or_next == kNull ||
                                       m_enlarged[static_cast<std::size_t>(node.parent_or_next)] != 0,
                                   "tree: a flagged node's parent is not flagged");
            }
            if (node.height == 0) {
                ++leaves;
                continue;
            }
            const std::int32_t c[2] = {node.payload.children.first, node.payload.children.second};
            for (const std::int32_t child : c) {
                SPINDLE_TREE_CHECK(child >= 0 && child < node_count, "tree: child index out of range");
                const Node& cn = m_nodes[static_cast<std::size_t>(child)];
                SPINDLE_TREE_CHECK(cn.parent_or_next == id, "tree: child does not point back to its parent");
                // set_fat_box() leaves flagged nodes short of their children until the rebuild.
                const bool stale = m_stale_boxes && m_enlarged[static_cast<std::size_t>(id)] != 0;
                SPINDLE_TREE_CHECK(stale || node.box.contains(cn.box), "tree: node box does not contain a child box");
                stack.push(child);
            }
            SPINDLE_TREE_CHECK(c[0] != c[1], "tree: both children are the same node");
            // Kept boxes are right but for the flagged nodes, which the next rebuild makes again.
            if (m_child_boxes_current || (m_child_boxes_kept && m_enlarged[static_cast<std::size_t>(id)] == 0)) {
                const ChildBoxes& children = m_child_boxes[static_cast<std::size_t>(id)];
                for (int k = 0; k < 2; ++k) {
                    const Node& cn = m_nodes[static_cast<std::size_t>(c[k])];
                    SPINDLE_TREE_CHECK(children.entry[k] == (cn.height == 0 ? ~c[k] : c[k]),
                                       "tree: a child box's entry is not its child");
                    for (int axis = 0; axis < 3; ++axis) {
                        SPINDLE_TREE_CHECK(children.min[3 * k + axis] == static_cast<float>(cn.box.min[axis]) &&
                                               children.max[3 * k + axis] == static_cast<float>(cn.box.max[axis]),
                                           "tree: a child's float box is not its box");
                    }
                }
            }
            const int expected = 1 + std::max(m_nodes[static_cast<std::size_t>(c[0])].height,
                                              m_nodes[static_cast<std::size_t>(c[1])].height);
            SPINDLE_TREE_CHECK(node.height == expected, "tree: height is not 1 + the taller child");
        }
    }
    SPINDLE_TREE_CHECK(leaves == m_proxy_count, "tree: leaf count differs from proxy count");
    SPINDLE_TREE_CHECK(flagged == m_enlarged_nodes, "tree: flagged node count differs from the nodes flagged");

    std::int32_t free_nodes = 0;
    for (std::int32_t id = m_free_list; id != kNull; id = m_nodes[static_cast<std::size_t>(id)].parent_or_next) {
        SPINDLE_TREE_CHECK(id >= 0 && id < node_count, "tree: free list index out of range");
        SPINDLE_TREE_CHECK(m_nodes[static_cast<std::size_t>(id)].height == kFreeHeight,
                           "tree: a used node is on the free list");
        ++free_nodes;
        SPINDLE_TREE_CHECK(free_nodes <= node_count, "tree: cycle in the free list");
    }
    SPINDLE_TREE_CHECK(free_nodes == m_free_count, "tree: free list length differs from the free count");
    SPINDLE_TREE_CHECK(reached + free_nodes == node_count, "tree: nodes lost (neither reachable nor free)");
    SPINDLE_TREE_CHECK(m_proxy_count == 0 || reached == 2 * m_proxy_count - 1, "tree: not a full binary tree");
}

}  // namespace spindle
