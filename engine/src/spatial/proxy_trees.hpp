// ProxyTrees, the broadphase's data structure: two AABB trees (moving proxies, static
// proxies) and the search for new pairs of overlapping fat boxes after proxies moved.
// Knows nothing of bodies or shapes.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <spindle/engine/math.hpp>
#include <spindle/scheduler/job_system.hpp>

#include "memory/huge_page_vector.hpp"
#include "spatial/aabb_tree.hpp"

namespace spindle {

// A proxy handle: the tree it lives in (low bit) and its id in that tree. Ids are reused
// after destroy_proxy; the engine keeps a handle only while its shape exists.
class ProxyId {
public:
    constexpr ProxyId() noexcept = default;
    static constexpr ProxyId make(std::int32_t tree_id, bool is_static) noexcept {
        return ProxyId((static_cast<std::uint32_t>(tree_id) << 1) | (is_static ? 1u : 0u));
    }
    constexpr bool valid() const noexcept { return m_key != kInvalid; }
    constexpr bool is_static() const noexcept { return (m_key & 1u) != 0; }
    constexpr std::int32_t tree_id() const noexcept { return static_cast<std::int32_t>(m_key >> 1); }
    // A total order over live proxies, stable for their life: used to break ties.
    constexpr std::uint32_t key() const noexcept { return m_key; }
    friend constexpr bool operator==(ProxyId a, ProxyId b) noexcept = default;

private:
    static constexpr std::uint32_t kInvalid = std::numeric_limits<std::uint32_t>::max();
    constexpr explicit ProxyId(std::uint32_t key) noexcept : m_key(key) {}
    std::uint32_t m_key = kInvalid;
};

// A pair of proxies whose fat boxes overlap. Canonical: user_a <= user_b, and when the
// user values are equal, proxy_a.key() < proxy_b.key().
struct Pair {
    ProxyId proxy_a;
    ProxyId proxy_b;
    std::uint64_t user_a = 0;
    std::uint64_t user_b = 0;
};

// update_pairs' result, and the merge's scratch it is swapped with. A first step finds
// every pair at once, megabytes of them: their lists' room is left as it is by a resize
// and first written by the jobs that copy and merge the pairs into it, instead of zeroed
// first by the thread that resizes.
using PairList = RawRoomVector<Pair>;

struct BroadphaseSettings {
    // Fat box margin of moving proxies created without one of their own (metres). Static
    // proxies get none: they rarely move.
    Real margin = Real(0.1);
    // Moving fat boxes stretch this many displacements ahead (see AabbTreeSettings).
    Real displacement_multiplier = Real(2);
    // Enlarged proxies per pair-finding job. Fixed, so chunks do not depend on workers.
    std::uint32_t grain = 64;
    // The trees check themselves after changes (amortised: see AabbTreeSettings) and the
    // enlarged list after each change; default on with SPINDLE_VALIDATE.
    bool validate_after_changes = SPINDLE_VALIDATE_ENABLED != 0;
};

// Thread use: every function is called by one thread at a time (the physics stage that
// owns the broadphase). update_pairs fans out on the JobSystem and returns when done.
class ProxyTrees {
public:
    explicit ProxyTrees(BroadphaseSettings settings = {});

    // Adds a proxy (static: the static tree, else the moving tree) and marks it enlarged,
    // so its pairs are found at the next update_pairs. A moving proxy's fat boxes are its
    // tight boxes grown by `margin` (its own for its life), else by the settings' margin;
    // a static proxy's by none. The margin must be finite and >= 0.
    ProxyId create_proxy(const Aabb& aabb, std::uint64_t user, bool is_static) {
        return create_proxy(aabb, user, is_static, m_settings.margin);
    }
    ProxyId create_proxy(const Aabb& aabb, std::uint64_t user, bool is_static, Real margin);
    void destroy_proxy(ProxyId id);
    // Marks a proxy enlarged without moving it, so that the next update_pairs reports
    // every pair it overlaps again (its collision filter changed).
    void touch(ProxyId id) { mark_enlarged(id); }
    // Updates the proxy's tight box; `displacement` is its motion this step (stretches the
    // fat box ahead). Returns true and marks the proxy enlarged when the fat box grew.
    bool move_proxy(ProxyId id, const Aabb& tight_aabb, const Vec3& displacement);
    // Whether move_proxy would change the proxy's fat box (const: any number of threads
    // while nothing writes), so callers can test many proxies in parallel and move few.
    bool needs_move(ProxyId id, const Aabb& tight_aabb, const Vec3& displacement) const {
        return tree_of(id).needs_move(id.tree_id(), tight_aabb, displacement, margin(id));
    }
    // The fat box move_proxy would give the proxy (when needs_move says it moves). Const.
    Aabb fat_box(ProxyId id, const Aabb& tight_aabb, const Vec3& displacement) const {
        return tree_of(id).fat_box(tight_aabb, displacement, margin(id));
    }
    // The proxy's fat box margin (0 for a static proxy).
    Real margin(ProxyId id) const {
        return id.is_static() ? Real(0) : m_margins[static_cast<std::size_t>(id.tree_id())];
    }
    // Gives the proxy a fat box from fat_box() and marks it enlarged when the box grew, as
    // move_proxy does, but leaves the trees' inner boxes to update_pairs' rebuild: for the
    // broadphase, which moves many proxies and then calls update_pairs. Nothing may query
    // the trees in between (DynamicAabbTree::set_fat_box).
    void set_fat_box(ProxyId id, const Aabb& fat);
    // set_fat_box(ids[k], boxes[k]) for every k whose id is valid, in jobs on `jobs`: the
    // same boxes, the same flagged nodes and the same enlarged list, in the order of k, as
    // those calls one by one in that order. The valid ids must be distinct. Who may call:
    // the thread that owns the broadphase, as for set_fat_box; it waits for the jobs.
    void set_fat_boxes(JobSystem& jobs, std::span<const ProxyId> ids, std::span<const Aabb> boxes);

    // Replaces new_pairs with every pair of proxies whose fat boxes overlap and of which at
    // least one was enlarged (created or grown) since the last call; never static with
    // static, each pair once, sorted by (user_a, user_b, proxy_a.key, proxy_b.key), so
    // the result does not depend on the worker count or on which job ran first. Pairs
    // found before are found again if one of them grew; those known(user_a, user_b) -> bool
    // accepts (the caller already has the pair; user_a <= user_b) are left out where they
    // are found (Box2D's pair set), so a step where many proxies grow around pairs they
    // have does not collect, sort and merge them only to drop them. `known` is called from
    // the pair jobs, many at once: it may only read. A template, so that it inlines into
    // the search: a search asks it of most proxies it meets.
    // Clears the enlarged marks, and first rebuilds the parts of the trees that moves
    // enlarged (DynamicAabbTree::rebuild_enlarged). Who may call: the thread that owns the broadphase; it
    // runs jobs on `jobs` and waits for them (nothing else may touch the broadphase
    // meanwhile). Safe from inside a job: parallel_for may nest. `expected_pairs`: how many
    // pairs the caller expects (a level's first step: the contacts its bodies counted), so
    // that the walk's list takes its room at once, among the arrays stocked for that step.
    template <typename Known>
    void update_pairs(JobSystem& jobs, PairList& new_pairs, const Known& known, std::size_t expected_pairs = 0);
    // As above, every pair reported.
    void update_pairs(JobSystem& jobs, PairList& new_pairs) {
        update_pairs(jobs, new_pairs, [](std::uint64_t, std::uint64_t) { return false; });
    }

    // Whether the fat boxes of a and b overlap (the engine drops a contact when not).
    bool test_overlap(ProxyId a, ProxyId b) const { return fat_aabb(a).overlaps(fat_aabb(b)); }

    // Calls callback(ProxyId) -> bool for every proxy (both trees) whose fat box
    // overlaps box; false stops.
    template <typename Callback>
    void query(const Aabb& box, Callback&& callback) const;

    // Rebuilds the static tree top down (after loading many static proxies at once).
    void rebuild_static_tree();

    const Aabb& fat_aabb(ProxyId id) const { return tree_of(id).fat_aabb(id.tree_id()); }
    std::uint64_t user(ProxyId id) const { return tree_of(id).user(id.tree_id()); }
    bool is_enlarged(ProxyId id) const {
        const std::vector<std::int32_t>& slots = m_enlarged_slot[id.is_static() ? 1 : 0];
        const auto i = static_cast<std::size_t>(id.tree_id());
        return i < slots.size() && slots[i] >= 0;
    }
    std::int32_t proxy_count() const noexcept { return m_trees[0].proxy_count() + m_trees[1].proxy_count(); }
    std::size_t enlarged_count() const noexcept { return m_enlarged.size(); }
    // The proxies enlarged since the last update_pairs, in marking order (for checks).
    std::span<const ProxyId> enlarged() const noexcept { return m_enlarged; }
    const DynamicAabbTree& moving_tree() const noexcept { return m_trees[0]; }
    const DynamicAabbTree& static_tree() const noexcept { return m_trees[1]; }
    const BroadphaseSettings& settings() const noexcept { return m_settings; }
    // Heap bytes held: both trees, the enlarged list, the pair jobs' lists and the merge's scratch (at capacity).
    std::size_t heap_bytes() const noexcept;

    // Validates both trees and the enlarged list (any build type; see DynamicAabbTree).
    void validate() const;

private:
    const DynamicAabbTree& tree_of(ProxyId id) const {
        SPINDLE_ASSERT(id.valid(), "ProxyTrees: invalid proxy id");
        return m_trees[id.is_static() ? 1 : 0];
    }
    DynamicAabbTree& tree_of(ProxyId id) {
        SPINDLE_ASSERT(id.valid(), "ProxyTrees: invalid proxy id");
        return m_trees[id.is_static() ? 1 : 0];
    }
    std::vector<std::int32_t>& slots_of(ProxyId id) { return m_enlarged_slot[id.is_static() ? 1 : 0]; }
    // Per moving tree id: the proxy's margin (create_proxy).
    std::vector<Real> m_margins;
    void mark_enlarged(ProxyId id);
    void unmark_enlarged(ProxyId id);
    // With `moving_pairs_found`, a moving proxy does not search the moving tree (self_pairs did).
    template <typename Known>
    void find_pairs_of(ProxyId proxy, const Known& known, bool moving_pairs_found, std::vector<Pair>& out) const;
    // Whether every moving proxy is enlarged (a first step): then one walk of the moving tree
    // against itself finds the moving pairs, not a search per proxy.
    bool all_moving_enlarged() const;
    // The pairs of the searches and of the walk of the moving tree against itself (`walked`),
    // in canonical order: put in first users' order by counting, then each user's run sorted.
    void order_by_first_user(PairList& pairs, std::span<const Pair> walked);
    // update_pairs' parts around its search: the rebuild and the float boxes before (returns
    // the searches to make), and the runs put together and the marks cleared after.
    std::uint32_t begin_pair_search(JobSystem& jobs, PairList& new_pairs);
    void end_pair_search(JobSystem& jobs, PairList& new_pairs, bool self);
    static Pair make_pair(ProxyId p, std::uint64_t user_p, ProxyId q, std::uint64_t user_q) {
        if (user_q < user_p || (user_q == user_p && q.key() < p.key())) return {q, p, user_q, user_p};
        return {p, q, user_p, user_q};
    }
    // Sorts a chunk's pairs in canonical order.
    static void sort_pairs(std::vector<Pair>& pairs);
    // Sorts each run of one first user in [begin, end), whose first users ascend.
    static void sort_runs(Pair* begin, Pair* end);
    // The pair search's chunks: one job's enlarged proxies and one output list each.
    std::uint32_t pair_chunks() const noexcept {
        return (static_cast<std::uint32_t>(m_enlarged.size()) + m_settings.grain - 1) / m_settings.grain;
    }
    // A tree's children's float boxes are made for a pair search of at least its proxy
    // count over this many enlarged proxies (DynamicAabbTree::make_child_boxes).
    static constexpr std::uint32_t kSearchesPerChildBoxes = 8;
    void merge_runs(JobSystem& jobs, PairList& pairs);
    void validate_enlarged() const;
    // The trees check themselves (amortised); this adds the enlarged list, after each change.
    void validate_if_enabled() const {
        if (m_settings.validate_after_changes) validate_enlarged();
    }

    BroadphaseSettings m_settings;
    DynamicAabbTree m_trees[2];  // [0] moving (dynamic, kinematic), [1] static
    // Proxies enlarged since the last update_pairs, in marking order, and per tree id the
    // index into that list (-1 when not enlarged): O(1) marking, unmarking and lookup
    // from the pair jobs, which test it to report a pair of two enlarged proxies once.
    std::vector<ProxyId> m_enlarged;
    std::vector<std::int32_t> m_enlarged_slot[2];
    // One output list per job chunk, merged in chunk order; kept between calls so a
    // steady-state update does not allocate.
    std::vector<std::vector<Pair>> m_chunk_pairs;
    // Scratch for putting the chunks' sorted lists together: where each run starts, and
    // the merged list (swapped with the caller's at each round).
    std::vector<std::size_t> m_run_starts;
    PairList m_merged_pairs;
    // Scratch for set_fat_boxes: per range of ids, the boxes set and nodes flagged in each
    // tree, the proxies that grew and were not enlarged yet, and where in the enlarged list
    // the range's first goes; per id, whether it is one of those.
    struct FatBoxRange {
        std::int32_t set[2] = {0, 0};
        std::int32_t flagged[2] = {0, 0};
        std::uint32_t grown = 0;
        std::uint32_t first = 0;
    };
    std::vector<FatBoxRange> m_fat_ranges;
    std::vector<std::uint8_t> m_grown;
    // The walk of the moving tree against itself: its stack, and per first user the count,
    // then the place, of the pairs (order_by_first_user).
    std::vector<std::pair<std::int32_t, std::int32_t>> m_self_stack;
    std::vector<std::uint32_t> m_user_places;
};

template <typename Callback>
void ProxyTrees::query(const Aabb& box, Callback&& callback) const {
    bool go_on = true;
    for (int t = 0; t < 2 && go_on; ++t) {
        m_trees[t].query(box, [&](std::int32_t id) {
            go_on = callback(ProxyId::make(id, t == 1));
            return go_on;
        });
    }
}

// Pairs of one enlarged proxy: moving proxies look in both trees, static ones only in
// the moving tree. When both proxies are enlarged, both searches meet the pair; only
// the proxy with the smaller key reports it, unless the caller knows it. Those two rules
// read neither box, so the walk asks them before it reads the other's.
template <typename Known>
void ProxyTrees::find_pairs_of(ProxyId proxy, const Known& known, bool moving_pairs_found,
                               std::vector<Pair>& out) const {
    const Aabb& box = fat_aabb(proxy);
    const std::uint64_t user_p = user(proxy);
    const int last = !proxy.is_static() && moving_pairs_found ? 1 : 0;
    for (int t = proxy.is_static() ? 0 : 1; t >= last; --t) {
        const DynamicAabbTree& tree = m_trees[t];
        const auto passed_over = [&](std::int32_t tree_id) {
            const ProxyId other = ProxyId::make(tree_id, t == 1);
            return other == proxy || (other.key() < proxy.key() && is_enlarged(other));
        };
        tree.query(box, passed_over, [&](std::int32_t tree_id) {
            const Pair pair = make_pair(proxy, user_p, ProxyId::make(tree_id, t == 1), tree.user(tree_id));
            if (!known(pair.user_a, pair.user_b)) out.push_back(pair);
            return true;
        });
    }
}

template <typename Known>
void ProxyTrees::update_pairs(JobSystem& jobs, PairList& new_pairs, const Known& known, std::size_t expected_pairs) {
    const std::uint32_t count = begin_pair_search(jobs, new_pairs);
    if (count == 0) return;
    // Jobs only read the trees and the enlarged marks and write their own chunk's list,
    // sorted there: end_pair_search puts the sorted runs together.
    const std::uint32_t grain = m_settings.grain;
    // Every moving proxy enlarged (a first step): the moving pairs from one walk of the
    // moving tree against itself (order_by_first_user orders them with every search's); the
    // searches then look only in the other tree. The same pairs in the same order as the
    // searches give. On more workers too: the walk meets each overlapping node pair once,
    // where a search per proxy starts from the root, so one thread's walk and ordering beat
    // the searches side by side (many_pyramids' first step on two workers: 1.3-1.6 against
    // 3.8 ms, docs/benchmarks.md). The walk's pairs go into the merge's scratch, which the
    // ordering leaves free, with room for the expected pairs at once: a heap list grown by
    // doubling wrote twice its megabyte on fresh pages in a first step (many_pyramids: 1 ms
    // of page faults, docs/benchmarks.md).
    const DynamicAabbTree& moving = m_trees[0];
    bool self = all_moving_enlarged();
    if (self) {
        m_merged_pairs.clear();
        m_merged_pairs.reserve(expected_pairs);
        self = moving.self_pairs(m_self_stack, [&](std::int32_t a, std::int32_t b) {
            const Pair pair = make_pair(ProxyId::make(a, false), moving.user(a), ProxyId::make(b, false),
                                        moving.user(b));
            if (!known(pair.user_a, pair.user_b)) m_merged_pairs.push_back(pair);
        });
    }
    jobs.parallel_for("broadphase.find_pairs", 0, count, grain, [&](std::uint32_t begin, std::uint32_t end, unsigned) {
        std::vector<Pair>& out = m_chunk_pairs[begin / grain];
        for (std::uint32_t i = begin; i < end; ++i) find_pairs_of(m_enlarged[i], known, self, out);
        if (!self) sort_pairs(out);
    });
    end_pair_search(jobs, new_pairs, self);
}

}  // namespace spindle
