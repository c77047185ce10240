// ProxyTrees: proxy bookkeeping over the moving and static trees, and update_pairs, the
// parallel search for pairs around the proxies enlarged since the last step.
#include "spatial/proxy_trees.hpp"

#include <algorithm>

namespace spindle {
namespace {

AabbTreeSettings moving_tree_settings(const BroadphaseSettings& s) {
    return {s.margin, s.displacement_multiplier, s.validate_after_changes};
}
AabbTreeSettings static_tree_settings(const BroadphaseSettings& s) {
    return {Real(0), Real(0), s.validate_after_changes};
}

// The pairs' canonical order, a function object so that the sorts and merges inline it.
constexpr auto canonical_less = [](const Pair& a, const Pair& b) {
    if (a.user_a != b.user_a) return a.user_a < b.user_a;
    if (a.user_b != b.user_b) return a.user_b < b.user_b;
    if (a.proxy_a.key() != b.proxy_a.key()) return a.proxy_a.key() < b.proxy_a.key();
    return a.proxy_b.key() < b.proxy_b.key();
};

}  // namespace

ProxyTrees::ProxyTrees(BroadphaseSettings settings)
    : m_settings(settings),
      m_trees{DynamicAabbTree(moving_tree_settings(settings)), DynamicAabbTree(static_tree_settings(settings))} {
    if (m_settings.grain == 0) m_settings.grain = 1;
}

ProxyId ProxyTrees::create_proxy(const Aabb& aabb, std::uint64_t user, bool is_static, Real margin) {
    SPINDLE_ASSERT(margin >= 0 && is_finite(margin), "ProxyTrees::create_proxy: margin must be finite and >= 0");
    const std::int32_t tree_id = is_static ? m_trees[1].create_proxy(aabb, user)
                                           : m_trees[0].create_proxy(aabb, user, margin);
    const ProxyId id = ProxyId::make(tree_id, is_static);
    if (!is_static) {
        if (m_margins.size() <= static_cast<std::size_t>(tree_id))
            m_margins.resize(static_cast<std::size_t>(tree_id) + 1);
        m_margins[static_cast<std::size_t>(tree_id)] = margin;
    }
    std::vector<std::int32_t>& slots = slots_of(id);
    if (slots.size() <= static_cast<std::size_t>(tree_id)) slots.resize(static_cast<std::size_t>(tree_id) + 1, -1);
    mark_enlarged(id);
    validate_if_enabled();
    return id;
}

void ProxyTrees::destroy_proxy(ProxyId id) {
    unmark_enlarged(id);
    tree_of(id).destroy_proxy(id.tree_id());
    validate_if_enabled();
}

bool ProxyTrees::move_proxy(ProxyId id, const Aabb& tight_aabb, const Vec3& displacement) {
    DynamicAabbTree& tree = tree_of(id);
    const Aabb old_fat = tree.fat_aabb(id.tree_id());
    if (!tree.move_proxy(id.tree_id(), tight_aabb, displacement, margin(id))) return false;
    // A re-insert that only shrank the box (a body slowed down) cannot create pairs.
    if (old_fat.contains(tree.fat_aabb(id.tree_id()))) return false;
    mark_enlarged(id);
    return true;
}

void ProxyTrees::set_fat_box(ProxyId id, const Aabb& fat) {
    DynamicAabbTree& tree = tree_of(id);
    const bool grew = !tree.fat_aabb(id.tree_id()).contains(fat);
    tree.set_fat_box(id.tree_id(), fat);
    if (grew) mark_enlarged(id);
}

void ProxyTrees::set_fat_boxes(JobSystem& jobs, std::span<const ProxyId> ids, std::span<const Aabb> boxes) {
    SPINDLE_ASSERT(boxes.size() >= ids.size(), "ProxyTrees::set_fat_boxes: a box for every id");
    const auto n = static_cast<std::uint32_t>(ids.size());
    // Ids per job: each set walks up its leaf's path until a flagged node.
    constexpr std::uint32_t kGrain = 256;
    m_fat_ranges.assign((n + kGrain - 1) / kGrain, FatBoxRange{});
    m_grown.resize(n);
    // The boxes and flags, and which proxies join the enlarged list. The list and its slots
    // are only read here (is_enlarged), so each range can tell its own.
    jobs.parallel_for("broadphase.fat_boxes", 0, n, kGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        FatBoxRange range;
        for (std::uint32_t k = lo; k < hi; ++k) {
            m_grown[k] = 0;
            const ProxyId id = ids[k];
            if (!id.valid()) continue;
            DynamicAabbTree& tree = tree_of(id);
            const int t = id.is_static() ? 1 : 0;
            const bool grew = !tree.fat_aabb(id.tree_id()).contains(boxes[k]);
            range.flagged[t] += tree.set_fat_box_shared(id.tree_id(), boxes[k]);
            range.set[t] += 1;
            if (grew && !is_enlarged(id)) {
                m_grown[k] = 1;
                range.grown += 1;
            }
        }
        m_fat_ranges[lo / kGrain] = range;
    });
    auto end = static_cast<std::uint32_t>(m_enlarged.size());
    std::int32_t set[2] = {0, 0}, flagged[2] = {0, 0};
    for (FatBoxRange& range : m_fat_ranges) {
        range.first = end;
        end += range.grown;
        for (int t = 0; t < 2; ++t) set[t] += range.set[t], flagged[t] += range.flagged[t];
    }
    for (int t = 0; t < 2; ++t) m_trees[t].end_shared_fat_boxes(flagged[t], set[t]);
    if (end == m_enlarged.size()) return;
    // Each range places its grown proxies from its own first place on: the list's order is
    // the ids' order, on any worker count.
    m_enlarged.resize(end);
    jobs.parallel_for("broadphase.mark_enlarged", 0, n, kGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        std::uint32_t place = m_fat_ranges[lo / kGrain].first;
        for (std::uint32_t k = lo; k < hi; ++k) {
            if (!m_grown[k]) continue;
            m_enlarged[place] = ids[k];
            slots_of(ids[k])[static_cast<std::size_t>(ids[k].tree_id())] = static_cast<std::int32_t>(place);
            ++place;
        }
    });
    validate_if_enabled();
}

void ProxyTrees::mark_enlarged(ProxyId id) {
    std::int32_t& slot = slots_of(id)[static_cast<std::size_t>(id.tree_id())];
    if (slot >= 0) return;
    slot = static_cast<std::int32_t>(m_enlarged.size());
    m_enlarged.push_back(id);
}

void ProxyTrees::unmark_enlarged(ProxyId id) {
    std::int32_t& slot = slots_of(id)[static_cast<std::size_t>(id.tree_id())];
    if (slot < 0) return;
    // Swap-remove: the list order only decides which job finds a pair, never the result.
    const ProxyId last = m_enlarged.back();
    m_enlarged[static_cast<std::size_t>(slot)] = last;
    slots_of(last)[static_cast<std::size_t>(last.tree_id())] = slot;
    m_enlarged.pop_back();
    slot = -1;
}

void ProxyTrees::sort_pairs(std::vector<Pair>& pairs) {
    // A first step's chunk: its proxies searched in user order, each reporting its pairs
    // from its own user on, so the pairs' first users ascend already and only each user's
    // run (one proxy's pairs, in the order its search met them) is sorted. Else all of it.
    const auto first_user_less = [](const Pair& a, const Pair& b) { return a.user_a < b.user_a; };
    if (!std::is_sorted(pairs.begin(), pairs.end(), first_user_less)) {
        std::sort(pairs.begin(), pairs.end(), canonical_less);
        return;
    }
    sort_runs(pairs.data(), pairs.data() + pairs.size());
}

void ProxyTrees::sort_runs(Pair* begin, Pair* end) {
    constexpr std::ptrdiff_t kFew = 16;  // a box meets a few others: an insertion sort; a floor thousands
    for (Pair* run = begin; run != end;) {
        const std::uint64_t user = run->user_a;
        Pair* const run_end = std::find_if(run, end, [user](const Pair& p) { return p.user_a != user; });
        if (run_end - run > kFew) {
            std::sort(run, run_end, canonical_less);
        } else {
            for (Pair* i = run + 1; i < run_end; ++i) {
                const Pair pair = *i;
                Pair* j = i;
                for (; j > run && canonical_less(pair, *(j - 1)); --j) *j = *(j - 1);
                *j = pair;
            }
        }
        run = run_end;
    }
}

bool ProxyTrees::all_moving_enlarged() const {
    const auto moving = m_trees[0].proxy_count();
    if (moving == 0 || m_enlarged.size() < static_cast<std::size_t>(moving)) return false;
    const auto enlarged_moving = std::count_if(m_enlarged.begin(), m_enlarged.end(),
                                               [](ProxyId id) { return !id.is_static(); });
    return enlarged_moving == moving;
}

void ProxyTrees::order_by_first_user(PairList& pairs, std::span<const Pair> walked) {
    const std::uint32_t chunks = pair_chunks();
    std::size_t total = walked.size();
    std::uint64_t last_user = 0;
    const auto for_each_pair = [&](auto&& visit) {
        for (const Pair& p : walked) visit(p);
        for (std::uint32_t c = 0; c < chunks; ++c) {
            for (const Pair& p : m_chunk_pairs[c]) visit(p);
        }
    };
    for (std::uint32_t c = 0; c < chunks; ++c) total += m_chunk_pairs[c].size();
    for_each_pair([&](const Pair& p) { last_user = std::max(last_user, p.user_a); });
    pairs.resize(total);  // raw room: every place is written below
    if (last_user >= 4 * (total + static_cast<std::size_t>(proxy_count()))) {
        // Users too sparse to count by: the lists joined and sorted whole.
        std::size_t at = 0;
        for_each_pair([&](const Pair& p) { pairs[at++] = p; });
        std::sort(pairs.begin(), pairs.end(), canonical_less);
    } else {
        m_user_places.assign(static_cast<std::size_t>(last_user) + 2, 0);
        for_each_pair([&](const Pair& p) { ++m_user_places[static_cast<std::size_t>(p.user_a) + 1]; });
        for (std::size_t u = 1; u < m_user_places.size(); ++u) m_user_places[u] += m_user_places[u - 1];
        for_each_pair([&](const Pair& p) { pairs[m_user_places[static_cast<std::size_t>(p.user_a)]++] = p; });
        sort_runs(pairs.data(), pairs.data() + pairs.size());
    }
    m_run_starts.assign({0, total});
}

std::uint32_t ProxyTrees::begin_pair_search(JobSystem& jobs, PairList& new_pairs) {
    new_pairs.clear();
    // The moves since the last call left the trees valid but loose where proxies went:
    // one rebuild of those parts, before the searches walk them.
    m_trees[0].rebuild_enlarged(&jobs);
    m_trees[1].rebuild_enlarged(&jobs);
    const auto count = static_cast<std::uint32_t>(m_enlarged.size());
    if (count == 0) return 0;
    // A search visits some hundred nodes; the float boxes cost one pass over a tree's
    // nodes, paid back once the searches are a fair share of its proxies. Once made, the
    // tree keeps them through moves (rebuild_enlarged makes again only what it builds).
    for (DynamicAabbTree& tree : m_trees) {
        if (!tree.child_boxes_current() &&
            count >= static_cast<std::uint32_t>(tree.proxy_count()) / kSearchesPerChildBoxes) {
            tree.make_child_boxes(&jobs);
        }
    }
    const std::uint32_t chunks = pair_chunks();
    if (m_chunk_pairs.size() < chunks) m_chunk_pairs.resize(chunks);
    for (std::uint32_t c = 0; c < chunks; ++c) m_chunk_pairs[c].clear();
    return count;
}

void ProxyTrees::end_pair_search(JobSystem& jobs, PairList& new_pairs, bool self) {
    if (self) {
        // One run. The walk's pairs are read from the merge's scratch before the merge lays it out.
        order_by_first_user(new_pairs, m_merged_pairs);
    } else {
        const std::uint32_t chunks = pair_chunks();
        m_run_starts.assign(chunks + 1, 0);
        for (std::uint32_t c = 0; c < chunks; ++c) m_run_starts[c + 1] = m_run_starts[c] + m_chunk_pairs[c].size();
        // Raw room: each chunk's run is first written by its copy, in jobs where there are
        // several (a first step's megabytes), here where there is one (a step's few pairs).
        new_pairs.resize(m_run_starts[chunks]);
        const auto join = [&](std::uint32_t begin, std::uint32_t end, unsigned) {
            for (std::uint32_t c = begin; c < end; ++c) {
                std::copy(m_chunk_pairs[c].begin(), m_chunk_pairs[c].end(),
                          new_pairs.begin() + static_cast<std::ptrdiff_t>(m_run_starts[c]));
            }
        };
        if (chunks == 1) {
            join(0, 1, 0);
        } else {
            jobs.parallel_for("broadphase.join_pairs", 0, chunks, 1, join);
        }
    }
    // The chunk order already fixes the result for a given enlarged list; sorting also
    // frees it from the marking order, so the engine sees pairs in a canonical order.
    // (The walk's one run: only the merge's scratch laid out, as for a search's.)
    merge_runs(jobs, new_pairs);
    if (self) {
        // A first step's scratch, given back: the steps after walk nothing and count no
        // users. (The walk's pairs were in the merge's scratch, a step's stocked array.)
        std::vector<std::uint32_t>().swap(m_user_places);
        std::vector<std::pair<std::int32_t, std::int32_t>>().swap(m_self_stack);
    }
    for (const ProxyId id : m_enlarged) slots_of(id)[static_cast<std::size_t>(id.tree_id())] = -1;
    m_enlarged.clear();
}

// Merges the sorted runs [m_run_starts[r], m_run_starts[r + 1]) of `pairs` into one sorted
// list, neighbouring runs two at a time in parallel rounds. No two pairs are equal, so the
// sorted order is unique: the result does not depend on how the rounds ran.
void ProxyTrees::merge_runs(JobSystem& jobs, PairList& pairs) {
    std::vector<std::size_t>& starts = m_run_starts;
    // The scratch is laid out whether the rounds run or not (raw room: nothing is written),
    // so that a first step's arrays are those stages/capacity.hpp counts for its stock.
    m_merged_pairs.resize(pairs.size());
    // Runs that already follow each other in order (a first step's chunks, each of proxies
    // in user order) are the sorted list as they lie: no round copies them.
    bool in_order = true;
    for (std::size_t r = 1; r + 1 < starts.size() && in_order; ++r) {
        const std::size_t at = starts[r];  // the pair before it ends an earlier run (empty runs pass)
        if (at != 0 && at != pairs.size()) in_order = canonical_less(pairs[at - 1], pairs[at]);
    }
    if (in_order) return;
    for (auto runs = static_cast<std::uint32_t>(starts.size() - 1); runs > 1;) {
        const std::uint32_t merges = (runs + 1) / 2;
        jobs.parallel_for("broadphase.merge_pairs", 0, merges, 1,
                          [&](std::uint32_t begin, std::uint32_t end, unsigned) {
                              for (std::uint32_t m = begin; m < end; ++m) {
                                  const auto first = static_cast<std::ptrdiff_t>(starts[2 * m]);
                                  const auto middle = static_cast<std::ptrdiff_t>(starts[std::min(2 * m + 1, runs)]);
                                  const auto last = static_cast<std::ptrdiff_t>(starts[std::min(2 * m + 2, runs)]);
                                  std::merge(pairs.begin() + first, pairs.begin() + middle, pairs.begin() + middle,
                                             pairs.begin() + last, m_merged_pairs.begin() + first, canonical_less);
                              }
                          });
        for (std::uint32_t m = 0; m < merges; ++m) starts[m] = starts[2 * m];  // reads at or ahead of the write
        starts[merges] = starts[runs];
        starts.resize(merges + 1);
        pairs.swap(m_merged_pairs);
        runs = merges;
    }
}

void ProxyTrees::rebuild_static_tree() { m_trees[1].rebuild(); }

std::size_t ProxyTrees::heap_bytes() const noexcept {
    std::size_t bytes = m_trees[0].heap_bytes() + m_trees[1].heap_bytes() + m_enlarged.capacity() * sizeof(ProxyId) +
                        (m_enlarged_slot[0].capacity() + m_enlarged_slot[1].capacity()) * sizeof(std::int32_t) +
                        m_chunk_pairs.capacity() * sizeof(std::vector<Pair>) +
                        m_run_starts.capacity() * sizeof(std::size_t) + m_merged_pairs.capacity() * sizeof(Pair) +
                        m_fat_ranges.capacity() * sizeof(FatBoxRange) + m_grown.capacity() +
                        m_margins.capacity() * sizeof(Real) + m_self_stack.capacity() * sizeof(m_self_stack[0]) +
                        m_user_places.capacity() * sizeof(std::uint32_t);
    for (const std::vector<Pair>& pairs : m_chunk_pairs) bytes += pairs.capacity() * sizeof(Pair);
    return bytes;
}

void ProxyTrees::validate() const {
    m_trees[0].validate();
    m_trees[1].validate();
    validate_enlarged();
}

void ProxyTrees::validate_enlarged() const {
    for (std::size_t i = 0; i < m_enlarged.size(); ++i) {
        const ProxyId id = m_enlarged[i];
        const std::vector<std::int32_t>& slots = m_enlarged_slot[id.is_static() ? 1 : 0];
        if (!tree_of(id).is_proxy(id.tree_id()) || static_cast<std::size_t>(id.tree_id()) >= slots.size() ||
            slots[static_cast<std::size_t>(id.tree_id())] != static_cast<std::int32_t>(i)) {
            assert_failed("enlarged list consistent", "broadphase: enlarged list and marks disagree", __FILE__,
                          __LINE__);
        }
    }
    std::size_t marked = 0;
    for (const auto& slots : m_enlarged_slot) {
        marked +=
            static_cast<std::size_t>(std::count_if(slots.begin(), slots.end(), [](std::int32_t s) { return s >= 0; }));
    }
    if (marked != m_enlarged.size()) {
        assert_failed("marked == enlarged", "broadphase: more proxies marked enlarged than listed", __FILE__, __LINE__);
    }
}

}  // namespace spindle
