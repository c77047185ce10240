// DynamicAabbTree::rebuild and rebuild_enlarged: top-down binned SAH builds over the
// existing leaves (all of them, for trees filled in bulk), or over the subtrees that hang
// off the paths moves flagged. Leaves stay where they are, so proxy ids survive.
#include "spatial/aabb_tree.hpp"

#include <algorithm>
#include <array>

namespace spindle {
namespace {

// Sixteen bins find a split within a few percent of the full sweep's SAH cost at a
// fraction of its price (Wald 2007).
constexpr int kBinCount = 16;

}  // namespace

void DynamicAabbTree::rebuild() {
    // Every internal node is built again, from the same nodes: the pool does not grow.
    m_build_leaves.clear();
    m_build_pool.clear();
    for (std::size_t i = 0; i < m_nodes.size(); ++i) {
        const Node& node = m_nodes[i];
        if (node.height == 0) {
            m_build_leaves.push_back(static_cast<std::int32_t>(i));
        } else if (node.height > 0) {
            m_build_pool.push_back(static_cast<std::int32_t>(i));
        }
        m_enlarged[i] = 0;
    }
    m_enlarged_nodes = 0;
    m_stale_boxes = false;
    forget_child_boxes();
    build_from_leaves(nullptr);
    m_built_cost = build_cost();
    validate_if_enabled();
}

// Walks the flagged nodes from `root` down in pre-order: appends them to `pool` (clearing
// their flags) and what hangs off them (a leaf or an unflagged subtree) to `leaves`. With
// `jobs_out`, a flagged node of height job_height or less is not walked but listed there.
void DynamicAabbTree::collect_flagged(std::int32_t root, std::vector<std::int32_t>& pool,
                                      std::vector<std::int32_t>& leaves, std::int32_t job_height,
                                      std::vector<WalkJob>* jobs_out) {
    TraversalStack stack;
    stack.push(root);
    while (!stack.empty()) {
        const std::int32_t id = stack.pop();
        const Node& node = m_nodes[static_cast<std::size_t>(id)];
        if (m_enlarged[static_cast<std::size_t>(id)] == 0) {
            leaves.push_back(id);
            continue;
        }
        if (jobs_out != nullptr && node.height <= job_height) {
            jobs_out->push_back({id, pool.size(), leaves.size()});
            continue;
        }
        stack.push(node.payload.children.second);
        stack.push(node.payload.children.first);
        m_enlarged[static_cast<std::size_t>(id)] = 0;
        pool.push_back(id);
    }
}

// The walk of rebuild_enlarged() with the subtrees below its top walked in jobs, each
// refitting its own flagged nodes (children first) while its nodes are in its cache; the
// top's nodes are refitted by rebuild_enlarged where it keeps the refit. A refit the build
// then replaces changes nothing it reads. The lists come out as the one walk makes them.
// Returns false (nothing done) for a tree too small or too little flagged for it.
bool DynamicAabbTree::collect_flagged_in_jobs(JobSystem& jobs) {
    const std::int32_t job_height = m_nodes[static_cast<std::size_t>(m_root)].height - kWalkJobLevels;
    if (jobs.worker_count() < 2 || m_enlarged_nodes < kWalkJobNodes || job_height < 1) return false;
    m_walk_jobs.clear();
    m_walk_top.clear();
    collect_flagged(m_root, m_walk_top, m_build_leaves, job_height, &m_walk_jobs);
    const auto count = static_cast<std::uint32_t>(m_walk_jobs.size());
    if (m_walk_pools.size() < count) {
        m_walk_pools.resize(count);
        m_walk_leaves.resize(count);
    }
    jobs.parallel_for("TreeWalk", 0, count, 1, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t k = lo; k < hi; ++k) {
            std::vector<std::int32_t>& pool = m_walk_pools[k];
            pool.clear();
            m_walk_leaves[k].clear();
            collect_flagged(m_walk_jobs[k].root, pool, m_walk_leaves[k], 0, nullptr);
            for (auto it = pool.rbegin(); it != pool.rend(); ++it) refit(*it);  // pre-order: children first
        }
    });
    // Each job's lists go where its subtree stood in the top's walk.
    const auto splice = [&](std::vector<std::int32_t>& top, std::vector<std::vector<std::int32_t>>& parts,
                            std::size_t WalkJob::*at, std::vector<std::int32_t>& out) {
        out.clear();
        std::size_t from = 0;
        for (std::uint32_t k = 0; k < count; ++k) {
            const std::size_t to = m_walk_jobs[k].*at;
            out.insert(out.end(), top.begin() + static_cast<std::ptrdiff_t>(from),
                       top.begin() + static_cast<std::ptrdiff_t>(to));
            out.insert(out.end(), parts[k].begin(), parts[k].end());
            from = to;
        }
        out.insert(out.end(), top.begin() + static_cast<std::ptrdiff_t>(from), top.end());
    };
    splice(m_walk_top, m_walk_pools, &WalkJob::pool_at, m_build_pool);
    splice(m_build_leaves, m_walk_leaves, &WalkJob::leaves_at, m_walk_spliced);
    m_build_leaves.swap(m_walk_spliced);
    return true;
}

void DynamicAabbTree::rebuild_enlarged(JobSystem* jobs) {
    if (m_enlarged_nodes == 0) {
        m_stale_boxes = false;  // only flagged nodes go stale
        m_child_boxes_current = m_child_boxes_kept;
        return;
    }
    // Flagged nodes form a tree from the root down (a flagged node's parent is flagged):
    // they are built again, and what hangs off them (a leaf or an unflagged subtree) is
    // kept whole.
    m_child_boxes_current = false;
    m_build_leaves.clear();
    m_build_pool.clear();
    const bool in_jobs = jobs != nullptr && collect_flagged_in_jobs(*jobs);
    if (!in_jobs) collect_flagged(m_root, m_build_pool, m_build_leaves, 0, nullptr);
    m_enlarged_nodes = 0;
    m_stale_boxes = false;
    const bool most = builds_most_of_tree();
    bool refitted = false;
    if (most && m_built_cost.leaves > 0) {
        // The pool is in pre-order: walking it backwards fits children first (the jobs' own
        // subtrees are fitted already).
        const std::vector<std::int32_t>& unfitted = in_jobs ? m_walk_top : m_build_pool;
        for (auto it = unfitted.rbegin(); it != unfitted.rend(); ++it) refit(*it);
        refitted = refit_holds(build_cost());
    }
    if (refitted) {
        ++m_refit_count;
    } else {
        build_from_leaves(jobs);
        if (most) m_built_cost = build_cost();
    }
    if (m_child_boxes_kept) remake_built_child_boxes(jobs);
    validate_if_enabled();
}

// After rebuild_enlarged's build or refit: the nodes it made (m_build_pool) are the only
// ones whose children or children's boxes changed since the moves (a kept subtree keeps
// its nodes, and a moved leaf's parent was flagged), so the kept float boxes are made
// again for those alone.
void DynamicAabbTree::remake_built_child_boxes(JobSystem* jobs) {
    const auto make = [this](std::uint32_t begin, std::uint32_t end, unsigned) {
        for (std::uint32_t k = begin; k < end; ++k) make_child_boxes_of(m_build_pool[k]);
    };
    run_child_box_pass(jobs, static_cast<std::uint32_t>(m_build_pool.size()), make);
    m_child_boxes_current = true;
}

// Whether the build in m_build_pool makes at least half of the internal nodes: only such
// builds are compared, as the quality of a small part says little about the whole.
bool DynamicAabbTree::builds_most_of_tree() const noexcept {
    return 2 * m_build_pool.size() + 1 >= static_cast<std::size_t>(m_proxy_count);
}

// The half areas of the nodes in m_build_pool and of the leaves in m_build_leaves, as they are now.
DynamicAabbTree::BuildCost DynamicAabbTree::build_cost() const {
    BuildCost cost;
    for (const std::int32_t id : m_build_pool) cost.nodes += m_nodes[static_cast<std::size_t>(id)].box.perimeter();
    for (const std::int32_t id : m_build_leaves) cost.leaves += m_nodes[static_cast<std::size_t>(id)].box.perimeter();
    return cost;
}

bool DynamicAabbTree::refit_holds(const BuildCost& refitted) const noexcept {
    return refitted.nodes <= kRefitSlack * m_built_cost.nodes &&
           refitted.nodes * m_built_cost.leaves <= kRefitSlack * m_built_cost.nodes * refitted.leaves;
}

// Places one range of build leaves: a leaf or kept subtree for one, else the pool node
// task.pool with the range split in two (pushed on `tasks`). In pre-order, a range of n
// leaves takes the n - 1 pool nodes from task.pool on, its own first: the result does not
// depend on which thread builds which range, and pool order is creation order.
std::int32_t DynamicAabbTree::place(const BuildTask& task, std::vector<BuildTask>& tasks) {
    std::int32_t id;
    if (task.end - task.begin == 1) {
        id = m_build_leaves[task.begin];
    } else {
        id = m_build_pool[task.pool];
        const std::uint32_t mid = partition_sah(task.begin, task.end);
        Node& node = m_nodes[static_cast<std::size_t>(id)];
        node.height = 1;  // internal; refit sets the height
        tasks.push_back({id, 1, mid, task.end, task.pool + (mid - task.begin)});
        tasks.push_back({id, 0, task.begin, mid, task.pool + 1});
    }
    m_nodes[static_cast<std::size_t>(id)].parent_or_next = task.parent;
    if (task.parent == kNull) {
        m_root = id;
    } else {
        Children& pc = m_nodes[static_cast<std::size_t>(task.parent)].payload.children;
        (task.slot == 0 ? pc.first : pc.second) = id;
    }
    return id;
}

// Builds internal nodes from m_build_pool over m_build_leaves (proxies or whole
// subtrees) and makes the result the tree's root. Iterative, so a degenerate split
// sequence cannot overflow the C++ stack. With jobs, the ranges of at most
// kSubtreeLeaves below the top are built as jobs, each fitting its own nodes.
void DynamicAabbTree::build_from_leaves(JobSystem* jobs) {
    m_root = kNull;
    const auto count = static_cast<std::uint32_t>(m_build_leaves.size());
    if (count == 0) return;
    SPINDLE_ASSERT(m_build_pool.size() + 1 == count, "DynamicAabbTree: a build needs one node fewer than leaves");
    const bool split = jobs != nullptr && jobs->worker_count() > 1 && count > 2 * kSubtreeLeaves;
    m_build_tasks.clear();
    m_build_subtrees.clear();
    m_build_order.clear();
    m_build_tasks.push_back({kNull, 0, 0, count, 0});
    while (!m_build_tasks.empty()) {
        const BuildTask task = m_build_tasks.back();
        m_build_tasks.pop_back();
        if (split && task.end - task.begin <= kSubtreeLeaves) {
            m_build_subtrees.push_back(task);
            continue;
        }
        const std::int32_t id = place(task, m_build_tasks);
        if (task.end - task.begin > 1) m_build_order.push_back(id);
    }
    if (!m_build_subtrees.empty()) {
        if (m_build_stacks.size() < jobs->worker_count()) m_build_stacks.resize(jobs->worker_count());
        // Each job writes only its range's leaves and pool nodes, and one child slot of a
        // top node; the top is fitted after them.
        jobs->parallel_for("TreeRebuild", 0, static_cast<std::uint32_t>(m_build_subtrees.size()), 1,
                           [&](std::uint32_t lo, std::uint32_t hi, unsigned worker) {
                               std::vector<BuildTask>& tasks = m_build_stacks[worker];
                               for (std::uint32_t k = lo; k < hi; ++k) {
                                   const BuildTask& subtree = m_build_subtrees[k];
                                   tasks.clear();
                                   tasks.push_back(subtree);
                                   while (!tasks.empty()) {
                                       const BuildTask task = tasks.back();
                                       tasks.pop_back();
                                       place(task, tasks);
                                   }
                                   // Pre-order: walking the range's pool nodes backwards fits children first.
                                   const std::uint32_t nodes = subtree.end - subtree.begin - 1;
                                   for (std::uint32_t i = nodes; i-- > 0;) refit(m_build_pool[subtree.pool + i]);
                               }
                           });
    }
    for (auto it = m_build_order.rbegin(); it != m_build_order.rend(); ++it) refit(*it);
}

// Splits m_build_leaves[begin, end) in two along the longest axis of the leaf centres,
// at the bin boundary with the least SAH cost (count x area on each side). Returns the
// first index of the right half; both halves are non-empty.
std::uint32_t DynamicAabbTree::partition_sah(std::uint32_t begin, std::uint32_t end) {
    const std::uint32_t count = end - begin;
    const std::uint32_t half = begin + count / 2;
    if (count == 2) return half;

    // Centres are read from the nodes, not kept beside the ids: the scratch of every tree
    // that moves is held at its high-water mark, a quarter of the tree's own bytes.
    auto center = [&](std::int32_t id) { return m_nodes[static_cast<std::size_t>(id)].box.center(); };
    Aabb centers;
    for (std::uint32_t i = begin; i < end; ++i) centers.include(center(m_build_leaves[i]));
    int axis;
    const Real extent = (centers.max - centers.min).maxCoeff(&axis);
    if (!(extent > 0)) return half;  // all centres equal: any split is as good, keep it balanced

    const Real lo = centers.min[axis];
    const Real scale = Real(kBinCount) / extent;
    auto bin_of = [&](const Vec3& c) { return std::min(kBinCount - 1, static_cast<int>((c[axis] - lo) * scale)); };

    struct Bin {
        Aabb box;
        std::uint32_t count = 0;
    };
    std::array<Bin, kBinCount> bins{};
    for (std::uint32_t i = begin; i < end; ++i) {
        const Aabb& leaf = m_nodes[static_cast<std::size_t>(m_build_leaves[i])].box;
        Bin& bin = bins[static_cast<std::size_t>(bin_of(leaf.center()))];
        bin.box = bin.box.merged(leaf);
        ++bin.count;
    }

    // right_cost[i]: cost of bins i.. on the right side of a split before bin i.
    std::array<Real, kBinCount> right_cost{};
    Aabb box;
    std::uint32_t n = 0;
    for (int i = kBinCount - 1; i > 0; --i) {
        box = box.merged(bins[static_cast<std::size_t>(i)].box);
        n += bins[static_cast<std::size_t>(i)].count;
        right_cost[static_cast<std::size_t>(i)] = n == 0 ? 0 : Real(n) * box.perimeter();
    }
    int best_split = -1;  // split before this bin
    Real best_cost = kHuge;
    box = Aabb{};
    n = 0;
    for (int i = 1; i < kBinCount; ++i) {
        box = box.merged(bins[static_cast<std::size_t>(i - 1)].box);
        n += bins[static_cast<std::size_t>(i - 1)].count;
        if (n == 0 || n == count) continue;
        const Real cost = Real(n) * box.perimeter() + right_cost[static_cast<std::size_t>(i)];
        if (cost < best_cost) {
            best_cost = cost;
            best_split = i;
        }
    }
    if (best_split < 0) return half;

    const auto first = m_build_leaves.begin() + static_cast<std::ptrdiff_t>(begin);
    const auto last = m_build_leaves.begin() + static_cast<std::ptrdiff_t>(end);
    const auto mid = std::partition(first, last, [&](std::int32_t id) { return bin_of(center(id)) < best_split; });
    const auto split = static_cast<std::uint32_t>(mid - m_build_leaves.begin());
    return split == begin || split == end ? half : split;
}

}  // namespace spindle
