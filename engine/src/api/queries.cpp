// Space's scene queries: the arguments checked, the published scene held
// (query/query_scene.hpp), the walk done without the lock.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include "api/describe.hpp"
#include "api/validation.hpp"
#include "query/query_lease.hpp"
#include "query/query_scene.hpp"
#include "world.hpp"

namespace spindle {

namespace {

void check_segment(const Vec3& from, const Vec3& to, const char* who) {
    check_position(from, who, "from");
    check_position(to, who, "to");
}

// The query's own shape: one a body could have (validated as create_body does) and
// convex, since sweeps and overlaps are convex against anything.
void check_query_shape(const Shape& shape, const Transform& pose, const char* who) {
    validate(shape, who);
    if (shape.static_only()) {
        throw Error(std::string(who) + ": shape must be a sphere, capsule, box or convex hull, got " +
                    to_string(shape.type));
    }
    check_position(pose.p, who, "pose.p");
    check_orientation(pose.q, who, "pose.q");
}

Transform normalized(const Transform& pose) { return {pose.p, pose.q.normalized()}; }

}  // namespace

std::optional<QueryHit> Space::cast_ray(const Vec3& from, const Vec3& to, const QueryFilter& filter) const {
    check_segment(from, to, "cast_ray");
    const QueryLease lease(*m_world);
    QueryHit hit;
    if (!lease.scene().cast_ray(from, to, filter, lease.alpha(), hit)) return std::nullopt;
    return hit;
}

bool Space::ray_hits_any(const Vec3& from, const Vec3& to, const QueryFilter& filter) const {
    check_segment(from, to, "ray_hits_any");
    const QueryLease lease(*m_world);
    return lease.scene().ray_hits_any(from, to, filter, lease.alpha());
}

std::size_t Space::cast_ray_all(const Vec3& from, const Vec3& to, std::vector<QueryHit>& hits,
                                const QueryFilter& filter) const {
    check_segment(from, to, "cast_ray_all");
    hits.clear();
    const QueryLease lease(*m_world);
    lease.scene().cast_ray_all(from, to, filter, lease.alpha(), hits);
    return hits.size();
}

std::optional<QueryHit> Space::cast_shape(const Shape& shape, const Transform& start, const Vec3& translation,
                                          const QueryFilter& filter) const {
    check_query_shape(shape, start, "cast_shape");
    check_position(translation, "cast_shape", "translation");
    const QueryLease lease(*m_world);
    QueryHit hit;
    if (!lease.scene().cast_shape(shape, normalized(start), translation, filter, lease.alpha(), hit)) {
        return std::nullopt;
    }
    return hit;
}

std::size_t Space::overlap_shape(const Shape& shape, const Transform& pose, std::vector<BodyHandle>& bodies,
                                 const QueryFilter& filter) const {
    check_query_shape(shape, pose, "overlap_shape");
    bodies.clear();
    const QueryLease lease(*m_world);
    lease.scene().overlap_shape(shape, normalized(pose), filter, lease.alpha(), bodies);
    return bodies.size();
}

std::size_t Space::overlap_box(const Aabb& box, std::vector<BodyHandle>& bodies, const QueryFilter& filter) const {
    check_position(box.min, "overlap_box", "box.min");
    check_position(box.max, "overlap_box", "box.max");
    if (!box.valid()) {
        throw Error("overlap_box: box.min must not exceed box.max, got min " + vec(box.min) + " max " + vec(box.max));
    }
    bodies.clear();
    const QueryLease lease(*m_world);
    lease.scene().overlap_box(box, filter, lease.alpha(), bodies);
    return bodies.size();
}

}  // namespace spindle
