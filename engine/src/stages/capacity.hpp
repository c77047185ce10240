// Capacity of the arrays that grow with the scene's contacts: grown by a quarter rather
// than doubled, and given back once use falls far below it, so that the memory a space
// holds follows its contacts instead of their high-water mark. Both are rare (the gap
// between the two thresholds): a step that changes little allocates nothing.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <type_traits>
#include <vector>

#include <spindle/scheduler/job_system.hpp>

#include "memory/huge_page_vector.hpp"
#include "memory/page_stock.hpp"
#include "solver/constraints.hpp"
#include "spatial/proxy_trees.hpp"
#include "stages/contact_index.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace spindle {

// Room for at least `needed` elements.
template <typename T, typename A>
void reserve_for(std::vector<T, A>& v, std::size_t needed) {
    if (v.capacity() < needed) v.reserve(std::max(needed, v.capacity() + v.capacity() / 4));
}

// Whether a capacity is far enough above its use to give back: over twice the use, and
// more than a few elements (small arrays are not worth the move). The gap between this
// and fit_capacity's quarter to spare is what keeps a count that swings from step to
// step (a tumbling pile's contacts) from moving its arrays every step.
inline bool far_above_use(std::size_t capacity, std::size_t size) {
    constexpr std::size_t kMinExcess = 64;
    return capacity > 2 * size + kMinExcess;
}

// Moves the elements into an array with a quarter to spare.
template <typename T, typename A>
void fit_capacity(std::vector<T, A>& v) {
    std::vector<T, A> fitted;
    fitted.reserve(v.size() + v.size() / 4);
    std::move(v.begin(), v.end(), std::back_inserter(fitted));
    v.swap(fitted);
}

// map_room maps room from a megabyte up: less is not worth the jobs.
inline constexpr std::size_t kMappedRoomMinBytes = std::size_t{1} << 20;
static_assert(kMappedRoomMinBytes >= kOnHugePagesBytes,
              "room of kMappedRoomMinBytes lies in a block of whole huge pages");

// Has the OS map the pages of v's room for elements [v.size(), end) (end <= capacity) now,
// split over jobs, before one thread constructs them there. A first step fills tens of
// megabytes of new arrays, and a page's first touch (a fault, the kernel zeroing it) costs
// more than writing it: in jobs, the workers share that cost. A job maps one huge page's
// span (the array's blocks of half a huge page or more are whole huge pages: huge_page_vector.hpp),
// so no two jobs fault the same page. On some virtual machines a mapped small page's first
// write from the program is still a fault of its own (the hypervisor's, unseen by the
// kernel), so each job also writes a byte of each of its small pages (raw room: no element
// lives there yet). A whole huge page of the room is instead a stocked one moved there,
// where the stock has one (memory/page_stock.hpp): written before the step, it waits for
// nothing. A hint: nothing for room of less than a megabyte (not worth the jobs), or where
// the OS has no such call.
template <typename T, typename A>
void map_room(JobSystem& jobs, std::vector<T, A>& v, std::size_t end) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    constexpr std::uintptr_t kPage = 4096;
    constexpr std::uintptr_t kPagesPerJob = kHugePageBytes / kPage;
    if (end <= v.size() || (end - v.size()) * sizeof(T) < kMappedRoomMinBytes) return;
    // Whole pages inside the room only: the pages it shares with live elements are mapped.
    const auto first = (reinterpret_cast<std::uintptr_t>(v.data() + v.size()) + kPage - 1) / kPage;
    const auto last = reinterpret_cast<std::uintptr_t>(v.data() + end) / kPage;
    if (last <= first) return;
    const std::uintptr_t first_span = first / kPagesPerJob;
    const auto spans = static_cast<std::uint32_t>((last - 1) / kPagesPerJob - first_span + 1);
    // A huge page may be replaced where it holds no live element and lies inside the block's
    // whole huge pages (HugePageAllocator, from room of a megabyte up; a short tail is small
    // pages, which a huge page moved there would overrun).
    constexpr bool kOnWholeHugePages = std::is_base_of_v<HugePageAllocator<T>, A>;
    const auto live_end = reinterpret_cast<std::uintptr_t>(v.data() + v.size());
    const auto whole_end = reinterpret_cast<std::uintptr_t>(v.data()) +
                           whole_huge_pages(v.capacity() * sizeof(T)) * kHugePageBytes;
    jobs.parallel_for("MapPages", 0, spans, 1, [=](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t span = lo; span < hi; ++span) {
            const std::uintptr_t huge_page = (first_span + span) * kHugePageBytes;
            if (kOnWholeHugePages && huge_page >= live_end && huge_page + kHugePageBytes <= whole_end &&
                move_stocked_huge_page_to(reinterpret_cast<void*>(huge_page)))
                continue;
            const std::uintptr_t from = std::max(first, (first_span + span) * kPagesPerJob);
            const std::uintptr_t to = std::min(last, (first_span + span + 1) * kPagesPerJob);
            // Errors (an old kernel without the call) leave the pages to fault as before.
            madvise(reinterpret_cast<void*>(from * kPage), (to - from) * kPage, MADV_POPULATE_WRITE);
            for (std::uintptr_t page = from; page < to; ++page)
                *reinterpret_cast<volatile unsigned char*>(page * kPage) = 0;
        }
    });
#else
    (void)jobs, (void)v, (void)end;
#endif
}

// The stocked pages map_room moves under an empty array on huge pages given room for
// `count` elements of `element_bytes`: each whole huge page of its block, none under
// kMappedRoomMinBytes (map_room maps nothing there).
constexpr std::size_t stocked_room_pages(std::size_t count, std::size_t element_bytes) {
    const std::size_t bytes = count * element_bytes;
    return bytes < kMappedRoomMinBytes ? 0 : whole_huge_pages(bytes);
}

// An array a first step lays out on huge pages (memory/huge_page_vector.hpp), for the stock
// that create_body fills ahead of it (memory/page_stock.hpp).
struct FirstStepArray {
    const char* name;
    std::size_t count;
    std::size_t element_bytes;
    bool mapped;  // filled by map_room: stocked pages move under it from kMappedRoomMinBytes up

    // The stocked pages map_room moves under it.
    constexpr std::size_t pages() const { return mapped ? stocked_room_pages(count, element_bytes) : 0; }
    // The medium block it takes, or 0 (an array of the heap's size, or one whose pages are
    // moved under it, or a list of a megabyte or more, which faults its own huge pages).
    constexpr std::size_t block_bytes() const {
        const std::size_t bytes = count * element_bytes;
        if (pages() != 0 || bytes < kMediumBlockMinBytes || bytes >= kMediumBlockEndBytes) return 0;
        return medium_block_bytes(bytes);
    }
};

// The arrays of the first step of `bodies` new dynamic bodies making `contacts` contacts that
// take huge pages, as the stages lay them out; the rolling rows only where some contact
// `rolls` (has rolling resistance: one of the bodies has it). The wide contacts are counted as if the
// colours were full (the solver rounds each colour up to whole lanes). A list a step adds
// on huge pages must be added here: PageStock.AFirstStepLaysOutTheArraysItsStockCounted
// fails otherwise. The array's length is the rows': a row added or removed needs no count.
constexpr auto first_step_arrays(std::size_t bodies, std::size_t contacts, bool rolls) {
    const std::size_t wide = (contacts + kLanes - 1) / kLanes;
    const std::size_t slots = ContactIndex::slots_for(contacts);
    return std::to_array<FirstStepArray>({
        {"contact records", contacts, sizeof(Contact), true},
        {"wide contacts", wide, sizeof(WideContact), true},
        {"push anchors", wide * kLanes, sizeof(PushAnchors), true},
        {"rolling rows", rolls ? wide : 0, sizeof(WideRolling), false},
        {"solver bodies", bodies + 1, sizeof(SolverBody), true},
        {"pairs found", contacts, sizeof(Pair), false},
        {"pairs merged", contacts, sizeof(Pair), false},
        {"new pair keys", contacts, sizeof(std::uint64_t), false},
        {"contact keys", contacts, sizeof(std::uint64_t), false},
        {"claimed slots", contacts, sizeof(std::uint32_t), false},
        {"contact summaries", contacts, sizeof(std::uint32_t), false},
        {"manifolds", contacts, sizeof(ManifoldRef), false},
        {"coloured manifolds", contacts, sizeof(ManifoldRef), false},
        {"contact index keys", slots, sizeof(std::uint64_t), false},
        {"contact index positions", slots, sizeof(std::uint32_t), false},
        {"moved fat boxes", bodies, sizeof(Aabb), false},
        {"push velocities", bodies + 1, sizeof(PushVelocity), false},
        {"warm velocities", bodies + 1, sizeof(PushVelocity), false},
        {"gravity scales", bodies + 1, sizeof(Real), false},
    });
}

// The huge pages those arrays take: the pages moved under the mapped ones, and the chunks
// (whole pages) of the medium block pool their blocks fill.
constexpr std::size_t first_step_pages(std::size_t bodies, std::size_t contacts, bool rolls) {
    std::size_t pages = 0;
    std::size_t pool_bytes = 0;
    for (const FirstStepArray& array : first_step_arrays(bodies, contacts, rolls)) {
        pages += array.pages();
        pool_bytes += array.block_bytes();
    }
    return pages + (pool_bytes + kHugePageBytes - 1) / kHugePageBytes;
}

}  // namespace spindle
