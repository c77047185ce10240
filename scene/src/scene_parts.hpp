// What the scene loader's files share: shapes (scene_shapes.cpp), body properties
// and [defaults] (scene_parse.cpp), and the entries that expand into bodies
// (scene_entries.cpp: [[body]], [[stack]], [[pyramid]], [[pyramid_2d]], [[chain]], copies;
// scene_ragdoll.cpp: [[ragdoll]]).
#pragma once

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <spindle/scene/scene.hpp>

#include "toml_reader.hpp"

namespace spindle::scene_detail {

// The largest scene the loader accepts (a typo such as count = [1000, 1000, 10] fails
// clearly instead of exhausting memory); room for Box3D's large_world (1,000,100 bodies).
inline constexpr std::size_t kMaxSceneBodies = 2'000'000;

// Room for an entry's `more` bodies. The list at least doubles when it grows: a scene of
// hundreds of small entries (washer's rows of 20 cubes) would otherwise move every body
// made so far at each entry.
inline void reserve_bodies(SceneDesc& scene, std::size_t more) {
    const std::size_t need = scene.bodies.size() + more;
    if (need > scene.bodies.capacity()) scene.bodies.reserve(std::max(need, 2 * scene.bodies.capacity()));
}

// A shape table such as { box = [1, 1, 1] }; `what` is its dotted key ("body.shape").
ShapeSpec parse_shape(const TomlReader& reader, const toml::node& node, std::string_view what);

// [w, x, y, z], or { axis = [x, y, z], degrees = a } / { axis, radians = a }; normalised.
Quat parse_orientation(const TomlReader& reader, const toml::node& node, const std::string& what);

// An array of [x, y, z] points, at least `min_count`.
std::vector<Vec3> parse_points(const TomlReader& reader, const toml::node& node, std::string_view what,
                               std::size_t min_count);

// The properties every body of an entry shares: [defaults], then the entry's own keys.
struct BodyTemplate {
    BodyDesc desc;
    std::optional<std::uint32_t> shape;  // index into SceneDesc::shapes
    toml::source_region shape_where;     // where the shape was given (for static-only errors)
};

// The keys apply_body_key() understands (every entry and [defaults] accept them).
const std::vector<std::string_view>& body_property_keys();

// Applies one body property to `body`. Returns false when `key` is not a body property
// (the caller handles it or reports it as unknown). A shape is appended to scene.shapes.
bool apply_body_key(const TomlReader& reader, std::string_view key, const toml::node& value, std::string_view where,
                    BodyTemplate& body, SceneDesc& scene);

// Checks an entry's finished template: it has a shape, and a plane or mesh only on a static body.
void check_body_template(const TomlReader& reader, const BodyTemplate& body, const toml::table& entry,
                         std::string_view where, const SceneDesc& scene);

// The entry kinds that make bodies, as top-level keys of arrays of tables.
const std::vector<std::string_view>& entry_kinds();

// Expands one [[kind]] entry into scene.bodies (generators and copies included); not
// [[ragdoll]], which parse_ragdoll expands.
void parse_entry(const TomlReader& reader, std::string_view kind, const toml::table& entry,
                 const BodyTemplate& defaults, SceneDesc& scene);

// copies = { count = [nx, ny, nz], step = [dx, dy, dz] }: the entry's bodies repeated
// nx * ny * nz times, copy (i, j, k) moved by (i dx, j dy, k dz), x varying fastest.
struct Copies {
    std::array<std::int64_t, 3> count{1, 1, 1};
    Vec3 step = Vec3::Zero();
    double total() const { return static_cast<double>(count[0]) * static_cast<double>(count[1]) * count[2]; }
};
inline constexpr std::int64_t kMaxCopies = 1'000'000;
Copies parse_copies(const TomlReader& reader, const toml::node& node, const std::string& what);

// The bodies of one ragdoll: scene.bodies[first, first + count).
struct RagdollBodies {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
};

// Expands one [[ragdoll]] entry (and its copies) into scene.bodies and scene.joints, and
// appends each ragdoll's bodies to `ragdolls`; their groups are given once the whole file
// is read (assign_ragdoll_groups).
void parse_ragdoll(const TomlReader& reader, const toml::table& entry, const BodyTemplate& defaults, SceneDesc& scene,
                   std::vector<RagdollBodies>& ragdolls);

// Gives each ragdoll a collision group of its own that no other body of the scene uses.
void assign_ragdoll_groups(const TomlReader& reader, SceneDesc& scene, const std::vector<RagdollBodies>& ragdolls);

}  // namespace spindle::scene_detail
