// MemoryReport: the heap a Space's live state holds, by structure, for the engine's own
// tests and benchmarks (docs/benchmarks.md: bytes per body); a game never includes it.
#pragma once

#include <cstddef>

#include <spindle/engine/space.hpp>

namespace spindle {

// Bytes at capacity (what the containers reserved, not what they use), so that room
// kept at a high-water mark shows. What it does not itemize (write buffer, events,
// joints, islands) a heap counter sees as the rest.
struct MemoryReport {
    std::size_t bodies = 0;          // the per-slot body arrays, descriptions included
    std::size_t histories = 0;       // the interpolation history of the bodies that can move
    std::size_t published = 0;       // both published buffers (what reads copy)
    std::size_t contacts = 0;        // contact records, with their first manifold
    std::size_t contact_extras = 0;  // further manifolds and triangle features (meshes, compounds)
    std::size_t contact_lookup = 0;  // pair index, keys, summaries, awake list
    std::size_t wide_contacts = 0;   // the solver's contacts eight by eight (kLanes)
    std::size_t push_rows = 0;       // their push-out rows (the anchors they are made from)
    std::size_t solver_other = 0;    // solver bodies, manifold lists, colours, joints, phases
    std::size_t broadphase = 0;      // AABB trees, per-slot proxies, pair lists, compounds' part boxes
    std::size_t query_scenes = 0;    // both published query scenes
    // Not the heap, and not in total(): the huge pages mapped for the next first step of
    // the bodies made since the last update (SpaceSettings::capacity), which that update
    // takes under its arrays or gives back.
    std::size_t page_stock = 0;

    std::size_t total() const noexcept {
        return bodies + histories + published + contacts + contact_extras + contact_lookup + wide_contacts + push_rows +
               solver_other + broadphase + query_scenes;
    }
};

// The update thread, or a stopped space (it reads the live state).
MemoryReport memory_report(const Space& space);

}  // namespace spindle
