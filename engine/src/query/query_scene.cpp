// The published query structure: building it from a published buffer, keeping it in step
// with the live bodies (the physics thread, at publication) and walking it (any thread,
// under a QueryLease).
#include "query/query_scene.hpp"

#include <spindle/engine/motion_state_manager.hpp>

#include <algorithm>
#include <numbers>
#include <vector>

#include "collision/cast.hpp"
#include "query/slerp_series.hpp"
#include "stages/capacity.hpp"
#include "world.hpp"

namespace spindle {

namespace {

// Queries never validate the tree per operation (a scene of 10k bodies would pay O(n)
// per moved proxy in debug builds); tests call validate() themselves.
AabbTreeSettings query_tree_settings() {
    AabbTreeSettings settings;
    settings.validate_after_changes = false;
    settings.margin = Real(0.3);
    return settings;
}

bool same_shape(const Shape& a, const Shape& b) {
    return a.type == b.type && a.radius == b.radius && a.half_height == b.half_height &&
           a.half_extents == b.half_extents && a.normal == b.normal && a.offset == b.offset && a.hull == b.hull &&
           a.mesh == b.mesh && a.parts == b.parts;
}

}  // namespace

// The same arithmetic as the published reads (api/motion_state_manager.cpp), so a ray
// meets a body where its motion state puts it, to the bit.
Transform QueryBody::pose(double alpha) const {
    if (!interpolate || alpha >= 1) return current;
    const Real t = alpha;
    return {previous.p + (current.p - previous.p) * t, SlerpSeries(t)(previous.q, current.q)};
}

QueryScene::QueryScene() : m_tree(query_tree_settings()) {}

QueryScene::QueryScene(const QueryScene& other)
    : m_tree(other.m_tree), m_bodies(other.m_bodies), m_shapes(other.m_shapes) {}

std::unique_ptr<QueryScene> QueryScene::clone() const { return std::unique_ptr<QueryScene>(new QueryScene(*this)); }

void QueryScene::reserve(std::uint32_t slots) {
    reserve_for(m_bodies, slots);  // as the bodies' own arrays grow (api/space.cpp)
    reserve_for(m_shapes, slots);
    if (m_bodies.size() < slots) m_bodies.resize(slots);
    if (m_shapes.size() < slots) m_shapes.resize(slots);
}

namespace {

Aabb box_of(const QueryBody& body, const Transform& pose) {
    const Mat3 r = pose.q.toRotationMatrix();
    return Aabb::from_center_extents(pose.apply(body.local_center), r.cwiseAbs() * body.local_extents);
}

}  // namespace

// The shape's box turned with the body (an over-estimate for round shapes, cheap and
// without reading the shape); a plane's or mesh's exact bounds (static: never blended).
// A blended pose lies within the boxes at both poses but for the swing of the turn: a
// point at distance r from the origin, turned through angle a by slerp while its origin
// moves linearly, strays at most r a / 2 from the segment between its two end positions
// (each end's distance from the slerped point is at most r a t, resp. r a (1 - t)).
Aabb QueryScene::tight_bounds(std::uint32_t i) const {
    const QueryBody& body = m_bodies[i];
    if (body.exact_bounds) return m_shapes[i].bounds(body.current);
    const Aabb now = box_of(body, body.current);
    if (!body.interpolate) return now;
    const Aabb both = now.merged(box_of(body, body.previous));
    // The angle a <= pi sin(a / 2) = pi |vec(q0^-1 q1)| on [0, pi].
    const Real turn = std::numbers::pi_v<Real> * (body.previous.q.conjugate() * body.current.q).vec().norm();
    if (turn == 0) return both;
    const Real reach = body.local_center.norm() + body.local_extents.norm();
    return both.fattened(reach * turn / 2);
}

void QueryScene::refresh_pose(const World& world, std::uint32_t i, bool interpolating, Aabb& tight) {
    const Bodies& b = world.bodies;
    QueryBody& body = m_bodies[i];
    body.layer = b.layer[i];
    body.group = b.group[i];
    body.current = b.transform(i);
    body.interpolate = interpolating && b.interpolate[i] && b.type[i] != MotionType::Static;  // as fill()
    if (body.interpolate) {
        const std::uint32_t h = b.history_place[i];
        body.previous = {b.history_position[0][h], b.history_orientation[0][h]};
    }
    tight = tight_bounds(i);
}

void QueryScene::move(std::uint32_t i, const Aabb& tight, const Vec3& displacement) {
    QueryBody& body = m_bodies[i];
    if (body.proxy == DynamicAabbTree::kNull) {
        body.proxy = m_tree.create_proxy(tight, i);
    } else {
        m_tree.move_proxy(body.proxy, tight, displacement);
    }
}

void QueryScene::set_shape(const World& world, std::uint32_t i) {
    QueryBody& body = m_bodies[i];
    const Shape& shape = world.bodies.traits[i].shape;
    m_shapes[i] = shape;
    body.exact_bounds = shape.static_only();
    body.sensor = world.bodies.traits[i].sensor;  // set at creation only
    const Aabb local = shape.bounds({});
    body.local_center = body.exact_bounds ? Vec3::Zero() : local.center();
    body.local_extents = body.exact_bounds ? Vec3::Zero() : local.extents();
}

void QueryScene::refresh(const World& world, std::uint32_t i, bool interpolating) {
    reserve(world.bodies.capacity());
    QueryBody& body = m_bodies[i];
    if (!world.bodies.alive[i]) {
        if (body.proxy != DynamicAabbTree::kNull) m_tree.destroy_proxy(body.proxy);
        body = QueryBody{};
        m_shapes[i] = Shape{};  // lets go of a hull or mesh
        return;
    }
    // Shapes change only with the body (creation, a new shape): compared, not copied.
    if (body.generation != world.bodies.generation[i] || !same_shape(m_shapes[i], world.bodies.traits[i].shape)) {
        set_shape(world, i);
    }
    body.generation = world.bodies.generation[i];
    Aabb tight;
    refresh_pose(world, i, interpolating, tight);
    const Bodies& b = world.bodies;
    move(i, tight, b.type[i] == MotionType::Static ? Vec3::Zero() : Vec3(b.v[i] * world.settings.time_step.duration));
}

// Poses from the buffer, not the live state: between flips the live state may be ahead of
// what reads return (set_internal_motion_state), and the back buffer is behind it until
// the flip refills it (then exactly the bodies refreshed there differ). The tree is built
// once over all the boxes (create_proxies), not grown a proxy at a time: a first query in a
// world of a million bodies pays one top-down build instead of a million sibling searches.
std::shared_ptr<QueryScene> QueryScene::build(const World& world, const PublishedBuffer& buffer) {
    auto scene = std::make_shared<QueryScene>();
    const Bodies& b = world.bodies;
    scene->reserve(b.capacity());
    const auto slots = static_cast<std::uint32_t>(std::min<std::size_t>(buffer.size(), b.capacity()));
    std::vector<Aabb> tight;
    std::vector<std::uint64_t> user;
    for (std::uint32_t i = 0; i < slots; ++i) {
        // A body made or destroyed but not published yet (a creation waiting for the lock
        // this build runs under) joins the scene at the next flip, which refreshes it.
        if (buffer.generation[i] == 0 || !b.alive[i] || b.generation[i] != buffer.generation[i]) continue;
        QueryBody& body = scene->m_bodies[i];
        body.generation = buffer.generation[i];
        scene->set_shape(world, i);
        body.layer = b.layer[i];
        body.group = b.group[i];
        body.current = {buffer.current[i].position, buffer.current[i].orientation};
        body.interpolate = buffer.interpolate[i] != 0;
        if (body.interpolate) {
            const PublishedHistory& before = buffer.previous_of(i);
            body.previous = {before.position, before.orientation};
        }
        tight.push_back(scene->tight_bounds(i));
        user.push_back(i);
    }
    std::vector<std::int32_t> ids(tight.size());
    scene->m_tree.create_proxies(tight, user, ids);
    for (std::size_t k = 0; k < ids.size(); ++k) scene->m_bodies[user[k]].proxy = ids[k];
    return scene;
}

bool QueryScene::passes(const QueryBody& body, BodyHandle handle, const QueryFilter& filter) {
    if (((filter.layer_mask >> body.layer) & 1u) == 0) return false;
    if (filter.group != 0 && body.group == filter.group) return false;
    if (handle == filter.ignore) return false;
    if (body.sensor && !filter.sensors) return false;
    return !filter.accept || filter.accept(handle);
}

// ---- queries ----

// The exact hit of the segment on the body behind tree proxy `id`, if it passes the filter.
bool QueryScene::ray_hit(std::int32_t id, const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha,
                         QueryHit& hit) const {
    const auto i = static_cast<std::uint32_t>(m_tree.user(id));
    const QueryBody& body = m_bodies[i];
    const BodyHandle handle{i, body.generation};
    CastHit h;
    if (!passes(body, handle, filter) || !ray_cast(m_shapes[i], body.pose(alpha), from, to, h)) return false;
    hit = {handle, h.fraction, h.point, h.normal, h.part};
    return true;
}

bool QueryScene::cast_ray(const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha,
                          QueryHit& hit) const {
    bool found = false;
    m_tree.ray_cast(from, to - from, 1, [&](std::int32_t id, Real max_fraction) -> Real {
        QueryHit h;
        if (!ray_hit(id, from, to, filter, alpha, h)) return -1;
        // Equal fractions go to the lower slot: the two scenes' trees differ in shape, and
        // a ray must not flip between two bodies from one flip to the next.
        if (found && (h.fraction > hit.fraction || (h.fraction == hit.fraction && h.body.index > hit.body.index))) {
            return -1;
        }
        found = true;
        hit = h;
        // Clips the segment; at fraction 0 the walk goes on (0 would stop it) for a lower
        // slot also hit at 0.
        return h.fraction > 0 ? h.fraction : max_fraction;
    });
    return found;
}

bool QueryScene::ray_hits_any(const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha) const {
    bool found = false;
    m_tree.ray_cast(from, to - from, 1, [&](std::int32_t id, Real) -> Real {
        QueryHit h;
        found = ray_hit(id, from, to, filter, alpha, h);
        return found ? 0 : -1;  // 0 stops at the first
    });
    return found;
}

// Sorted by fraction, then by body slot, so the order never depends on the tree's shape.
void QueryScene::cast_ray_all(const Vec3& from, const Vec3& to, const QueryFilter& filter, double alpha,
                              std::vector<QueryHit>& hits) const {
    m_tree.ray_cast(from, to - from, 1, [&](std::int32_t id, Real max_fraction) -> Real {
        QueryHit h;
        if (ray_hit(id, from, to, filter, alpha, h)) hits.push_back(h);
        return max_fraction;  // keep walking the whole segment
    });
    std::sort(hits.begin(), hits.end(), [](const QueryHit& a, const QueryHit& b) {
        return a.fraction != b.fraction ? a.fraction < b.fraction : a.body.index < b.body.index;
    });
}

bool QueryScene::cast_shape(const Shape& shape, const Transform& start, const Vec3& translation,
                            const QueryFilter& filter, double alpha, QueryHit& hit) const {
    const Aabb swept = shape.bounds(start).merged(shape.bounds({start.p + translation, start.q}));
    bool found = false;
    m_tree.query(swept, [&](std::int32_t id) {
        const auto i = static_cast<std::uint32_t>(m_tree.user(id));
        const QueryBody& body = m_bodies[i];
        const BodyHandle handle{i, body.generation};
        CastHit h;
        if (!passes(body, handle, filter) || !shape_cast(shape, start, translation, m_shapes[i], body.pose(alpha), h)) {
            return true;
        }
        // The nearer wins; equal fractions go to the lower slot, whatever the walk's order.
        if (!found || h.fraction < hit.fraction || (h.fraction == hit.fraction && i < hit.body.index)) {
            hit = {handle, h.fraction, h.point, h.normal, h.part};
            found = true;
        }
        return true;
    });
    return found;
}

void QueryScene::overlap_shape(const Shape& shape, const Transform& pose, const QueryFilter& filter, double alpha,
                               std::vector<BodyHandle>& bodies) const {
    const std::size_t first = bodies.size();
    m_tree.query(shape.bounds(pose), [&](std::int32_t id) {
        const auto i = static_cast<std::uint32_t>(m_tree.user(id));
        const QueryBody& body = m_bodies[i];
        const BodyHandle handle{i, body.generation};
        if (passes(body, handle, filter) && overlaps(shape, pose, m_shapes[i], body.pose(alpha))) {
            bodies.push_back(handle);
        }
        return true;
    });
    std::sort(bodies.begin() + static_cast<std::ptrdiff_t>(first), bodies.end(),
              [](BodyHandle a, BodyHandle b) { return a.index < b.index; });
}

void QueryScene::overlap_box(const Aabb& box, const QueryFilter& filter, double alpha,
                             std::vector<BodyHandle>& bodies) const {
    // Exact against every shape: the box as a box shape (built directly: a flat box, or a
    // point, is a fine query though not a fine body).
    Shape shape;
    shape.type = ShapeType::Box;
    shape.half_extents = box.extents();
    overlap_shape(shape, {box.center(), Quat::Identity()}, filter, alpha, bodies);
}

// ---- updating ----

QueryScene& writable_query_scene(World& world, int k) {
    std::shared_ptr<QueryScene>& scene = world.query_scenes[k];
    SPINDLE_ASSERT(scene != nullptr, "writable_query_scene: no query scene for this buffer");
    if (scene->holders.load(std::memory_order_acquire) != 0) {
        // A query walks it still: it keeps the old one, which goes when it lets go.
        scene = std::shared_ptr<QueryScene>(scene->clone());
        world.counters.query_scene_copies += 1;
    }
    return *scene;
}

}  // namespace spindle
