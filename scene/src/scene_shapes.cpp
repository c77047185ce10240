// Scene shapes: the `shape = { ... }` tables (sphere, box, capsule, hull, plane, mesh,
// heightfield, compound), their check at parse time, and the Shape factories at build time.
#include <spindle/platform/error.hpp>
#include <spindle/scene/scene.hpp>

#include <array>
#include <cmath>

#include "scene_parts.hpp"

namespace spindle {
namespace scene_detail {
namespace {

constexpr std::int64_t kMaxHeightfieldCells = 1024;

ShapeSpec parse_capsule(const TomlReader& r, const toml::node& node, const std::string& what) {
    const toml::table& t = r.table(node, what, "{ half_height = h, radius = r }");
    r.check_keys(t, what, {"half_height", "radius"});
    ShapeSpec s;
    s.type = ShapeType::Capsule;
    s.half_height = r.positive(r.require(t, what, "half_height"), what + ".half_height");
    s.radius = r.positive(r.require(t, what, "radius"), what + ".radius");
    return s;
}

ShapeSpec parse_plane(const TomlReader& r, const toml::node& node, const std::string& what) {
    const toml::table& t = r.table(node, what, "{ normal = [x, y, z], offset = d }");
    r.check_keys(t, what, {"normal", "offset"});
    ShapeSpec s;
    s.type = ShapeType::Plane;
    const toml::node& normal = r.require(t, what, "normal");
    s.normal = r.vec3(normal, what + ".normal");
    if (s.normal.norm() < 1e-9) r.fail(normal, what + ".normal: expected a non-zero direction");
    s.normal.normalize();
    if (const toml::node* offset = t.get("offset")) s.offset = r.number(*offset, what + ".offset");
    return s;
}

ShapeSpec parse_mesh(const TomlReader& r, const toml::node& node, const std::string& what) {
    const toml::table& t = r.table(node, what, "{ vertices = [[x, y, z], ...], triangles = [[a, b, c], ...] }");
    r.check_keys(t, what, {"vertices", "triangles"});
    ShapeSpec s;
    s.type = ShapeType::TriangleMesh;
    s.points = parse_points(r, r.require(t, what, "vertices"), what + ".vertices", 3);
    const std::string tris = what + ".triangles";
    const toml::array& list = r.array(r.require(t, what, "triangles"), tris, "of [a, b, c] vertex indices");
    if (list.empty()) r.fail(list, tris + ": expected at least one triangle");
    const auto last = static_cast<std::int64_t>(s.points.size()) - 1;
    for (const toml::node& tri : list) {
        const toml::array* corners = tri.as_array();
        if (!corners || corners->size() != 3) r.fail(tri, tris + ": expected [a, b, c], three vertex indices");
        for (const toml::node& corner : *corners) {
            s.indices.push_back(static_cast<std::uint32_t>(r.integer(corner, tris, 0, last)));
        }
    }
    return s;
}

// A generated heightfield's wavelength: one for both axes, or [along x, along z] (Box3D's
// wave mesh waves twice as fast along x as along z).
std::array<Real, 2> parse_wavelength(const TomlReader& r, const toml::node* node, const std::string& what) {
    if (!node) return {10, 10};
    if (!node->is_array()) {
        const Real both = r.positive(*node, what);
        return {both, both};
    }
    const std::vector<Real> v = r.numbers(*node, what, 2, "wx, wz in m");
    for (std::size_t i = 0; i < 2; ++i) {
        if (!(v[i] > 0))
            r.fail(*node->as_array()->get(i), what + ": expected numbers > 0 [wx, wz in m], got " + show(v[i]));
    }
    return {v[0], v[1]};
}

// A terrain as a triangle mesh over a grid in x and z, centred on the body's origin:
// heights either listed (rows along z, each along x) or a product of sines
// amplitude * sin(2 pi x / wx) * sin(2 pi z / wz).
ShapeSpec parse_heightfield(const TomlReader& r, const toml::node& node, const std::string& what) {
    const toml::table& t = r.table(node, what,
                                   "{ size = [sx, sz], cells = [nx, nz], amplitude = a, wavelength = w } or "
                                   "{ size = [sx, sz], heights = [[...], ...] }");
    r.check_keys(t, what, {"size", "cells", "amplitude", "wavelength", "heights"});
    const toml::node& size_node = r.require(t, what, "size");
    const std::vector<Real> size = r.numbers(size_node, what + ".size", 2, "sx, sz in m");
    if (!(size[0] > 0) || !(size[1] > 0)) r.fail(size_node, what + ".size: expected two numbers > 0 (m)");

    std::vector<std::vector<Real>> heights;  // [z][x]
    if (const toml::node* listed = t.get("heights")) {
        for (const char* key : {"cells", "amplitude", "wavelength"}) {
            if (const toml::node* other = t.get(key)) {
                r.fail(*other, what + "." + key + ": not allowed together with heights (the rows give the grid)");
            }
        }
        const std::string hw = what + ".heights";
        const toml::array& rows = r.array(*listed, hw, "of rows of heights");
        if (rows.size() < 2) r.fail(*listed, hw + ": expected at least 2 rows");
        for (const toml::node& row : rows) {
            const toml::array& values = r.array(row, hw, "row of heights (m)");
            if (values.size() < 2) r.fail(row, hw + ": expected at least 2 heights per row");
            if (!heights.empty() && values.size() != heights.front().size()) {
                r.fail(row, hw + ": expected every row to have " + std::to_string(heights.front().size()) +
                                " heights, got " + std::to_string(values.size()));
            }
            heights.emplace_back();
            for (const toml::node& h : values) heights.back().push_back(r.number(h, hw));
        }
    } else {
        const toml::node& cells_node = r.require(t, what, "cells");
        const toml::array& cells = r.array(cells_node, what + ".cells", "[nx, nz]");
        if (cells.size() != 2) r.fail(cells_node, what + ".cells: expected [nx, nz], two integers");
        const std::int64_t nx = r.integer(*cells.get(0), what + ".cells", 1, kMaxHeightfieldCells);
        const std::int64_t nz = r.integer(*cells.get(1), what + ".cells", 1, kMaxHeightfieldCells);
        const Real amplitude = t.get("amplitude") ? r.number(*t.get("amplitude"), what + ".amplitude") : 0;
        const std::array<Real, 2> wavelength = parse_wavelength(r, t.get("wavelength"), what + ".wavelength");
        for (std::int64_t iz = 0; iz <= nz; ++iz) {
            heights.emplace_back();
            for (std::int64_t ix = 0; ix <= nx; ++ix) {
                const Real x = size[0] * (static_cast<Real>(ix) / static_cast<Real>(nx) - 0.5);
                const Real z = size[1] * (static_cast<Real>(iz) / static_cast<Real>(nz) - 0.5);
                heights.back().push_back(amplitude * std::sin(2 * kPi * x / wavelength[0]) *
                                         std::sin(2 * kPi * z / wavelength[1]));
            }
        }
    }

    ShapeSpec s;
    s.type = ShapeType::TriangleMesh;
    const std::size_t rows = heights.size();
    const std::size_t columns = heights.front().size();
    for (std::size_t iz = 0; iz < rows; ++iz) {
        for (std::size_t ix = 0; ix < columns; ++ix) {
            const Real x = size[0] * (static_cast<Real>(ix) / static_cast<Real>(columns - 1) - 0.5);
            const Real z = size[1] * (static_cast<Real>(iz) / static_cast<Real>(rows - 1) - 0.5);
            s.points.emplace_back(x, heights[iz][ix], z);
        }
    }
    // Two triangles per cell, counter-clockwise seen from above so the front faces +y.
    for (std::size_t iz = 0; iz + 1 < rows; ++iz) {
        for (std::size_t ix = 0; ix + 1 < columns; ++ix) {
            const auto v00 = static_cast<std::uint32_t>(iz * columns + ix);
            const auto v10 = v00 + 1;                                    // +x
            const auto v01 = static_cast<std::uint32_t>(v00 + columns);  // +z
            const auto v11 = v01 + 1;
            s.indices.insert(s.indices.end(), {v00, v01, v10, v10, v01, v11});
        }
    }
    return s;
}

// Parts of a body: [{ shape = ..., position = [x, y, z], orientation = ... }, ...], each
// a convex shape (its own checks make a part of zero size fail at its line).
ShapeSpec parse_compound(const TomlReader& r, const toml::node& node, const std::string& what) {
    const toml::array& list = r.array(node, what,
                                      "of parts { shape = { ... }, position = [x, y, z], orientation = [w, x, y, z] }");
    if (list.empty()) r.fail(node, what + ": expected at least one part");
    ShapeSpec s;
    s.type = ShapeType::Compound;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string item = what + "[" + std::to_string(i) + "]";
        const toml::table& t = r.table(list[i], item, "{ shape = { ... }, position = [x, y, z], orientation = ... }");
        r.check_keys(t, item, {"shape", "position", "orientation"});
        const toml::node& shape_node = r.require(t, item, "shape");
        CompoundPartSpec part;
        part.shape = parse_shape(r, shape_node, item + ".shape");
        const ShapeType type = part.shape.type;
        if (type != ShapeType::Sphere && type != ShapeType::Box && type != ShapeType::Capsule &&
            type != ShapeType::ConvexHull) {
            r.fail(shape_node, item + ".shape: a compound part must be a sphere, box, capsule or hull, got " +
                                   std::string(to_string(type)));
        }
        if (const toml::node* position = t.get("position")) part.position = r.vec3(*position, item + ".position");
        if (const toml::node* orientation = t.get("orientation")) {
            part.orientation = parse_orientation(r, *orientation, item + ".orientation");
        }
        s.parts.push_back(std::move(part));
    }
    return s;
}

}  // namespace

std::vector<Vec3> parse_points(const TomlReader& r, const toml::node& node, std::string_view what,
                               std::size_t min_count) {
    const std::string w(what);
    const toml::array& list = r.array(node, w, "of [x, y, z] points");
    if (list.size() < min_count) {
        r.fail(node,
               w + ": expected at least " + std::to_string(min_count) + " points, got " + std::to_string(list.size()));
    }
    std::vector<Vec3> points;
    points.reserve(list.size());
    for (const toml::node& p : list) points.push_back(r.vec3(p, w));
    return points;
}

ShapeSpec parse_shape(const TomlReader& r, const toml::node& node, std::string_view what_view) {
    const std::string what(what_view);
    constexpr const char* kExpected =
        "{ sphere = r }, { box = [hx, hy, hz] }, { capsule = { half_height, radius } }, "
        "{ hull = [[x, y, z], ...] }, { plane = { normal, offset } }, { mesh = { vertices, triangles } } or "
        "{ heightfield = { size, cells, amplitude, wavelength } } or "
        "{ compound = [{ shape, position, orientation }, ...] }";
    const toml::table* t = node.as_table();
    if (!t || t->size() != 1) r.fail(node, what + ": expected one of " + std::string(kExpected));
    r.check_keys(*t, what, {"sphere", "box", "capsule", "hull", "plane", "mesh", "heightfield", "compound"});
    const auto entry = t->begin();
    const toml::key& key = entry->first;
    const toml::node& value = entry->second;
    const std::string name = what + "." + std::string(key.str());
    ShapeSpec s;
    if (key.str() == "sphere") {
        s.type = ShapeType::Sphere;
        s.radius = r.positive(value, name);
    } else if (key.str() == "box") {
        s.type = ShapeType::Box;
        s.half_extents = r.positive_vec3(value, name, "half extents hx, hy, hz in m");
    } else if (key.str() == "capsule") {
        s = parse_capsule(r, value, name);
    } else if (key.str() == "hull") {
        s.type = ShapeType::ConvexHull;
        s.points = parse_points(r, value, name, 4);
    } else if (key.str() == "plane") {
        s = parse_plane(r, value, name);
    } else if (key.str() == "mesh") {
        s = parse_mesh(r, value, name);
    } else if (key.str() == "compound") {
        s = parse_compound(r, value, name);
    } else {
        s = parse_heightfield(r, value, name);
    }
    return s;
}

}  // namespace scene_detail

Shape ShapeSpec::make() const {
    switch (type) {
        case ShapeType::Sphere: return Shape::sphere(radius);
        case ShapeType::Capsule: return Shape::capsule(half_height, radius);
        case ShapeType::Box: return Shape::box(half_extents);
        case ShapeType::ConvexHull: return Shape::convex_hull(points);
        case ShapeType::Plane: return Shape::plane(normal, offset);
        case ShapeType::TriangleMesh: return Shape::triangle_mesh(points, indices);
        case ShapeType::Compound: {
            std::vector<CompoundPart> made;
            for (std::size_t i = 0; i < parts.size(); ++i) {
                try {
                    made.push_back({parts[i].shape.make(), parts[i].position, parts[i].orientation});
                } catch (const Error& e) {
                    throw Error("compound: part " + std::to_string(i) + ": " + e.what());
                }
            }
            return Shape::compound(made);
        }
        case ShapeType::Count: break;
    }
    throw Error("scene: unknown shape type");
}

Vec3 ShapeSpec::half_size(const Quat& q) const {
    const Mat3 abs_rotation = q.normalized().toRotationMatrix().cwiseAbs();
    switch (type) {
        case ShapeType::Sphere: return Vec3::Constant(radius);
        case ShapeType::Capsule: return abs_rotation * Vec3(0, half_height, 0) + Vec3::Constant(radius);
        case ShapeType::Box: return abs_rotation * half_extents;
        case ShapeType::ConvexHull: {
            Aabb box;
            for (const Vec3& p : points) box.include(q.normalized() * p);
            return box.extents();
        }
        case ShapeType::Compound: {
            Aabb box;
            for (const CompoundPartSpec& part : parts) {
                const Vec3 center = q.normalized() * part.position;
                const Vec3 half = part.shape.half_size(q.normalized() * part.orientation);
                box = box.merged(Aabb::from_center_extents(center, half));
            }
            return box.extents();
        }
        default: return Vec3::Zero();
    }
}

}  // namespace spindle
