// The broadphase stage's state and the body/contact bookkeeping it owns.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "spatial/proxy_trees.hpp"
#include "world.hpp"

namespace spindle {

// The moving compounds' part boxes: each one's parts' world boxes, made with its bounds by
// a step's Bounds jobs, which the narrowphase's part walks read in that step instead of
// making them again. Only compound bodies that can move have room here, so a scene
// without them holds nothing.
class CompoundPartBoxes {
public:
    // A body's proxy was added (kept when the body is a compound that can move) or removed
    // (add_proxy, remove_proxy): the room is laid out again at the next broadphase, before
    // its Bounds jobs.
    void add(const Bodies& bodies, std::uint32_t slot);
    void remove(std::uint32_t slot);
    // Gives each compound its range of boxes, when the compounds changed.
    void lay_out(const Bodies& bodies);
    // Body `slot`'s boxes for the Bounds job to fill in `step` (empty: not a kept compound).
    // A job writes its bodies' ranges only, so the jobs may run at once.
    std::span<Aabb> fill(std::uint32_t slot, std::uint64_t step) {
        const std::uint32_t k = find(slot);
        if (k == kNone) return {};
        m_made[k] = step + 1;
        return std::span<Aabb>(m_boxes).subspan(m_first[k], m_first[k + 1] - m_first[k]);
    }
    // Body `slot`'s boxes when the broadphase made them in `step`, else empty: a compound
    // asleep, static or moved since has others.
    std::span<const Aabb> made_in(std::uint32_t slot, std::uint64_t step) const {
        const std::uint32_t k = find(slot);
        if (k == kNone || m_made[k] != step + 1) return {};
        return std::span<const Aabb>(m_boxes).subspan(m_first[k], m_first[k + 1] - m_first[k]);
    }
    std::size_t heap_bytes() const noexcept;

private:
    static constexpr std::uint32_t kNone = ~std::uint32_t{0};
    // The compound's place in the layout, or kNone.
    std::uint32_t find(std::uint32_t slot) const { return slot < m_index.size() ? m_index[slot] : kNone; }

    std::vector<std::uint32_t> m_members;  // the kept compounds' slots (a removal moves the last in)
    // Per slot up to the highest kept so far: its place in m_members (kNone: not kept), so
    // that removing one of many compounds does not search the list.
    std::vector<std::uint32_t> m_member_place;
    bool m_changed = false;  // m_members differs from the layout
    // The layout: per slot up to the highest kept compound's, its place (kNone: none), so
    // that a part walk finds its boxes at once; per place, the first of its boxes (one
    // more at the end) and the step they were made in plus one (0: never).
    std::vector<std::uint32_t> m_index;
    std::vector<std::uint32_t> m_first;
    std::vector<std::uint64_t> m_made;
    std::vector<Aabb> m_boxes;
};

// Box3D's fat box rule (its shape.c b3UpdateShapeAABBs and b3ComputeShapeMargin, body.c's
// finalize): a moving body's proxy must hold its bounds grown by `speculative`; when they
// leave it, its new fat box is those grown by the body's margin, margin_fraction x its
// shape's radius (fat_box_radius), at most max_margin. A small body gets a small box, so
// fewer pairs wait in the narrowphase. Static proxies hold their bounds. A body in free
// flight (its velocity changed over the last step by gravity's share, within
// `free_tolerance` of it), a kinematic one, and one thrown or hit hard (its velocity changed
// by more than its margin a step) holds its bounds swept over the step, so that it has its
// pair (and speculative contact) with what it would meet within the step first; a fast one
// in free flight, moving more than its margin a step, would then leave its box every step
// and be re-inserted and searched again each time, so its box reaches `stretch`
// displacements ahead and lasts a few steps. A body carried by what touches it (its
// contacts or joints changed its velocity last step, by less than its margin a step) gets
// Box3D's box, neither swept nor stretched: it moves with what touches it, whose pairs it
// has, and a box reaching ahead of it meets the bodies beyond, moving with it too, at every
// new box, contacts made and lost for nothing (a tumbling pile's churn).
struct FatBoxRule {
    Real speculative = Real(0.02);       // m: Box3D's speculative distance, 4 linear slops
    Real max_margin = Real(0.05);        // m
    Real margin_fraction = Real(0.125);  // of the shape's radius
    Real stretch = Real(2);              // displacements ahead, for a fast body in free flight
    Real free_tolerance = Real(0.25);    // of gravity's velocity change a step
    // Throws std::invalid_argument naming the field when one is negative or not finite.
    void check() const;
    Real margin(Real radius) const { return std::min(max_margin, margin_fraction * radius); }
    // Whether a dynamic body is in free flight: its velocity changed over the last step by
    // gravity's `gravity_change` (gravity x the step), to within free_tolerance of it.
    bool in_free_flight(const Vec3& velocity_change, const Vec3& gravity_change) const {
        return (velocity_change - gravity_change).squaredNorm() <=
               free_tolerance * free_tolerance * gravity_change.squaredNorm();
    }
    // Whether a dynamic body not in free flight is carried by what touches it: its velocity
    // changed over the last step by less than `body_margin` a step (`dt`) along every axis.
    static bool carried(const Vec3& velocity_change, Real dt, Real body_margin) {
        return (velocity_change * dt).cwiseAbs().maxCoeff() <= body_margin;
    }
    // Whether a body moving `displacement` a step is fast for its margin: a stretch, if it
    // is in free flight.
    static bool fast(const Vec3& displacement, Real body_margin) {
        return displacement.cwiseAbs().maxCoeff() > body_margin;
    }
};

// A shape's radius for FatBoxRule (Box3D's b3ComputeShapeMargin): a sphere's radius, a
// capsule's half length and radius, a box's or hull's farthest vertex from its centre; a
// compound has one proxy, so the farthest reach of its parts from the body's origin.
// Huge for a static-only shape (never given a margin).
Real fat_box_radius(const Shape& shape);

struct BroadphaseState {
    explicit BroadphaseState(const FatBoxRule& fat_rule = {});
    FatBoxRule rule;
    ProxyTrees tree;             // moving and static AABB trees; proxy user value = body slot
    std::vector<ProxyId> proxy;  // per body slot
    PairList pairs;              // scratch: pairs found this step (kept: no allocation per step)
    // Per body slot: 1 when its fat box changed since the last broadphase stage. A contact
    // can only lose its overlap when one of its bodies' fat boxes changed.
    std::vector<std::uint8_t> refit;
    std::vector<std::uint32_t> refit_slots;  // the slots marked in refit, to clear just them
    // Scratch, per awake body: 1 when this step's move set its refit mark (those marks are
    // not in refit_slots: the stage clears them through this).
    RawRoomVector<std::uint8_t> refit_marked;
    // Per body slot: its velocity at the last broadphase (FatBoxRule::in_free_flight), each
    // awake body's written by the Bounds job that has it.
    std::vector<Vec3> last_velocity;
    RawRoomVector<ProxyId> moved_ids;  // scratch, per awake body: its proxy where it moves, else invalid
    RawRoomVector<Aabb> moved_boxes;   // scratch, per awake body: its new fat box where it moves
    // Scratch on raw room: the jobs after each growing resize write what is read (a first
    // step's tens of thousands, not value-initialised by the resizing thread first).
    RawRoomVector<std::uint64_t> new_keys;       // keys of the new pairs that may make contacts
    std::vector<std::uint32_t> range_counts;     // values kept per job range (broadphase.cpp, create_contacts)
    RawRoomVector<std::uint32_t> claimed_slots;  // per new key, the index slot it claimed (create_contacts)
    CompoundPartBoxes part_boxes;
};

// Whether bodies on layers a and b collide, per the space's layer table.
inline bool layers_collide(const World& world, std::uint32_t a, std::uint32_t b) {
    return ((world.layer_masks[a] >> b) & 1u) != 0;
}
// Whether the collision filter keeps two bodies apart: their layers do not collide, or
// they share a non-zero group. Reads the hot filter arrays only.
inline bool filter_blocks_pair(const World& world, std::uint32_t i, std::uint32_t j) {
    const Bodies& b = world.bodies;
    if (b.group[i] != 0 && b.group[i] == b.group[j]) return true;
    return !layers_collide(world, b.layer[i], b.layer[j]);
}
// These bodies' filters changed (their layers and groups are already set; slots
// ascending): their contacts the filters now reject are removed, waking both bodies, and
// their proxies marked so that the next broadphase reports their overlaps again (pairs
// the filters now allow become contacts). One pass over the contacts for all of them.
void refilter_bodies(World& world, std::span<const std::uint32_t> slots);
// The layer table changed: the same for every body. Wakes every moving body (a newly
// allowed pair of two sleepers must not start as an awake contact between sleepers).
void refilter_all(World& world);

void add_proxy(World& world, std::uint32_t slot);
void remove_proxy(World& world, std::uint32_t slot);
// Re-fits a proxy to the body's current bounds (a teleport, or a static body moved).
void refresh_proxy(World& world, std::uint32_t slot);
// Removes every contact of a body (destroy_body).
void remove_contacts_of(World& world, std::uint32_t slot);
// Creates a contact for each pair key (min slot << 32 | max slot; the keys distinct) that has none, at the
// end of World::contacts in the keys' order, the records filled in parallel jobs. Room is
// made once for all of them: a first step makes tens of thousands, and growing by
// push_back would move every contact again and again.
void create_contacts(World& world, std::span<const std::uint64_t> keys);
// Gives back the contact arrays' room when it is far above their use (a pile came apart).
void fit_contacts(World& world);
// Removes contacts by their positions in world.contacts (ascending); the kept contacts
// past the new end take the removed places below it, in order (the rest stay in place).
void remove_contacts(World& world, std::span<const std::uint32_t> positions);

}  // namespace spindle
