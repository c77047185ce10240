// Huge pages mapped and written ahead of the step that first needs them. A first step
// writes tens of megabytes of fresh arrays (contact records, wide contacts, the pool's
// chunks); on a virtual machine that has given its free memory back to the host, each fresh
// huge page waits for the host, and the step waited for all of them (docs/benchmarks.md).
// Space::create_body stocks the pages its dynamic bodies' first step will write, a page at
// a time, where the game builds its level; the step then moves stocked pages under its
// arrays (page tables only, no copy) instead of faulting fresh ones, and the update gives
// back what the step did not take (api/space.cpp, stages/update.cpp).
// Process-wide, under a lock, as the medium block pool: the allocators hold no state. So a
// page taken is nobody's: map_room and the pool take pages without knowing for which space.
// Each space gives back as many as it stocked, which may be pages another space stocked
// for its own first step (that step then maps its own: slower, never wrong).
#pragma once

#include <cstddef>

namespace spindle {

// Adds a huge page to the stock, mapped and written once. Throws std::bad_alloc when the
// system has no memory for it or for its place in the stock (the stock is then as it was,
// and the page unmapped). Any thread.
void stock_huge_page();

// A stocked page where it lies, or nullptr when the stock is empty: for a new block of
// one huge page (the medium block pool's chunk).
void* take_stocked_huge_page() noexcept;

// Moves a stocked page onto the huge page at `where` (aligned to a huge page, inside a
// mapping of map_huge_pages whose bytes there hold nothing live): whatever lay there is
// replaced. False when the stock is empty or the move failed; `where` is then as it was.
bool move_stocked_huge_page_to(void* where) noexcept;

// Unmaps at most `pages` stocked pages; returns how many it unmapped.
std::size_t give_back_stocked_huge_pages(std::size_t pages) noexcept;

// Pages in the stock: for tests.
std::size_t stocked_huge_pages() noexcept;

}  // namespace spindle
