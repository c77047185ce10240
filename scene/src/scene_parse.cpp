// Scene files: the top level (name, description, [settings], [defaults], entries in
// file order) and the body properties every entry shares. docs/scenes.md lists every key.
#include <spindle/platform/error.hpp>
#include <spindle/scene/scene.hpp>

#include <algorithm>
#include <array>
#include <fstream>
#include <sstream>

#include "scene_parts.hpp"

namespace spindle {
namespace scene_detail {
namespace {

// ignore_layers = [[a, b], ...]: pairs of layers whose bodies do not collide.
std::vector<std::array<std::uint32_t, 2>> parse_layer_pairs(const TomlReader& r, const toml::node& node,
                                                            const std::string& what) {
    std::vector<std::array<std::uint32_t, 2>> pairs;
    const toml::array& list = r.array(node, what, "of [a, b] layer pairs");
    for (std::size_t k = 0; k < list.size(); ++k) {
        const std::string item = what + "[" + std::to_string(k) + "]";
        const toml::array& pair = r.array(list[k], item, "[a, b] of two layers");
        if (pair.size() != 2) {
            r.fail(list[k], item + ": expected two layers [a, b], got " + std::to_string(pair.size()) + " items");
        }
        std::array<std::uint32_t, 2> layers{};
        for (std::size_t m = 0; m < 2; ++m) {
            layers[m] = static_cast<std::uint32_t>(
                r.integer(pair[m], item + "[" + std::to_string(m) + "]", 0, std::int64_t{kLayerCount} - 1));
        }
        pairs.push_back(layers);
    }
    return pairs;
}

void parse_settings(const TomlReader& r, const toml::node& node, SceneDesc& scene) {
    const toml::table& t = r.table(node, "settings", "([settings])");
    r.check_keys(t, "[settings]",
                 {"gravity",
                  "time_step",
                  "max_steps_per_frame",
                  "min_steps_per_frame",
                  "substeps",
                  "iterations",
                  "relax_iterations",
                  "contact_hertz",
                  "contact_damping_ratio",
                  "joint_hertz",
                  "joint_damping_ratio",
                  "push_out_speed",
                  "recovery_depth",
                  "restitution_threshold",
                  "speculative_distance",
                  "linear_slop",
                  "sleep",
                  "time_to_sleep",
                  "sleep_linear_threshold",
                  "sleep_angular_threshold",
                  "ignore_layers",
                  "capacity"});
    SpaceSettings& s = scene.settings;
    TimeStepSettings& ts = s.time_step;
    SolverSettings& solver = s.solver;
    auto name = [](const char* key) { return std::string("settings.") + key; };
    auto positive = [&](const char* key, Real& field) {
        if (const toml::node* n = t.get(key)) field = r.positive(*n, name(key));
    };
    auto non_negative = [&](const char* key, Real& field) {
        if (const toml::node* n = t.get(key)) field = r.non_negative(*n, name(key));
    };
    auto count = [&](const char* key, int& field, int min) {
        constexpr std::int64_t kMaxSettingsCount = 1000;
        if (const toml::node* n = t.get(key))
            field = static_cast<int>(r.integer(*n, name(key), min, kMaxSettingsCount));
    };
    if (const toml::node* n = t.get("gravity")) s.gravity = r.vec3(*n, name("gravity"), "x, y, z in m/s^2");
    positive("time_step", ts.duration);
    count("max_steps_per_frame", ts.max_steps_per_frame, 1);
    count("min_steps_per_frame", ts.min_steps_per_frame, 0);
    if (ts.min_steps_per_frame > ts.max_steps_per_frame) {
        r.fail(*t.get("min_steps_per_frame"), "settings.min_steps_per_frame: expected at most max_steps_per_frame (" +
                                                  std::to_string(ts.max_steps_per_frame) + "), got " +
                                                  std::to_string(ts.min_steps_per_frame));
    }
    count("substeps", solver.substeps, 1);
    count("iterations", solver.iterations, 1);
    count("relax_iterations", solver.relax_iterations, 0);
    positive("contact_hertz", solver.contact_hertz);
    non_negative("contact_damping_ratio", solver.damping_ratio);
    non_negative("joint_hertz", solver.joint_hertz);
    non_negative("joint_damping_ratio", solver.joint_damping_ratio);
    non_negative("push_out_speed", solver.push_out_speed);
    non_negative("recovery_depth", solver.recovery_depth);
    non_negative("restitution_threshold", solver.restitution_threshold);
    non_negative("speculative_distance", solver.speculative_distance);
    non_negative("linear_slop", solver.linear_slop);
    if (const toml::node* n = t.get("sleep")) s.sleep.enabled = r.boolean(*n, name("sleep"));
    non_negative("time_to_sleep", s.sleep.time_to_sleep);
    non_negative("sleep_linear_threshold", s.sleep.linear_threshold);
    non_negative("sleep_angular_threshold", s.sleep.angular_threshold);
    if (const toml::node* n = t.get("ignore_layers"))
        scene.ignore_layers = parse_layer_pairs(r, *n, name("ignore_layers"));
    if (const toml::node* n = t.get("capacity")) {
        const toml::table& capacity = r.table(*n, name("capacity"), "({ contact_count = ... })");
        r.check_keys(capacity, name("capacity"), {"contact_count"});
        if (const toml::node* c = capacity.get("contact_count")) {
            s.capacity.contact_count = r.integer(*c, name("capacity.contact_count"), 0,
                                                 CapacitySettings::kMaxContactCount);
        }
    }
}

MotionType parse_type(const TomlReader& r, const toml::node& node, const std::string& what) {
    const std::string type = r.string(node, what);
    if (type == "dynamic") return MotionType::Dynamic;
    if (type == "static") return MotionType::Static;
    if (type == "kinematic") return MotionType::Kinematic;
    r.fail(node, what + ": expected \"dynamic\", \"static\" or \"kinematic\", got \"" + type + "\"");
}

// Locked world axes, ["x", "z"]: the three flags for x, y and z.
std::array<bool, 3> parse_axes(const TomlReader& r, const toml::node& node, const std::string& what) {
    std::array<bool, 3> locked{};
    const toml::array& list = r.array(node, what, "of axis names (\"x\", \"y\", \"z\")");
    for (std::size_t k = 0; k < list.size(); ++k) {
        const std::string item = what + "[" + std::to_string(k) + "]";
        const std::string axis = r.string(list[k], item);
        if (axis != "x" && axis != "y" && axis != "z") {
            r.fail(list[k], item + ": expected \"x\", \"y\" or \"z\", got \"" + axis + "\"");
        }
        locked[static_cast<std::size_t>(axis[0] - 'x')] = true;
    }
    return locked;
}

std::string stem(std::string_view source) {
    std::string_view name = source;
    if (const auto slash = name.find_last_of("/\\"); slash != std::string_view::npos) name.remove_prefix(slash + 1);
    if (name.size() > 5 && name.substr(name.size() - 5) == ".toml") name.remove_suffix(5);
    return std::string(name);
}

struct Entry {
    std::uint32_t line, column;
    std::string_view kind;
    const toml::table* table;
};

}  // namespace

Quat parse_orientation(const TomlReader& r, const toml::node& node, const std::string& what) {
    if (node.is_array()) {
        const std::vector<Real> q = r.numbers(node, what, 4, "w, x, y, z (a quaternion)");
        const Quat result(q[0], q[1], q[2], q[3]);
        if (result.norm() < 1e-9) r.fail(node, what + ": expected a non-zero quaternion [w, x, y, z]");
        return result.normalized();
    }
    const toml::table& t =
        r.table(node, what, "{ axis = [x, y, z], degrees = a } or { axis, radians = a }, or an array [w, x, y, z]");
    r.check_keys(t, what, {"axis", "degrees", "radians"});
    const toml::node& axis_node = r.require(t, what, "axis");
    const Vec3 axis = r.vec3(axis_node, what + ".axis");
    if (axis.norm() < 1e-9) r.fail(axis_node, what + ".axis: expected a non-zero direction");
    const toml::node* degrees = t.get("degrees");
    const toml::node* radians = t.get("radians");
    if ((degrees != nullptr) == (radians != nullptr)) {
        r.fail(node, what + ": expected exactly one of degrees or radians");
    }
    const Real angle = degrees ? r.number(*degrees, what + ".degrees") * kPi / 180
                               : r.number(*radians, what + ".radians");
    return Quat(Eigen::AngleAxis<Real>(angle, axis.normalized()));
}

const std::vector<std::string_view>& body_property_keys() {
    static const std::vector<std::string_view> keys = {"type",
                                                       "shape",
                                                       "orientation",
                                                       "velocity",
                                                       "angular_velocity",
                                                       "density",
                                                       "mass",
                                                       "friction",
                                                       "restitution",
                                                       "rolling_resistance",
                                                       "gravity_scale",
                                                       "linear_damping",
                                                       "angular_damping",
                                                       "gyroscopic",
                                                       "lock_translation",
                                                       "lock_rotation",
                                                       "allow_interpolation",
                                                       "allow_sleep",
                                                       "fast",
                                                       "layer",
                                                       "group",
                                                       "contact_events",
                                                       "sensor"};
    return keys;
}

bool apply_body_key(const TomlReader& r, std::string_view key, const toml::node& value, std::string_view where,
                    BodyTemplate& body, SceneDesc& scene) {
    const std::string what = std::string(where) + "." + std::string(key);
    BodyDesc& d = body.desc;
    if (key == "type") {
        d.type = parse_type(r, value, what);
    } else if (key == "shape") {
        scene.shapes.push_back(parse_shape(r, value, what));
        body.shape = static_cast<std::uint32_t>(scene.shapes.size() - 1);
        body.shape_where = value.source();
    } else if (key == "orientation") {
        d.orientation = parse_orientation(r, value, what);
    } else if (key == "velocity") {
        d.linear_velocity = r.vec3(value, what, "x, y, z in m/s");
    } else if (key == "angular_velocity") {
        d.angular_velocity = r.vec3(value, what, "x, y, z in rad/s");
    } else if (key == "density") {
        d.density = r.positive(value, what);
    } else if (key == "mass") {
        d.mass = r.non_negative(value, what);
    } else if (key == "friction") {
        d.friction = r.non_negative(value, what);
    } else if (key == "restitution") {
        d.restitution = r.non_negative(value, what);
        if (d.restitution > 1) r.fail(value, what + ": expected a number in [0, 1], got " + show(d.restitution));
    } else if (key == "rolling_resistance") {
        d.rolling_resistance = r.non_negative(value, what);
    } else if (key == "gravity_scale") {
        d.gravity_scale = r.number(value, what);
    } else if (key == "linear_damping") {
        d.linear_damping = r.non_negative(value, what);
    } else if (key == "angular_damping") {
        d.angular_damping = r.non_negative(value, what);
    } else if (key == "gyroscopic") {
        d.gyroscopic = r.boolean(value, what);
    } else if (key == "lock_translation") {
        const std::array<bool, 3> axes = parse_axes(r, value, what);
        d.locks.translation_x = axes[0], d.locks.translation_y = axes[1], d.locks.translation_z = axes[2];
    } else if (key == "lock_rotation") {
        const std::array<bool, 3> axes = parse_axes(r, value, what);
        d.locks.rotation_x = axes[0], d.locks.rotation_y = axes[1], d.locks.rotation_z = axes[2];
    } else if (key == "allow_interpolation") {
        d.allow_interpolation = r.boolean(value, what);
    } else if (key == "allow_sleep") {
        d.allow_sleep = r.boolean(value, what);
    } else if (key == "fast") {
        d.fast = r.boolean(value, what);
    } else if (key == "layer") {
        d.layer = static_cast<std::uint32_t>(r.integer(value, what, 0, std::int64_t{kLayerCount} - 1));
    } else if (key == "group") {
        d.group = static_cast<std::uint32_t>(r.integer(value, what, 0, std::int64_t{UINT32_MAX}));
    } else if (key == "contact_events") {
        d.contact_events = r.boolean(value, what);
    } else if (key == "sensor") {
        d.sensor = r.boolean(value, what);
    } else {
        return false;
    }
    return true;
}

void check_body_template(const TomlReader& r, const BodyTemplate& body, const toml::table& entry,
                         std::string_view where, const SceneDesc& scene) {
    const std::string w(where);
    if (!body.shape) r.fail(entry.source(), w + ": missing key 'shape' (and [defaults] gives none)");
    const ShapeType shape = scene.shapes[*body.shape].type;
    if ((shape == ShapeType::Plane || shape == ShapeType::TriangleMesh) && body.desc.type != MotionType::Static) {
        r.fail(body.shape_where, w + ".shape: a " + (shape == ShapeType::Plane ? "plane" : "mesh or heightfield") +
                                     " can only belong to a static body (add type = \"static\")");
    }
}

}  // namespace scene_detail

SceneDesc parse_scene(std::string_view toml_text, std::string_view source_name) {
    using namespace scene_detail;
    const TomlReader r(source_name);
    toml::table root;
    try {
        root = toml::parse(toml_text, source_name);
    } catch (const toml::parse_error& e) {
        r.fail(e.source(), std::string(e.description()));
    }
    std::vector<std::string_view> top = {"name", "description", "settings", "defaults"};
    for (std::string_view kind : entry_kinds()) top.push_back(kind);
    r.check_keys(root, "the scene", top);

    SceneDesc scene;
    scene.source = std::string(source_name);
    scene.name = root.get("name") ? r.string(*root.get("name"), "name") : stem(source_name);
    if (scene.name.empty()) r.fail(*root.get("name"), "name: expected a non-empty string");
    if (const toml::node* d = root.get("description")) scene.description = r.string(*d, "description");
    if (const toml::node* s = root.get("settings")) parse_settings(r, *s, scene);

    BodyTemplate defaults;
    if (const toml::node* node = root.get("defaults")) {
        const toml::table& t = r.table(*node, "defaults", "([defaults]) of body properties");
        r.check_keys(t, "[defaults]", body_property_keys());
        for (auto&& [key, value] : t) apply_body_key(r, key.str(), value, "defaults", defaults, scene);
    }

    // Entries in file order (toml++ keeps a table's keys sorted, not in file order):
    // the order bodies are created in decides their handles, so it must be the file's.
    std::vector<Entry> entries;
    for (std::string_view kind : entry_kinds()) {
        const toml::node* node = root.get(kind);
        if (!node) continue;
        const toml::array* list = node->as_array();
        if (!list || !list->is_array_of_tables()) {
            r.fail(*node, std::string(kind) + ": expected [[" + std::string(kind) + "]] entries (an array of tables)");
        }
        for (const toml::node& entry : *list) {
            const toml::source_position at = entry.source().begin;
            entries.push_back({at.line, at.column, kind, entry.as_table()});
        }
    }
    std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
        return a.line != b.line ? a.line < b.line : a.column < b.column;
    });
    std::vector<RagdollBodies> ragdolls;
    for (const Entry& e : entries) {
        if (e.kind == "ragdoll") {
            parse_ragdoll(r, *e.table, defaults, scene, ragdolls);
        } else {
            parse_entry(r, e.kind, *e.table, defaults, scene);
        }
    }
    assign_ragdoll_groups(r, scene, ragdolls);
    return scene;
}

SceneDesc load_scene(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open scene file");
    std::stringstream text;
    text << in.rdbuf();
    return parse_scene(text.str(), path);
}

std::size_t SceneDesc::dynamic_body_count() const noexcept {
    return static_cast<std::size_t>(std::count_if(bodies.begin(), bodies.end(), [](const SceneBody& b) {
        return b.desc.type == MotionType::Dynamic;
    }));
}

}  // namespace spindle
