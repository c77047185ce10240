// DynamicAabbTree: a bounding volume hierarchy over fattened AABBs, updated incrementally
// (insert by cheapest SAH sibling, rebalance by tree rotations), moved in place and
// rebuilt where moves enlarged it, or built in bulk.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>
#if defined(__AVX__)
#include <immintrin.h>
#endif

#include <spindle/engine/math.hpp>
#include <spindle/platform/assert.hpp>
#include <spindle/scheduler/job_system.hpp>

#include "memory/huge_page_vector.hpp"

namespace spindle {

struct AabbTreeSettings {
    // Added on every side of a proxy's tight box, so small motions do not touch the tree.
    Real margin = Real(0.1);
    // The fat box is also stretched by this times the displacement passed to move_proxy,
    // so a speculative contact finds its pair before the bodies get there.
    Real displacement_multiplier = Real(2);
    // Walk the whole tree after changes: after each one while the tree is small, then once
    // every n / 16 changes for n proxies (each walk is O(n)). On by default where
    // SPINDLE_VALIDATE is on.
    bool validate_after_changes = SPINDLE_VALIDATE_ENABLED != 0;
};

// Proxy ids are leaf node indices: stable for the proxy's life (moves and rebuild() keep
// them) and reused after destroy_proxy. Not thread safe for writes; query(), ray_cast()
// and the accessors are const and may run on many threads at once while nothing writes.
class DynamicAabbTree {
public:
    static constexpr std::int32_t kNull = -1;

    explicit DynamicAabbTree(AabbTreeSettings settings = {});

    // Adds a proxy whose fat box is `tight` grown by the margin (the settings' or, given,
    // its own). Returns its id.
    std::int32_t create_proxy(const Aabb& tight, std::uint64_t user) {
        return create_proxy(tight, user, m_settings.margin);
    }
    std::int32_t create_proxy(const Aabb& tight, std::uint64_t user, Real margin);
    // Adds many proxies at once: one for tight[k] (grown by the margin) with user[k], its
    // id written to ids[k]. The whole tree, old proxies and new, is then built top down
    // with rebuild()'s binned SAH, its lower parts as jobs when `jobs` is given (the same
    // tree for any worker count; the caller waits for them). For filling a tree with a
    // scene's bodies: one create_proxy each pays a sibling search and rotations per
    // proxy, and this a rebuild of the whole tree, so a few proxies go one at a time.
    // Old proxies keep their ids, fat boxes and user values.
    void create_proxies(std::span<const Aabb> tight, std::span<const std::uint64_t> user, std::span<std::int32_t> ids,
                        JobSystem* jobs = nullptr);
    void destroy_proxy(std::int32_t id);
    // Returns true when the proxy got a new fat box: when `tight` left the fat box, or
    // when the fat box is far bigger than needed (a fast body stopped). The new fat box
    // is `tight` grown by the margin and stretched along the displacement. The leaf stays
    // where it is: its ancestors grow to hold the new box and are flagged for
    // rebuild_enlarged(), which a caller moving a batch of proxies calls once after them
    // (queries stay exact before it, only slower).
    // Each of these takes the proxy's margin, or the settings' when none is given.
    bool move_proxy(std::int32_t id, const Aabb& tight, const Vec3& displacement) {
        return move_proxy(id, tight, displacement, m_settings.margin);
    }
    bool move_proxy(std::int32_t id, const Aabb& tight, const Vec3& displacement, Real margin);
    // Whether move_proxy(id, tight, displacement) would re-insert the proxy. Const: may
    // run on many threads at once while nothing writes.
    bool needs_move(std::int32_t id, const Aabb& tight, const Vec3& displacement) const {
        return needs_move(id, tight, displacement, m_settings.margin);
    }
    bool needs_move(std::int32_t id, const Aabb& tight, const Vec3& displacement, Real margin) const;
    // The fat box move_proxy gives a proxy whose tight box is `tight`. Const.
    Aabb fat_box(const Aabb& tight, const Vec3& displacement) const {
        return fatten(tight, displacement, m_settings.margin);
    }
    Aabb fat_box(const Aabb& tight, const Vec3& displacement, Real margin) const {
        return fatten(tight, displacement, margin);
    }
    // Gives a proxy a new fat box (from fat_box()) and flags its ancestors without growing
    // them: for a caller that moves many proxies and then calls rebuild_enlarged(), which
    // makes every flagged node's box from its children, so growing them move by move
    // would be wasted. Until that rebuild the ancestors' boxes are stale: query() and
    // ray_cast() must not run (they could miss the moved proxies).
    void set_fat_box(std::int32_t id, const Aabb& fat);
    // set_fat_box for many proxies from jobs at once: gives one proxy its box and flags its
    // ancestors, each flag taken by an atomic exchange, so a path shared with calls on other
    // threads is flagged once and the walk stops at a flagged node as set_fat_box's does.
    // Returns the number of nodes this call flagged. The ids must be distinct; nothing
    // else may touch the tree until end_shared_fat_boxes(sum of the returns, calls made)
    // counts the flags (the flags set are the same whatever the order of the calls).
    std::int32_t set_fat_box_shared(std::int32_t id, const Aabb& fat);
    void end_shared_fat_boxes(std::int32_t flagged, std::int32_t boxes_set);

    // Calls callback(id) -> bool for every proxy whose fat box overlaps `box`; false stops.
    // While the child boxes are current (make_child_boxes), the walk tests a node's two
    // children at once on their float boxes; the same proxies in the same order either way.
    template <typename Callback>
    void query(const Aabb& box, Callback&& callback) const;
    // As above, but skip(id) -> bool is asked first of each proxy the walk reaches, and one
    // it accepts is passed over without its box being read (a caller's own cheaper test).
    template <typename Skip, typename Callback>
    void query(const Aabb& box, Skip&& skip, Callback&& callback) const;
    // Calls report(a, b) once for every two proxies whose fat boxes overlap, a and b in the
    // walk's order: the tree walked against itself, each overlapping pair of nodes met once
    // (a query per proxy meets every pair twice, and walks down from the root for each).
    // `stack` is the walk's scratch. Returns false, having reported nothing, when the child
    // boxes are not current (make_child_boxes) or the tree is too tall for query()'s walk.
    template <typename Report>
    bool self_pairs(std::vector<std::pair<std::int32_t, std::int32_t>>& stack, Report&& report) const;
    // Makes every internal node's children's boxes in float, for query()'s walk. Worth it
    // when many queries follow (a pair search of many moved proxies): it reads every node.
    // With `jobs`, in parallel (the caller waits). They are kept from then on through moves
    // (move_proxy, set_fat_box): rebuild_enlarged() makes again only the nodes it rebuilds,
    // and query() walks the double boxes from a move until that rebuild. A proxy made or
    // destroyed, or rebuild(), drops them until the next make_child_boxes().
    void make_child_boxes(JobSystem* jobs = nullptr);
    bool child_boxes_current() const noexcept { return m_child_boxes_current; }

    // Casts the segment origin + t * translation, t in [0, max_fraction], against fat
    // boxes. callback(id, max_fraction) -> Real returns: a negative value to ignore the
    // proxy, 0 to stop, or a fraction in (0, max_fraction] that clips the segment.
    template <typename Callback>
    void ray_cast(const Vec3& origin, const Vec3& translation, Real max_fraction, Callback&& callback) const;

    // Rebuilds every internal node top down with a binned surface area heuristic. Proxy
    // ids, fat boxes and user values are unchanged. For trees built in bulk (static).
    void rebuild();
    // Rebuilds, with the same heuristic, only the internal nodes move_proxy flagged (the
    // paths from moved leaves to the root); the subtrees hanging off those paths are kept
    // whole and placed as if they were leaves. Proxy ids, fat boxes and user values are
    // unchanged. Costs nothing when no proxy moved since the last rebuild. With `jobs`,
    // the lower parts are built in parallel (the same tree for any worker count); the
    // caller waits for them, and nothing else may touch the tree meanwhile.
    // When most of the tree is flagged (proxies moving together), the flagged nodes are
    // first refitted in place, and kept so while their SAH cost per unit of leaf area stays
    // within kRefitSlack of the last build of most of the tree; else they are rebuilt.
    void rebuild_enlarged(JobSystem* jobs = nullptr);
    // Internal nodes flagged by moves and not rebuilt yet.
    std::int32_t enlarged_node_count() const noexcept { return m_enlarged_nodes; }
    // rebuild_enlarged() calls that kept the flagged nodes refitted instead of rebuilding them.
    std::int64_t refit_count() const noexcept { return m_refit_count; }

    const Aabb& fat_aabb(std::int32_t id) const {
        check_proxy(id);
        return m_nodes[static_cast<std::size_t>(id)].box;
    }
    std::uint64_t user(std::int32_t id) const {
        check_proxy(id);
        return m_nodes[static_cast<std::size_t>(id)].payload.user;
    }
    // Heap bytes the tree holds (its nodes and rebuild scratch, at capacity).
    std::size_t heap_bytes() const noexcept;
    bool is_proxy(std::int32_t id) const noexcept {
        return id >= 0 && static_cast<std::size_t>(id) < m_nodes.size() &&
               m_nodes[static_cast<std::size_t>(id)].height == 0;
    }
    // Height of the root; 0 for one proxy or none.
    int height() const noexcept { return m_root == kNull ? 0 : m_nodes[static_cast<std::size_t>(m_root)].height; }
    std::int32_t proxy_count() const noexcept { return m_proxy_count; }
    // Whole-tree walks made after changes (validate_after_changes) so far.
    std::int64_t whole_checks() const noexcept { return m_whole_checks; }
    // Nodes allocated so far (used and free); constant in steady state.
    std::size_t node_capacity() const noexcept { return m_nodes.size(); }
    // Sum of the internal nodes' half areas: the SAH cost of a query, for tests and benches.
    Real area_cost() const;
    const AabbTreeSettings& settings() const noexcept { return m_settings; }

    // Walks the whole tree and free list: parent links, boxes containing children, heights,
    // proxy and free counts. A failure calls the assert handler, in every build type.
    void validate() const;

private:
    struct Children {
        std::int32_t first;
        std::int32_t second;
    };
    // One cache line per node: a query reads a node's box and its children together, and
    // a leaf's user value sits where an internal node keeps its children (a node is one
    // or the other for its whole life), which keeps the node at 64 bytes.
    struct alignas(64) Node {
        Aabb box;
        union Payload {
            Children children;   // internal nodes (height > 0)
            std::uint64_t user;  // leaves (height == 0)
        } payload;
        std::int32_t parent_or_next;  // parent while used, next free node while free
        std::int32_t height;          // 0 leaf, > 0 internal, kFreeHeight on the free list
    };
    static_assert(sizeof(Node) == 64, "a node should fill one cache line");
    static constexpr std::int32_t kFreeHeight = -1;

    // Aabb::overlaps against one box, for a query's many nodes: with AVX, the six
    // comparisons in two, on the box's six coordinates loaded as two overlapping lanes of
    // four (no branch per axis for the walk to mispredict). The same result for any values,
    // NaN included (an unordered comparison fails either way).
    class OverlapTest {
    public:
        explicit OverlapTest(const Aabb& box);
        bool operator()(const Aabb& node) const;

    private:
#if defined(__AVX__)
        __m256d m_max;  // box max x, y, z; +inf (node min x, y, z, max x must be <= these)
        __m256d m_min;  // -inf; box min x, y, z (node min z, max x, y, z must be >= these)
#else
        Aabb m_box;
#endif
    };
    // An internal node's two children for query()'s walk, in one cache line: their fat
    // boxes in float (lanes: first child's x, y, z, second's x, y, z) and what the walk
    // pushes for each (its id; ~id for a leaf, whose double box the walk tests at the pop).
    // Converted to float as the query's box is, by the same rounding, which keeps order:
    // a float box overlaps the query's wherever the double boxes overlap, so the float test
    // only lets through some nodes the double one would not, never the reverse.
    struct alignas(64) ChildBoxes {
        float min[6];
        std::int32_t entry[2];  // in the lanes the compares of min ignore
        float max[6];
        float unused[2];
    };
    static_assert(sizeof(ChildBoxes) == 64, "a node's child boxes should fill one cache line");
    // Which of a node's two children's float boxes overlap one box (bit 0 the first, bit 1
    // the second): with AVX, the twelve comparisons in two.
    class ChildTest {
    public:
        explicit ChildTest(const Aabb& box);
        unsigned operator()(const ChildBoxes& children) const;

    private:
#if defined(__AVX__)
        __m256 m_max;  // box max x, y, z, x, y, z, then lanes left out of the mask
        __m256 m_min;  // box min x, y, z, x, y, z, likewise
#else
        float m_max[3];
        float m_min[3];
#endif
    };
    // Same as Aabb::overlaps, but exits at the first separating axis: most nodes a
    // query visits are rejected on x alone.
    static bool overlaps(const Aabb& a, const Aabb& b) noexcept {
        return a.min.x() <= b.max.x() && b.min.x() <= a.max.x() && a.min.y() <= b.max.y() && b.min.y() <= a.max.y() &&
               a.min.z() <= b.max.z() && b.min.z() <= a.max.z();
    }
    void make_child_boxes_of(std::int32_t id);
    void remake_built_child_boxes(JobSystem* jobs);
    // Runs make over the items [0, count) of a child box pass: in jobs with `jobs` where
    // there are more than kChildBoxesGrain, else here.
    static void run_child_box_pass(JobSystem* jobs, std::uint32_t count, RangeFn make);
    // For a change that is not a move: the float boxes are no longer kept.
    void forget_child_boxes() noexcept { m_child_boxes_current = m_child_boxes_kept = false; }
    void check_proxy(std::int32_t id) const {
        SPINDLE_ASSERT(is_proxy(id), "DynamicAabbTree: not a live proxy id");
        (void)id;
    }
    template <typename Enter, typename OnLeaf>
    void traverse(Enter&& enter, OnLeaf&& on_leaf) const;
    // query()'s walk on the child boxes below `node` (an internal node's id), whose box
    // overlaps `box`; false when callback stopped it.
    template <typename Skip, typename Callback>
    bool walk_below(std::int32_t node, const Aabb& box, const OverlapTest& overlaps_box, Skip&& skip,
                    Callback&& callback) const;
    std::int32_t allocate_node();
    void free_node(std::int32_t id);
    Aabb fatten(const Aabb& tight, const Vec3& displacement, Real margin) const;
    std::int32_t find_best_sibling(const Aabb& box) const;
    void insert_leaf(std::int32_t leaf);
    void remove_leaf(std::int32_t leaf);
    void refit_upwards(std::int32_t id);
    void refit(std::int32_t id);
    bool rotate(std::int32_t id);  // true when it swapped
    void enlarge_ancestors(std::int32_t leaf);
    void flag_ancestors(std::int32_t leaf);
    std::int32_t flag_ancestors_shared(std::int32_t leaf);
    // The whole-tree check after an operation (validate_after_changes), amortised: a tree of
    // n proxies is checked once every n / kValidateSpread operations (after each one while it
    // is small), so a world of n bodies made one by one costs O(n) node visits of checking,
    // not O(n^2); a broken tree is still found within n / kValidateSpread operations.
    static constexpr std::int32_t kValidateSpread = 16;
    void validate_if_enabled() const {
        if (!m_settings.validate_after_changes) return;
        if (++m_unvalidated_operations < m_proxy_count / kValidateSpread) return;
        m_unvalidated_operations = 0;
        ++m_whole_checks;
        validate();
    }
    // rebuild() helpers (aabb_tree_build.cpp).
    struct BuildTask;
    struct BuildCost;
    void build_from_leaves(JobSystem* jobs);
    std::int32_t place(const BuildTask& task, std::vector<BuildTask>& tasks);
    std::uint32_t partition_sah(std::uint32_t begin, std::uint32_t end);
    bool builds_most_of_tree() const noexcept;
    BuildCost build_cost() const;
    bool refit_holds(const BuildCost& refitted) const noexcept;
    // A subtree of rebuild_enlarged()'s walk left to a job, and where its lists go in the
    // walk's: before the top's pool node `pool_at` and leaf `leaves_at`.
    struct WalkJob {
        std::int32_t root;
        std::size_t pool_at, leaves_at;
    };
    void collect_flagged(std::int32_t root, std::vector<std::int32_t>& pool, std::vector<std::int32_t>& leaves,
                         std::int32_t job_height, std::vector<WalkJob>* jobs_out);
    bool collect_flagged_in_jobs(JobSystem& jobs);

    AabbTreeSettings m_settings;
    std::vector<Node> m_nodes;
    // Per node, its children's boxes in float (make_child_boxes). Kept: right for every
    // node but the flagged ones (a move changes only a leaf's box and flags its
    // ancestors), so rebuild_enlarged() need make only the nodes it builds. Current: right
    // for every node, so query() may read them. Made whole in a level's first step, so from
    // a megabyte up on whole huge pages (huge_page_vector.hpp): many_pyramids' 1.4 MB on
    // fresh small pages was 336 faults in that step, 15 us each on a virtual machine.
    std::vector<ChildBoxes, WholeHugePageAllocator<ChildBoxes>> m_child_boxes;
    bool m_child_boxes_kept = false;
    bool m_child_boxes_current = false;
    std::int32_t m_root = kNull;
    std::int32_t m_free_list = kNull;
    std::int32_t m_proxy_count = 0;
    mutable std::int32_t m_unvalidated_operations = 0;  // since the last whole-tree check
    mutable std::int64_t m_whole_checks = 0;            // validate_if_enabled's walks
    std::int32_t m_free_count = 0;
    // Per node: 1 when a move grew it (or moved a leaf below it) since the last rebuild.
    // Apart from the nodes, which fill their cache line; queries never read it. A flagged
    // node's parent is flagged too, so a walk from the root finds every flagged node.
    std::vector<std::uint8_t> m_enlarged;
    std::int32_t m_enlarged_nodes = 0;
    // set_fat_box() left flagged nodes' boxes short of their children's; the next rebuild
    // of the flagged nodes makes them whole.
    bool m_stale_boxes = false;
    // A refit keeps the tree's shape, which stays good while proxies keep their neighbours
    // (a pile falling together) and decays as they mix. Kept while the refitted nodes' SAH
    // cost is within kRefitSlack of the last build of most of the tree, both as it is and
    // per unit of the build leaves' half areas (boxes that all shrink hide a worse shape
    // from the first, boxes that all grow from the second); no reference before that build.
    struct BuildCost {
        Real nodes = 0;   // the built (or refitted) nodes' summed half areas
        Real leaves = 0;  // the build leaves' summed half areas
    };
    static constexpr Real kRefitSlack = Real(1.1);
    BuildCost m_built_cost;
    std::int64_t m_refit_count = 0;

    // Scratch for the rebuilds, kept so that a rebuild in steady state does not allocate.
    // A range of build leaves to place under `parent` (child `slot`), with the pool nodes
    // from `pool` on.
    struct BuildTask {
        std::int32_t parent;
        int slot;
        std::uint32_t begin;
        std::uint32_t end;
        std::uint32_t pool;
    };
    // Ranges this small are built as one job each (a few per worker on a washer-sized
    // tree; far more than its leaves would not pay for the job).
    static constexpr std::uint32_t kSubtreeLeaves = 256;
    // Nodes per job making float child boxes: a few per worker on a washer-sized tree.
    static constexpr std::uint32_t kChildBoxesGrain = 2048;
    std::vector<std::int32_t> m_build_leaves;  // proxies, or kept subtrees in rebuild_enlarged()
    std::vector<std::int32_t> m_build_pool;    // the internal nodes a build fills, in creation order
    std::vector<BuildTask> m_build_tasks;
    std::vector<BuildTask> m_build_subtrees;             // ranges left to the jobs
    std::vector<std::vector<BuildTask>> m_build_stacks;  // per worker: a job's own ranges
    std::vector<std::int32_t> m_build_order;
    // rebuild_enlarged()'s walk over many flagged nodes: the subtrees below the top walked
    // and refitted in jobs (kWalkJobLevels below the root, from kWalkJobNodes flagged nodes
    // on), each into its own lists, spliced into the build lists in the walk's order.
    static constexpr int kWalkJobLevels = 6;
    static constexpr std::int32_t kWalkJobNodes = 2048;
    std::vector<WalkJob> m_walk_jobs;
    std::vector<std::int32_t> m_walk_top;  // the top's pool nodes: refitted after the jobs
    std::vector<std::vector<std::int32_t>> m_walk_pools, m_walk_leaves;
    std::vector<std::int32_t> m_walk_spliced;

    // query()'s float walk keeps its stack in a fixed array of this many entries, room for
    // a tree of height kWalkDepth - 1; taller trees (a pathological rebuild()) walk the doubles.
    static constexpr int kWalkDepth = 64;

    // A traversal stack that lives on the C++ stack and spills to the heap only for
    // trees deeper than any balanced tree gets (a pathological rebuild()).
    class TraversalStack {
    public:
        void push(std::int32_t id) {
            if (m_size < kInline) {
                m_inline[m_size++] = id;
            } else {
                m_spill.push_back(id);
                ++m_size;
            }
        }
        std::int32_t pop() {
            --m_size;
            if (m_size < kInline) return m_inline[m_size];
            const std::int32_t id = m_spill.back();
            m_spill.pop_back();
            return id;
        }
        bool empty() const noexcept { return m_size == 0; }

    private:
        static constexpr std::size_t kInline = 128;
        std::int32_t m_inline[kInline];
        std::size_t m_size = 0;
        std::vector<std::int32_t> m_spill;
    };
};

// Depth first over the nodes whose box passes enter(box); on_leaf(id) -> bool is called
// for each such leaf, false stops.
template <typename Enter, typename OnLeaf>
void DynamicAabbTree::traverse(Enter&& enter, OnLeaf&& on_leaf) const {
    if (m_root == kNull) return;
    TraversalStack stack;
    stack.push(m_root);
    while (!stack.empty()) {
        const std::int32_t id = stack.pop();
        const Node& node = m_nodes[static_cast<std::size_t>(id)];
        if (!enter(node.box)) continue;
        if (node.height == 0) {
            if (!on_leaf(id)) return;
        } else {
            stack.push(node.payload.children.first);
            stack.push(node.payload.children.second);
        }
    }
}

static_assert(sizeof(Aabb) == 6 * sizeof(Real), "an Aabb is its six coordinates: min x, y, z, max x, y, z");

#if defined(__AVX__)
inline DynamicAabbTree::OverlapTest::OverlapTest(const Aabb& box)
    : m_max(_mm256_setr_pd(box.max.x(), box.max.y(), box.max.z(), std::numeric_limits<Real>::infinity())),
      m_min(_mm256_setr_pd(-std::numeric_limits<Real>::infinity(), box.min.x(), box.min.y(), box.min.z())) {}

inline bool DynamicAabbTree::OverlapTest::operator()(const Aabb& node) const {
    const Real* coordinates = reinterpret_cast<const Real*>(&node);
    const __m256d low = _mm256_loadu_pd(coordinates);       // min x, y, z, max x
    const __m256d high = _mm256_loadu_pd(coordinates + 2);  // min z, max x, y, z
    const __m256d inside = _mm256_and_pd(_mm256_cmp_pd(low, m_max, _CMP_LE_OQ), _mm256_cmp_pd(high, m_min, _CMP_GE_OQ));
    return _mm256_movemask_pd(inside) == 0xf;
}
#else
inline DynamicAabbTree::OverlapTest::OverlapTest(const Aabb& box) : m_box(box) {}

inline bool DynamicAabbTree::OverlapTest::operator()(const Aabb& node) const { return overlaps(node, m_box); }
#endif

#if defined(__AVX__)
inline DynamicAabbTree::ChildTest::ChildTest(const Aabb& box) {
    const auto x = static_cast<float>(box.max.x()), y = static_cast<float>(box.max.y()),
               z = static_cast<float>(box.max.z());
    m_max = _mm256_setr_ps(x, y, z, x, y, z, 0, 0);
    const auto u = static_cast<float>(box.min.x()), v = static_cast<float>(box.min.y()),
               w = static_cast<float>(box.min.z());
    m_min = _mm256_setr_ps(u, v, w, u, v, w, 0, 0);
}

inline unsigned DynamicAabbTree::ChildTest::operator()(const ChildBoxes& children) const {
    const __m256 low = _mm256_load_ps(children.min);  // lanes 6 and 7: the entries, left out
    const __m256 high = _mm256_load_ps(children.max);
    const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(low, m_max, _CMP_LE_OQ), _mm256_cmp_ps(high, m_min, _CMP_GE_OQ));
    const auto lanes = static_cast<unsigned>(_mm256_movemask_ps(inside));
    return ((lanes & 0x7u) == 0x7u ? 1u : 0u) | ((lanes & 0x38u) == 0x38u ? 2u : 0u);
}
#else
inline DynamicAabbTree::ChildTest::ChildTest(const Aabb& box) {
    for (int k = 0; k < 3; ++k) {
        m_max[k] = static_cast<float>(box.max[k]);
        m_min[k] = static_cast<float>(box.min[k]);
    }
}

inline unsigned DynamicAabbTree::ChildTest::operator()(const ChildBoxes& children) const {
    unsigned found = 0;
    for (int c = 0; c < 2; ++c) {
        bool inside = true;
        for (int k = 0; k < 3; ++k) {
            inside = inside && children.min[3 * c + k] <= m_max[k] && children.max[3 * c + k] >= m_min[k];
        }
        found |= inside ? 1u << c : 0u;
    }
    return found;
}
#endif

// Inline: make_child_boxes calls it for every node of a tree.
inline void DynamicAabbTree::make_child_boxes_of(std::int32_t id) {
    const Node& node = m_nodes[static_cast<std::size_t>(id)];
    ChildBoxes& children = m_child_boxes[static_cast<std::size_t>(id)];
    const std::int32_t c[2] = {node.payload.children.first, node.payload.children.second};
    for (int k = 0; k < 2; ++k) {
        const Node& child = m_nodes[static_cast<std::size_t>(c[k])];
        for (int axis = 0; axis < 3; ++axis) {
            children.min[3 * k + axis] = static_cast<float>(child.box.min[axis]);
            children.max[3 * k + axis] = static_cast<float>(child.box.max[axis]);
        }
        children.entry[k] = child.height == 0 ? ~c[k] : c[k];
    }
    children.unused[0] = children.unused[1] = 0;
}

template <typename Callback>
void DynamicAabbTree::query(const Aabb& box, Callback&& callback) const {
    const auto skip_none = [](std::int32_t) { return false; };
    query(box, skip_none, callback);
}

template <typename Skip, typename Callback>
void DynamicAabbTree::query(const Aabb& box, Skip&& skip, Callback&& callback) const {
    SPINDLE_ASSERT(!m_stale_boxes,
                   "DynamicAabbTree::query: set_fat_box moved proxies and rebuild_enlarged has not run");
    const OverlapTest overlaps_box(box);
    if (!m_child_boxes_current || height() == 0 || height() >= kWalkDepth) {
        traverse(overlaps_box, [&](std::int32_t id) { return skip(id) || callback(id); });
        return;
    }
    if (!overlaps_box(m_nodes[static_cast<std::size_t>(m_root)].box)) return;
    walk_below(m_root, box, overlaps_box, skip, callback);
}

template <typename Skip, typename Callback>
bool DynamicAabbTree::walk_below(std::int32_t node, const Aabb& box, const OverlapTest& overlaps_box, Skip&& skip,
                                 Callback&& callback) const {
    // traverse()'s walk, the same nodes entered in the same order, but a node's children
    // tested together on their float boxes before they are pushed, so an internal node's
    // own line is never read; a leaf let through is tested on its double box when popped,
    // unless skip passes it over. Depth first, the stack holds at most one waiting sibling
    // a level and the two children just pushed: height + 1 entries, so a fixed array with
    // no check for room.
    const ChildTest children_overlap(box);
    const ChildBoxes* const lines = m_child_boxes.data();
    const Node* const nodes = m_nodes.data();
    std::int32_t stack[kWalkDepth];
    std::int32_t* top = stack;
    *top++ = node;
    do {
        const std::int32_t entry = *--top;
        if (entry < 0) {
            const std::int32_t leaf = ~entry;
            if (!skip(leaf) && overlaps_box(nodes[static_cast<std::size_t>(leaf)].box) && !callback(leaf)) return false;
            continue;
        }
        const ChildBoxes& children = lines[static_cast<std::size_t>(entry)];
        const unsigned found = children_overlap(children);
        if ((found & 1u) != 0) *top++ = children.entry[0];
        if ((found & 2u) != 0) *top++ = children.entry[1];
    } while (top != stack);
    return true;
}

template <typename Report>
bool DynamicAabbTree::self_pairs(std::vector<std::pair<std::int32_t, std::int32_t>>& stack, Report&& report) const {
    SPINDLE_ASSERT(!m_stale_boxes,
                   "DynamicAabbTree::self_pairs: set_fat_box moved proxies and rebuild_enlarged has not run");
    if (!m_child_boxes_current || height() >= kWalkDepth) return false;
    if (height() == 0) return true;
    // Entries as the child boxes hold them: an internal node's id, ~id for a leaf. A node
    // against itself splits into its children against themselves and each other; two
    // internal nodes into their children two by two, on their float boxes (which overlap
    // wherever the double boxes do); a leaf against a subtree is a query of the leaf's box
    // down that subtree; two leaves are tested on their double boxes, as a query tests a leaf.
    const ChildBoxes* const lines = m_child_boxes.data();
    const Node* const nodes = m_nodes.data();
    const auto floats_overlap = [](const ChildBoxes& a, int i, const ChildBoxes& b, int j) {
        const float* const a_min = a.min + 3 * i;
        const float* const a_max = a.max + 3 * i;
        const float* const b_min = b.min + 3 * j;
        const float* const b_max = b.max + 3 * j;
        return a_min[0] <= b_max[0] && b_min[0] <= a_max[0] && a_min[1] <= b_max[1] && b_min[1] <= a_max[1] &&
               a_min[2] <= b_max[2] && b_min[2] <= a_max[2];
    };
    const auto leaf_against = [&](std::int32_t leaf, std::int32_t subtree) {
        const Aabb& box = nodes[static_cast<std::size_t>(leaf)].box;
        walk_below(
            subtree, box, OverlapTest(box), [](std::int32_t) { return false; },
            [&](std::int32_t other) {
                report(leaf, other);
                return true;
            });
    };
    stack.clear();
    stack.emplace_back(m_root, m_root);
    while (!stack.empty()) {
        const auto [x, y] = stack.back();
        stack.pop_back();
        if (x < 0 || y < 0) {
            if (x >= 0 || y >= 0) {
                leaf_against(x < 0 ? ~x : ~y, x < 0 ? y : x);
            } else if (overlaps(nodes[static_cast<std::size_t>(~x)].box, nodes[static_cast<std::size_t>(~y)].box)) {
                report(~x, ~y);
            }
            continue;
        }
        const ChildBoxes& a = lines[static_cast<std::size_t>(x)];
        if (x == y) {
            if (a.entry[0] >= 0) stack.emplace_back(a.entry[0], a.entry[0]);
            if (a.entry[1] >= 0) stack.emplace_back(a.entry[1], a.entry[1]);
            if (floats_overlap(a, 0, a, 1)) stack.emplace_back(a.entry[0], a.entry[1]);
            continue;
        }
        const ChildBoxes& b = lines[static_cast<std::size_t>(y)];
        for (int i = 0; i < 2; ++i) {
            for (int j = 0; j < 2; ++j) {
                if (floats_overlap(a, i, b, j)) stack.emplace_back(a.entry[i], b.entry[j]);
            }
        }
    }
    return true;
}

template <typename Callback>
void DynamicAabbTree::ray_cast(const Vec3& origin, const Vec3& translation, Real max_fraction,
                               Callback&& callback) const {
    SPINDLE_ASSERT(!m_stale_boxes,
                   "DynamicAabbTree::ray_cast: set_fat_box moved proxies and rebuild_enlarged has not run");
    if (!(max_fraction > 0)) return;
    // Slab test of the segment [0, max_fraction]. Axis-parallel components are tested
    // apart: the division would give 0 * inf = NaN for an origin on a slab plane.
    const Vec3 inverse = translation.cwiseInverse();
    auto hits = [&](const Aabb& b) {
        Real t_enter = 0;
        Real t_exit = max_fraction;
        for (int k = 0; k < 3; ++k) {
            if (translation[k] == 0) {
                if (origin[k] < b.min[k] || origin[k] > b.max[k]) return false;
                continue;
            }
            Real t1 = (b.min[k] - origin[k]) * inverse[k];
            Real t2 = (b.max[k] - origin[k]) * inverse[k];
            if (t1 > t2) std::swap(t1, t2);
            t_enter = t1 > t_enter ? t1 : t_enter;
            t_exit = t2 < t_exit ? t2 : t_exit;
            if (t_enter > t_exit) return false;
        }
        return true;
    };
    traverse(hits, [&](std::int32_t id) {
        const Real result = callback(id, max_fraction);
        if (result == 0) return false;
        if (result > 0 && result < max_fraction) max_fraction = result;
        return true;
    });
}

}  // namespace spindle
