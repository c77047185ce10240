// Scene entries that make bodies: [[body]] (one), [[stack]] (a column), [[pyramid]]
// (Jolt's 3D pyramid), [[pyramid_2d]] (a wall-like triangle), each optionally
// repeated on a grid by `copies`, so that big scenes stay short.
#include <spindle/engine/scene.hpp>

#include <array>

#include "scene_parts.hpp"

namespace spindle::scene_detail {
namespace {

constexpr std::int64_t kMaxCount = 1'000'000;

// copies = { count = [nx, ny, nz], step = [dx, dy, dz] }: the entry's bodies repeated
// nx * ny * nz times, copy (i, j, k) moved by (i dx, j dy, k dz).
struct Copies {
    std::array<std::int64_t, 3> count{1, 1, 1};
    Vec3 step = Vec3::Zero();
    double total() const { return static_cast<double>(count[0]) * static_cast<double>(count[1]) * count[2]; }
};

Copies parse_copies(const TomlReader& r, const toml::node& node, const std::string& what) {
    const toml::table& t = r.table(node, what, "{ count = [nx, ny, nz], step = [dx, dy, dz] }");
    r.check_keys(t, what, {"count", "step"});
    Copies c;
    const toml::node& count = r.require(t, what, "count");
    const toml::array* list = count.as_array();
    if (!list || list->size() != 3) r.fail(count, what + ".count: expected [nx, ny, nz], three integers >= 1");
    for (std::size_t i = 0; i < 3; ++i) c.count[i] = r.integer(*list->get(i), what + ".count", 1, kMaxCount);
    c.step = r.vec3(r.require(t, what, "step"), what + ".step", "dx, dy, dz in m");
    return c;
}

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

// What an entry kind accepts besides the body properties.
std::vector<std::string_view> own_keys(std::string_view kind) {
    if (kind == "body") return {"position", "copies"};
    if (kind == "stack") return {"position", "copies", "count", "gap", "spacing"};
    if (kind == "pyramid") return {"position", "copies", "layers", "spacing"};
    return {"position", "copies", "base", "spacing"};  // pyramid_2d
}

}  // namespace

const std::vector<std::string_view>& entry_kinds() {
    static const std::vector<std::string_view> kinds = {"body", "stack", "pyramid", "pyramid_2d"};
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
    if (kind == "body") {
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
    scene.bodies.reserve(scene.bodies.size() + static_cast<std::size_t>(total));
    for (std::int64_t cz = 0; cz < copies.count[2]; ++cz) {
        for (std::int64_t cy = 0; cy < copies.count[1]; ++cy) {
            for (std::int64_t cx = 0; cx < copies.count[0]; ++cx) {
                const Vec3 offset(copies.step.x() * static_cast<Real>(cx), copies.step.y() * static_cast<Real>(cy),
                                  copies.step.z() * static_cast<Real>(cz));
                for (const Vec3& p : positions) {
                    SceneBody b;
                    b.desc = body.desc;
                    b.desc.position = p + offset;
                    b.shape = *body.shape;
                    b.line = at.line;
                    b.column = at.column;
                    scene.bodies.push_back(std::move(b));
                }
            }
        }
    }
}

}  // namespace spindle::scene_detail
