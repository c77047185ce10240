// Every convex shape against a plane: the shape's core vertices (sphere centre, capsule
// ends, box corners, hull vertices) closer than the speculative distance become points,
// each named by its vertex index, and more than four are reduced.
#include <array>

#include "collision/clipping.hpp"
#include "collision/convex_hull.hpp"
#include "collision/pair_functions.hpp"

namespace spindle::detail {

namespace {
constexpr int kMaxPlaneCandidates = 256;  // ConvexHull keeps at most this many vertices
}

int collide_convex_plane(const Shape& a, const Transform& xa, const Shape& b, const Transform& xb, Real speculative,
                         Manifold* out, int) {
    // The plane in A's frame, so A's vertices are used as stored.
    const Transform b_in_a = xa.inverse() * xb;
    const Vec3 n = b_in_a.rotate(b.normal);
    const Real d = n.dot(b_in_a.apply(b.normal * b.offset));

    Real radius = 0;
    std::array<Vec3, 8> corners;
    const Vec3* vertices = corners.data();
    int vertex_count = 0;
    switch (a.type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule:
            radius = a.radius;
            rounded_core(a, corners[0], corners[1]);
            vertex_count = a.type == ShapeType::Sphere ? 1 : 2;
            break;
        case ShapeType::Box: {
            const BoxPoly box(a.half_extents);
            const PolyView view = box.view();
            for (int i = 0; i < 8; ++i) corners[i] = view.vertices[i];
            vertex_count = 8;
            break;
        }
        case ShapeType::ConvexHull:
            vertices = a.hull->vertices().data();
            vertex_count = static_cast<int>(a.hull->vertices().size());
            break;
        default: return 0;
    }

    std::array<ContactCandidate, kMaxPlaneCandidates> candidates;
    int count = 0;
    for (int i = 0; i < vertex_count && count < kMaxPlaneCandidates; ++i) {
        const Real separation = n.dot(vertices[i]) - d - radius;
        if (separation > speculative) continue;
        candidates[count++] = {vertices[i] - n * (radius + Real(0.5) * separation), separation,
                               other_contact_id(static_cast<std::uint32_t>(i))};
    }
    if (count == 0) return 0;
    Manifold& m = out[0];
    m.normal = -n;  // from the shape into the solid side of the plane
    reduce_to_manifold(candidates.data(), count, m);
    manifold_to_world(m, xa);
    return 1;
}

}  // namespace spindle::detail
