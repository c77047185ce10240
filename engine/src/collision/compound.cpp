// Compound shapes: parts checked once at creation, bounds and mass summed from them.
#include "collision/compound.hpp"

#include <string>

#include <spindle/platform/error.hpp>

#include "collision/convex_hull.hpp"
#include "collision/error_text.hpp"

namespace spindle {
namespace {

using detail::to_text;

[[noreturn]] void reject(std::uint32_t part, const std::string& what) {
    throw Error("compound: part " + std::to_string(part) + ": " + what);
}

void require_size(std::uint32_t part, const char* field, Real value) {
    if (!(is_finite(value) && value > 0)) {
        reject(part, std::string(field) + " must be positive and finite (a part needs volume), got " + to_text(value));
    }
}

// Parts are built by the factories, but Shape's fields are public: check what they hold.
void check_part(std::uint32_t i, const CompoundPart& part) {
    const Shape& s = part.shape;
    switch (s.type) {
        case ShapeType::Sphere: require_size(i, "sphere radius", s.radius); break;
        case ShapeType::Capsule:
            require_size(i, "capsule half_height", s.half_height);
            require_size(i, "capsule radius", s.radius);
            break;
        case ShapeType::Box:
            require_size(i, "box half_extents.x", s.half_extents.x());
            require_size(i, "box half_extents.y", s.half_extents.y());
            require_size(i, "box half_extents.z", s.half_extents.z());
            break;
        case ShapeType::ConvexHull:
            if (!s.hull) reject(i, "a convex hull part needs its hull (Shape::convex_hull)");
            break;
        default: reject(i, std::string("must be a sphere, capsule, box or convex hull, got ") + to_string(s.type));
    }
    if (!is_finite(part.position)) reject(i, "position must be finite, got " + to_text(part.position));
    if (part.position.cwiseAbs().maxCoeff() > kMaxCoordinate) {
        reject(i, "position must be within " + to_text(kMaxCoordinate) + " m of the origin, got " +
                      to_text(part.position));
    }
    const Vec3 q = part.orientation.vec();
    const Real w = part.orientation.w();
    // A finite norm too: components past about 1e154 square to infinity, and normalising
    // by an infinite norm leaves the zero quaternion.
    if (!is_finite(part.orientation) || !(part.orientation.norm() > 0) || !is_finite(part.orientation.norm())) {
        reject(i, "orientation must be finite and non-zero, got (" + to_text(w) + ", " + to_text(q.x()) + ", " +
                      to_text(q.y()) + ", " + to_text(q.z()) + ") (w, x, y, z)");
    }
}

}  // namespace

Compound::Compound(std::span<const CompoundPart> parts) : m_parts(parts.begin(), parts.end()) {
    if (m_parts.empty()) throw Error("compound: must have at least one part, got none");
    for (std::uint32_t i = 0; i < size(); ++i) check_part(i, m_parts[i]);
    m_poses.reserve(m_parts.size());
    m_part_bounds.reserve(m_parts.size());
    m_at_origin.reserve(m_parts.size());
    for (CompoundPart& part : m_parts) {
        part.orientation.normalize();
        m_poses.push_back({part.position, part.orientation});
        m_at_origin.push_back(part.position == Vec3::Zero() && part.orientation.coeffs() == Quat::Identity().coeffs());
        m_part_bounds.push_back(part.shape.bounds(m_poses.back()));
        m_bounds = m_bounds.merged(m_part_bounds.back());
    }
}

Aabb Compound::posed_part_bounds(std::uint32_t i, const Transform& x, const Mat3& r) const {
    // x * identity is x again but for the signs of zeros (products by one, sums with
    // zero), which no box comparison tells apart: the same box as the product's. A hull
    // takes x's matrix made once for all the parts, as its own bounds(x) would make it.
    const Shape& shape = m_parts[i].shape;
    if (!m_at_origin[i]) return shape.bounds(x * m_poses[i]);
    return shape.type == ShapeType::ConvexHull ? shape.hull->bounds(r, x.p) : shape.bounds(x);
}

Aabb Compound::bounds(const Transform& x, std::span<Aabb> parts) const {
    const Mat3 r = x.q.toRotationMatrix();
    // One loop, made twice: the broadphase's, which keeps every part's box, asks nothing per part.
    const auto merged = [&](auto&& keep) {
        Aabb box;
        for (std::uint32_t i = 0; i < size(); ++i) {
            const Aabb part = posed_part_bounds(i, x, r);
            keep(i, part);
            box = box.merged(part);
        }
        return box;
    };
    if (parts.empty()) return merged([](std::uint32_t, const Aabb&) {});
    return merged([parts](std::uint32_t i, const Aabb& part) { parts[i] = part; });
}

MassProperties Compound::mass_properties(Real density) const {
    MassProperties total;
    std::vector<MassProperties> each(m_parts.size());
    Vec3 moment = Vec3::Zero();
    for (std::uint32_t i = 0; i < size(); ++i) {
        MassProperties& mp = each[i];
        mp = m_parts[i].shape.mass_properties(density);
        const Mat3 r = m_poses[i].q.toRotationMatrix();
        mp.center_of_mass = m_poses[i].apply(mp.center_of_mass);
        mp.inertia = r * mp.inertia * r.transpose();
        total.mass += mp.mass;
        moment += mp.mass * mp.center_of_mass;
    }
    total.center_of_mass = moment / total.mass;
    for (const MassProperties& mp : each) {
        const Vec3 d = mp.center_of_mass - total.center_of_mass;
        total.inertia += mp.inertia + mp.mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
    }
    return total;
}

}  // namespace spindle
