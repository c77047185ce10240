// Every convex shape against a plane: the shape's core vertices (sphere centre, capsule
// ends, the box's or hull's face turned toward the plane) closer than the speculative
// distance become points, each named by its vertex index, and more than four are reduced.
#include <array>

#include "collision/clipping.hpp"
#include "collision/convex_hull.hpp"
#include "collision/pair_functions.hpp"
#include "collision/polyhedron.hpp"

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

    std::array<ContactCandidate, kMaxPlaneCandidates> candidates;
    int count = 0;
    auto add = [&](const Vec3& vertex, std::uint32_t index, Real radius) {
        const Real separation = n.dot(vertex) - d - radius;
        if (separation > speculative || count == kMaxPlaneCandidates) return;
        candidates[count++] = {vertex - n * (radius + Real(0.5) * separation), separation, other_contact_id(index)};
    };
    switch (a.type) {
        case ShapeType::Sphere:
        case ShapeType::Capsule: {
            Vec3 ends[2];
            rounded_core(a, ends[0], ends[1]);
            for (std::uint32_t i = 0; i < (a.type == ShapeType::Sphere ? 1U : 2U); ++i) add(ends[i], i, a.radius);
            break;
        }
        case ShapeType::Box:
        case ShapeType::ConvexHull: {
            // The vertices of the face turned most toward the plane (the incident face),
            // not every vertex within reach: a box thinner than the speculative distance
            // has its top corners within reach too, and a point there tilts it.
            const BoxPoly box(a.type == ShapeType::Box ? a.half_extents : Vec3::Zero());
            const PolyView poly = a.type == ShapeType::Box ? box.view() : view_of(*a.hull);
            std::uint32_t incident = 0;
            for (std::uint32_t f = 1; f < poly.face_count; ++f) {
                if (poly.faces[f].normal.dot(n) < poly.faces[incident].normal.dot(n)) incident = f;
            }
            const HullFace& face = poly.faces[incident];
            for (std::uint32_t k = 0; k < face.count; ++k) {
                const std::uint32_t i = poly.face_vertices[face.first + k];
                add(poly.vertices[i], i, 0);
            }
            break;
        }
        default: return 0;
    }
    if (count == 0) return 0;
    Manifold& m = out[0];
    m.normal = -n;  // from the shape into the solid side of the plane
    reduce_to_manifold(candidates.data(), count, m);
    manifold_to_world(m, xa);
    return 1;
}

}  // namespace spindle::detail
