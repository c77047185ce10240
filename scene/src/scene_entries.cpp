// Scene entries that make bodies: [[body]] (one), [[stack]] (a column), [[pyramid]]
// (Jolt's 3D pyramid), [[pyramid_2d]] (a wall-like triangle), [[chain]] (jointed links),
// each optionally repeated on a grid by `copies`, so that big scenes stay short.
// [[ragdoll]] is scene_ragdoll.cpp's.
#include <spindle/scene/scene.hpp>

#include <array>
#include <cmath>

#include "scene_parts.hpp"

namespace spindle::scene_detail {

Copies parse_copies(const TomlReader& r, const toml::node& node, const std::string& what) {
    const toml::table& t = r.table(node, what, "{ count = [nx, ny, nz], step = [dx, dy, dz] }");
    r.check_keys(t, what, {"count", "step"});
    Copies c;
    const toml::node& count = r.require(t, what, "count");
    const toml::array* list = count.as_array();
    if (!list || list->size() != 3) r.fail(count, what + ".count: expected [nx, ny, nz], three integers >= 1");
    for (std::size_t i = 0; i < 3; ++i) c.count[i] = r.integer(*list->get(i), what + ".count", 1, kMaxCopies);
    c.step = r.vec3(r.require(t, what, "step"), what + ".step", "dx, dy, dz in m");
    return c;
}

namespace {

constexpr std::int64_t kMaxCount = 1'000'000;

// Layer i of an n-layer pyramid has boxes j, k in [i/2, n - (i+1)/2) (integer
// division), shifted by half a spacing on odd layers: exactly Jolt's PerformanceTest
// "Pyramid", so results compare.
std::vector<Vec3> pyramid(const Vec3& origin, std::int64_t layers, const Vec3& spacing) {
    std::vector<Vec3> out;
    for (std::int64_t i = 0; i < layers; ++i) {
        const Real shift = (i & 1) ? 0.5 : 0.0;
        for (std::int64_t j = i / 2; j < layers - (i + 1) / 2; ++j) {
            for (std::int64_t k = i / 2; k < layers - (i + 1) / 2; ++k) {
                out.emplace_back(origin.x() + spacing.x() * (static_cast<Real>(j) + shift),
                                 origin.y() + spacing.y() * static_cast<Real>(i),
                                 origin.z() + spacing.z() * (static_cast<Real>(k) + shift));
            }
        }
    }
    return out;
}

double pyramid_count(std::int64_t layers) {
    double n = 0;
    for (std::int64_t i = 0; i < layers; ++i) {
        const auto width = static_cast<double>(layers - (i + 1) / 2 - i / 2);
        n += width * width;
    }
    return n;
}

// Row i of a base-b triangle has b - i boxes, shifted half a spacing per row, in the
// x-y plane.
std::vector<Vec3> pyramid_2d(const Vec3& origin, std::int64_t base, Real sx, Real sy) {
    std::vector<Vec3> out;
    for (std::int64_t i = 0; i < base; ++i) {
        for (std::int64_t j = 0; j < base - i; ++j) {
            out.emplace_back(origin.x() + sx * (static_cast<Real>(j) + 0.5 * static_cast<Real>(i)),
                             origin.y() + sy * static_cast<Real>(i), origin.z());
        }
    }
    return out;
}

// [[chain]]: `links` bodies made from the entry's body properties, centred along
// `direction` from the anchor at `position`, each jointed to the one before; the first
// hangs from a small static anchor body. `end_mass` makes the last link that heavy.
struct Chain {
    std::int64_t links = 0;
    Real spacing = 0;  // centre to centre, m
    Vec3 direction = Vec3::UnitX();
    JointType joint = JointType::BallSocket;
    Vec3 axis = Vec3::UnitZ();
    Real end_mass = 0;
};

Chain parse_chain(const TomlReader& r, const toml::table& entry, const std::string& where, const Vec3& half,
                  const BodyDesc& body) {
    auto key_name = [&](const char* key) { return where + "." + key; };
    Chain c;
    c.links = r.integer(r.require(entry, where, "links"), key_name("links"), 1, kMaxCount);
    if (const toml::node* d = entry.get("direction")) {
        c.direction = r.vec3(*d, key_name("direction"), "x, y, z");
        if (!(c.direction.norm() > 1e-9)) r.fail(*d, key_name("direction") + ": expected a non-zero vector");
        c.direction.normalize();
    }
    c.spacing = entry.get("spacing") ? r.positive(*entry.get("spacing"), key_name("spacing"))
                                     : 2 * half.dot(c.direction.cwiseAbs());  // the shape's extent along it
    if (!(c.spacing > 0)) {
        r.fail(entry.source(), where + ": the shape has no size along direction; give " + key_name("spacing"));
    }
    if (const toml::node* j = entry.get("joint")) {
        const std::string kind = r.string(*j, key_name("joint"));
        if (kind == "hinge") {
            c.joint = JointType::Hinge;
        } else if (kind != "ball_socket") {
            r.fail(*j, key_name("joint") + ": expected \"ball_socket\" or \"hinge\", got \"" + kind + "\"");
        }
    }
    if (const toml::node* a = entry.get("axis")) {
        c.axis = r.vec3(*a, key_name("axis"), "x, y, z");
        if (!(c.axis.norm() > 1e-9)) r.fail(*a, key_name("axis") + ": expected a non-zero vector");
        c.axis.normalize();
    }
    if (const toml::node* m = entry.get("end_mass")) c.end_mass = r.positive(*m, key_name("end_mass"));
    if (body.type != MotionType::Dynamic) r.fail(entry.source(), where + ": chain links must be dynamic bodies");
    return c;
}

// The anchor body and joints of one chain whose links start at scene.bodies[first].
void add_chain_joints(SceneDesc& scene, const Chain& chain, const Vec3& origin, std::uint32_t first,
                      const toml::source_position& at) {
    if (chain.end_mass > 0)
        scene.bodies[first + static_cast<std::uint32_t>(chain.links) - 1].desc.mass = chain.end_mass;
    ShapeSpec anchor_shape;
    anchor_shape.type = ShapeType::Sphere;
    anchor_shape.radius = 0.05;
    scene.shapes.push_back(anchor_shape);
    SceneBody anchor;
    anchor.desc.type = MotionType::Static;
    anchor.desc.position = origin;
    anchor.shape = static_cast<std::uint32_t>(scene.shapes.size() - 1);
    anchor.line = at.line;
    anchor.column = at.column;
    const auto anchor_index = static_cast<std::uint32_t>(scene.bodies.size());
    scene.bodies.push_back(anchor);
    for (std::int64_t i = 0; i < chain.links; ++i) {
        SceneJoint joint;
        const Vec3 at_link = origin + chain.direction * (chain.spacing * static_cast<Real>(i));
        joint.desc = chain.joint == JointType::Hinge ? JointDesc::hinge_at({}, {}, at_link, chain.axis)
                                                     : JointDesc::ball_socket_at({}, {}, at_link);
        joint.body_a = i == 0 ? anchor_index : first + static_cast<std::uint32_t>(i - 1);
        joint.body_b = first + static_cast<std::uint32_t>(i);
        joint.line = at.line;
        joint.column = at.column;
        scene.joints.push_back(joint);
    }
}

// What an entry kind accepts besides the body properties.
std::vector<std::string_view> own_keys(std::string_view kind) {
    if (kind == "body") return {"position", "copies"};
    if (kind == "stack") return {"position", "copies", "count", "gap", "spacing"};
    if (kind == "pyramid") return {"position", "copies", "layers", "spacing"};
    if (kind == "chain") return {"position", "copies", "links", "spacing", "direction", "joint", "axis", "end_mass"};
    return {"position", "copies", "base", "spacing"};  // pyramid_2d
}

}  // namespace

const std::vector<std::string_view>& entry_kinds() {
    static const std::vector<std::string_view> kinds = {"body", "stack", "pyramid", "pyramid_2d", "chain", "ragdoll"};
    return kinds;
}

void parse_entry(const TomlReader& r, std::string_view kind, const toml::table& entry, const BodyTemplate& defaults,
                 SceneDesc& scene) {
    const std::string where(kind);
    std::vector<std::string_view> allowed = body_property_keys();
    for (std::string_view key : own_keys(kind)) allowed.push_back(key);
    r.check_keys(entry, "[[" + where + "]]", allowed);

    BodyTemplate body = defaults;
    for (auto&& [key, value] : entry) apply_body_key(r, key.str(), value, where, body, scene);
    check_body_template(r, body, entry, where, scene);
    const Vec3 half = scene.shapes[*body.shape].half_size(body.desc.orientation);

    auto key_name = [&](const char* key) { return where + "." + key; };
    const Vec3 origin = entry.get("position") ? r.vec3(*entry.get("position"), key_name("position"), "x, y, z in m")
                                              : Vec3::Zero();
    const Copies copies = entry.get("copies") ? parse_copies(r, *entry.get("copies"), key_name("copies")) : Copies{};
    auto no_size = [&](const char* key) {
        r.fail(entry.source(), where + ": the shape has no size to space bodies by; give " + key_name(key));
    };

    double count = 1;  // bodies before copies, checked against the limit before any is made
    std::vector<Vec3> positions;
    Chain chain;
    if (kind == "chain") {
        chain = parse_chain(r, entry, where, half, body.desc);
        count = static_cast<double>(chain.links + 1);  // links and the static anchor
        const Real length = chain.spacing;
        if (count <= static_cast<double>(kMaxSceneBodies)) {
            for (std::int64_t i = 0; i < chain.links; ++i) {
                positions.push_back(origin + chain.direction * (length * (static_cast<Real>(i) + 0.5)));
            }
        }
    } else if (kind == "body") {
        positions.push_back(origin);
    } else if (kind == "stack") {
        const std::int64_t n = r.integer(r.require(entry, where, "count"), key_name("count"), 1, kMaxCount);
        const toml::node* gap = entry.get("gap");
        const toml::node* spacing = entry.get("spacing");
        if (gap && spacing) r.fail(*spacing, key_name("spacing") + ": not allowed together with gap");
        Real step = spacing ? r.positive(*spacing, key_name("spacing"))
                            : 2 * half.y() + (gap ? r.non_negative(*gap, key_name("gap")) : 0);
        if (!(step > 0)) no_size("spacing");
        count = static_cast<double>(n);
        if (count <= static_cast<double>(kMaxSceneBodies)) {
            for (std::int64_t i = 0; i < n; ++i) positions.push_back(origin + Vec3(0, step * static_cast<Real>(i), 0));
        }
    } else if (kind == "pyramid") {
        const std::int64_t layers = r.integer(r.require(entry, where, "layers"), key_name("layers"), 1, kMaxCount);
        Vec3 spacing = 2 * half;
        if (const toml::node* s = entry.get("spacing")) {
            spacing = r.positive_vec3(*s, key_name("spacing"), "sx, sy, sz: centre to centre, in m");
        } else if (!(spacing.array() > 0).all()) {
            no_size("spacing");
        }
        count = pyramid_count(layers);
        if (count <= static_cast<double>(kMaxSceneBodies)) positions = pyramid(origin, layers, spacing);
    } else {
        const std::int64_t base = r.integer(r.require(entry, where, "base"), key_name("base"), 1, kMaxCount);
        Real sx = 2 * half.x(), sy = 2 * half.y();
        if (const toml::node* s = entry.get("spacing")) {
            const std::vector<Real> v = r.numbers(*s, key_name("spacing"), 2, "sx, sy: centre to centre, in m");
            if (!(v[0] > 0) || !(v[1] > 0)) r.fail(*s, key_name("spacing") + ": expected two numbers > 0 (m)");
            sx = v[0];
            sy = v[1];
        } else if (!(sx > 0) || !(sy > 0)) {
            no_size("spacing");
        }
        count = static_cast<double>(base) * static_cast<double>(base + 1) / 2;
        if (count <= static_cast<double>(kMaxSceneBodies)) positions = pyramid_2d(origin, base, sx, sy);
    }

    const double total = count * copies.total();
    if (static_cast<double>(scene.bodies.size()) + total > static_cast<double>(kMaxSceneBodies)) {
        r.fail(entry.source(), where + ": makes " + show(total) + " bodies; a scene may have at most " +
                                   std::to_string(kMaxSceneBodies));
    }
    const toml::source_position at = entry.source().begin;
    reserve_bodies(scene, static_cast<std::size_t>(total));
    for (std::int64_t cz = 0; cz < copies.count[2]; ++cz) {
        for (std::int64_t cy = 0; cy < copies.count[1]; ++cy) {
            for (std::int64_t cx = 0; cx < copies.count[0]; ++cx) {
                const Vec3 offset(copies.step.x() * static_cast<Real>(cx), copies.step.y() * static_cast<Real>(cy),
                                  copies.step.z() * static_cast<Real>(cz));
                const auto first = static_cast<std::uint32_t>(scene.bodies.size());
                for (const Vec3& p : positions) {
                    SceneBody b;
                    b.desc = body.desc;
                    b.desc.position = p + offset;
                    b.shape = *body.shape;
                    b.line = at.line;
                    b.column = at.column;
                    scene.bodies.push_back(std::move(b));
                }
                if (kind == "chain") add_chain_joints(scene, chain, origin + offset, first, at);
            }
        }
    }
}

}  // namespace spindle::scene_detail
