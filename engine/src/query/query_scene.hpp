// The published query structure (design.md section 10): what scene queries read. Two
// scenes go with the two published motion-state buffers; FlipReadBuffers brings the
// back one up to date and publishes it with the buffer, under the motion-state lock, so
// a query sees exactly the step buffered reads see. A query takes the published scene
// (a shared pointer and a holder count, query/query_lease.hpp) under the lock and walks
// it without the lock; a scene the physics thread wants to update while a query still
// holds it is copied first, so a query never waits for a step and a step never waits
// for a query. None exists until the space's first query (query_lease.cpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/engine/query.hpp>
#include <spindle/engine/shape.hpp>

#include "spatial/aabb_tree.hpp"

namespace spindle {

struct PublishedBuffer;
struct World;

// One body as queries see it: its published pose (and the one before, for blending),
// its filter, and the box of its shape in its own frame (the tree's boxes come from it
// without reading the shape). Written only by the physics thread, while no query holds
// the scene. The shape itself is kept apart (QueryScene::shape), read by the exact tests.
struct QueryBody {
    std::uint32_t generation = 0;  // 0: no body in this slot
    std::int32_t proxy = DynamicAabbTree::kNull;
    bool interpolate = false;   // blended between previous and current, as its motion state
    bool exact_bounds = false;  // a plane or mesh: the tree takes Shape::bounds (static only)
    bool sensor = false;        // BodyDesc::sensor: met only by filters that ask
    std::uint8_t layer = 0;
    std::uint32_t group = 0;
    Transform current;                 // the shape's origin and orientation at the newest step
    Transform previous;                // the step before (interpolate only)
    Vec3 local_center = Vec3::Zero();  // the shape's box in its own frame
    Vec3 local_extents = Vec3::Zero();

    // The pose buffered reads return at blend weight alpha (MotionStateManager::blend).
    Transform pose(double alpha) const;
};

class QueryScene {
public:
    QueryScene();
    // A copy for the physics thread to update while a query holds this one.
    std::unique_ptr<QueryScene> clone() const;
    // The scene that goes with a published buffer: every body in it at its pose there
    // (so a query meets it where reads of that buffer put it), with its shape and filter
    // from the live state. The caller may read the live state (it holds the AccessGate,
    // or the thread that does waits for the motion-state lock) and nothing writes `buffer`.
    static std::shared_ptr<QueryScene> build(const World& world, const PublishedBuffer& buffer);

    // Slot i from the live state, shape included (or empty if no body lives there); its
    // proxy moved. For bodies created, destroyed or changed by a write.
    void refresh(const World& world, std::uint32_t i, bool interpolating);
    // The pose and filter of slot i from the live state (its shape as last refreshed),
    // and its tight box in `tight`; the proxy is left for move(). Distinct slots may run
    // on many threads at once.
    void refresh_pose(const World& world, std::uint32_t i, bool interpolating, Aabb& tight);
    // Moves slot i's proxy if `tight` has left its fat box, the new fat box stretched
    // along `displacement` (the body's travel in a step, as the broadphase does: a falling
    // body is not re-inserted every step). One thread.
    void move(std::uint32_t i, const Aabb& tight, const Vec3& displacement);
    // Rebuilds the parts of the tree that move() and refresh() left loose (they move
    // proxies in place): once after a batch of them, before the scene is published.
    void rebuild_moved(JobSystem& jobs) { m_tree.rebuild_enlarged(&jobs); }
    // The capacity of the body slots, at least.
    void reserve(std::uint32_t slots);

    // Whether the body passes the filter (layer, group, ignore, then accept).
    static bool passes(const QueryBody& body, BodyHandle handle, const QueryFilter& filter);

    // The queries, at blend weight alpha (see space.hpp for what each promises).
    bool cast_ray(const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha, QueryHit& hit) const;
    bool ray_hits_any(const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha) const;
    void cast_ray_all(const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha,
                      std::vector<QueryHit>& hits) const;
    bool cast_shape(const Shape& shape, const Transform& start, const Vec3& translation, const QueryFilter& filter,
                    double alpha, QueryHit& hit) const;
    void overlap_shape(const Shape& shape, const Transform& pose, const QueryFilter& filter, double alpha,
                       std::vector<BodyHandle>& bodies) const;
    void overlap_box(const Aabb& box, const QueryFilter& filter, double alpha, std::vector<BodyHandle>& bodies) const;

    const DynamicAabbTree& tree() const noexcept { return m_tree; }
    const std::vector<QueryBody>& bodies() const noexcept { return m_bodies; }
    const Shape& shape(std::uint32_t i) const { return m_shapes[i]; }
    // Heap bytes held: the tree and the per-slot arrays (shared shape data not counted).
    std::size_t heap_bytes() const noexcept {
        return m_tree.heap_bytes() + m_bodies.capacity() * sizeof(QueryBody) + m_shapes.capacity() * sizeof(Shape);
    }

    // Queries walking this scene now; the physics thread copies a held scene instead of
    // writing it. Incremented under the motion-state lock, decremented with release.
    mutable std::atomic<std::uint32_t> holders{0};

private:
    QueryScene(const QueryScene& other);
    // The exact hit of the segment on the body behind tree proxy id, if it passes the filter.
    bool ray_hit(std::int32_t id, const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha,
                 QueryHit& hit) const;
    // The box a proxy must cover: the shape at both poses (and the swing between them).
    Aabb tight_bounds(std::uint32_t i) const;
    // Slot i's shape, its box and the flags that come with it, from the live state.
    void set_shape(const World& world, std::uint32_t i);

    DynamicAabbTree m_tree;
    std::vector<QueryBody> m_bodies;  // per body slot; the flip's hot data
    std::vector<Shape> m_shapes;      // per body slot; changed only with the body's shape
};

// The physics side: the scene that goes with published buffer k (there must be one),
// ready to be written (copied first if a query holds it).
QueryScene& writable_query_scene(World& world, int k);

}  // namespace spindle
