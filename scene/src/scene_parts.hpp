// What the scene loader's files share: shapes (scene_shapes.cpp), body properties
// and [defaults] (scene_parse.cpp), and the entries that expand into bodies
// (scene_entries.cpp: [[body]], [[stack]], [[pyramid]], [[pyramid_2d]], copies).
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include <spindle/scene/scene.hpp>

#include "toml_reader.hpp"

namespace spindle::scene_detail {

// The largest scene the loader accepts (a typo such as count = 1000000 fails clearly
// instead of exhausting memory).
inline constexpr std::size_t kMaxSceneBodies = 1'000'000;

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

// Expands one [[kind]] entry into scene.bodies (generators and copies included).
void parse_entry(const TomlReader& reader, std::string_view kind, const toml::table& entry,
                 const BodyTemplate& defaults, SceneDesc& scene);

}  // namespace spindle::scene_detail
