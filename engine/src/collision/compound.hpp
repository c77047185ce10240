// Compound: the convex parts of a compound shape, posed in its frame, with their bounds
// there so that a pair test meets only the parts near the other shape.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <spindle/engine/shape.hpp>

namespace spindle {

class Compound {
public:
    // Throws spindle::Error naming the part for an empty list, a part that is not a
    // sphere, capsule, box or hull, a part of zero volume, a non-finite position, or a
    // non-finite or zero orientation. Orientations are normalised.
    explicit Compound(std::span<const CompoundPart> parts);

    std::uint32_t size() const noexcept { return static_cast<std::uint32_t>(m_parts.size()); }
    const Shape& shape(std::uint32_t i) const { return m_parts[i].shape; }
    const Transform& pose(std::uint32_t i) const { return m_poses[i]; }
    // Part i's bounds in the compound's frame.
    const Aabb& part_bounds(std::uint32_t i) const { return m_part_bounds[i]; }
    const Aabb& local_bounds() const noexcept { return m_bounds; }
    std::span<const CompoundPart> parts() const noexcept { return m_parts; }

    // World bounds under x: the union of the parts' own. Given room (parts.size() ==
    // size()), also writes each part's, the boxes a pair walk would make.
    Aabb bounds(const Transform& x, std::span<Aabb> parts = {}) const;
    // The parts' mass properties for one density, summed about their common centre of
    // mass (parallel axis theorem).
    MassProperties mass_properties(Real density) const;

private:
    // Part i's bounds in the world under the compound's pose x (r: x's rotation matrix).
    Aabb posed_part_bounds(std::uint32_t i, const Transform& x, const Mat3& r) const;

    std::vector<CompoundPart> m_parts;
    std::vector<Transform> m_poses;
    // Parts at the compound's origin, unturned (hulls often have their place baked into
    // their points): their world pose is the compound's, with no product to make.
    std::vector<std::uint8_t> m_at_origin;
    std::vector<Aabb> m_part_bounds;
    Aabb m_bounds;
};

// The shape that made a contact or hit: part `part` of a compound, the shape itself otherwise.
inline const Shape& part_shape(const Shape& shape, std::uint32_t part) {
    return shape.type == ShapeType::Compound ? shape.parts->shape(part) : shape;
}

}  // namespace spindle
