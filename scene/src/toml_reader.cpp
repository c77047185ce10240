// TomlReader: typed, range-checked reads of toml++ nodes with file:line:column errors.
#include <spindle/platform/error.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "toml_reader.hpp"

namespace spindle::scene_detail {

std::string join(const std::vector<std::string_view>& words) {
    std::string out;
    for (std::string_view w : words) {
        if (!out.empty()) out += ", ";
        out += w;
    }
    return out;
}

std::string show(Real value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

namespace {

// What the node is, for "got a string" in messages.
std::string kind(const toml::node& node) {
    switch (node.type()) {
        case toml::node_type::string: return "a string";
        case toml::node_type::integer: return "the integer " + std::to_string(*node.value_exact<std::int64_t>());
        case toml::node_type::floating_point: return "the number " + show(*node.value_exact<double>());
        case toml::node_type::boolean: return "a boolean";
        case toml::node_type::array: return "an array";
        case toml::node_type::table: return "a table";
        default: return "a date or time";
    }
}

}  // namespace

void TomlReader::fail(const toml::source_region& where, const std::string& what) const {
    std::ostringstream out;
    out << m_source << ':' << where.begin.line << ':' << where.begin.column << ": " << what;
    throw Error(out.str());
}

void TomlReader::check_keys(const toml::table& table, std::string_view where,
                            const std::vector<std::string_view>& allowed) const {
    for (auto&& [key, node] : table) {
        if (std::find(allowed.begin(), allowed.end(), key.str()) == allowed.end()) {
            fail(key.source(), "unknown key '" + std::string(key.str()) + "' in " + std::string(where) +
                                   " (expected one of: " + join(allowed) + ")");
        }
    }
}

const toml::node& TomlReader::require(const toml::table& table, std::string_view where, std::string_view key) const {
    const toml::node* node = table.get(key);
    if (!node) fail(table.source(), std::string(where) + ": missing key '" + std::string(key) + "'");
    return *node;
}

Real TomlReader::number(const toml::node& node, std::string_view what) const {
    std::optional<double> value;
    if (node.is_integer()) value = static_cast<double>(*node.value_exact<std::int64_t>());
    if (node.is_floating_point()) value = *node.value_exact<double>();
    if (!value) fail(node, std::string(what) + ": expected a number, got " + kind(node));
    if (!std::isfinite(*value)) fail(node, std::string(what) + ": expected a finite number, got " + show(*value));
    return *value;
}

Real TomlReader::positive(const toml::node& node, std::string_view what) const {
    const Real value = number(node, what);
    if (!(value > 0)) fail(node, std::string(what) + ": expected a number > 0, got " + show(value));
    return value;
}

Real TomlReader::non_negative(const toml::node& node, std::string_view what) const {
    const Real value = number(node, what);
    if (!(value >= 0)) fail(node, std::string(what) + ": expected a number >= 0, got " + show(value));
    return value;
}

std::int64_t TomlReader::integer(const toml::node& node, std::string_view what, std::int64_t min,
                                 std::int64_t max) const {
    const auto value = node.value_exact<std::int64_t>();
    if (!value) fail(node, std::string(what) + ": expected an integer, got " + kind(node));
    if (*value < min || *value > max) {
        fail(node, std::string(what) + ": expected an integer in [" + std::to_string(min) + ", " + std::to_string(max) +
                       "], got " + std::to_string(*value));
    }
    return *value;
}

bool TomlReader::boolean(const toml::node& node, std::string_view what) const {
    const auto value = node.value_exact<bool>();
    if (!value) fail(node, std::string(what) + ": expected true or false, got " + kind(node));
    return *value;
}

std::string TomlReader::string(const toml::node& node, std::string_view what) const {
    const auto value = node.value_exact<std::string>();
    if (!value) fail(node, std::string(what) + ": expected a string, got " + kind(node));
    return *value;
}

std::vector<Real> TomlReader::numbers(const toml::node& node, std::string_view what, std::size_t n,
                                      std::string_view meaning) const {
    const toml::array* list = node.as_array();
    if (!list || list->size() != n) {
        fail(node, std::string(what) + ": expected an array of " + std::to_string(n) + " numbers [" +
                       std::string(meaning) + "], got " +
                       (list ? "an array of " + std::to_string(list->size()) : kind(node)));
    }
    std::vector<Real> values;
    values.reserve(n);
    for (const toml::node& entry : *list) values.push_back(number(entry, what));
    return values;
}

Vec3 TomlReader::vec3(const toml::node& node, std::string_view what, std::string_view meaning) const {
    const std::vector<Real> v = numbers(node, what, 3, meaning);
    return {v[0], v[1], v[2]};
}

Vec3 TomlReader::positive_vec3(const toml::node& node, std::string_view what, std::string_view meaning) const {
    const Vec3 v = vec3(node, what, meaning);
    const toml::array& list = *node.as_array();  // vec3 checked it is an array of 3
    for (int i = 0; i < 3; ++i) {
        if (!(v[i] > 0)) {
            fail(*list.get(static_cast<std::size_t>(i)),
                 std::string(what) + ": expected numbers > 0 [" + std::string(meaning) + "], got " + show(v[i]));
        }
    }
    return v;
}

const toml::table& TomlReader::table(const toml::node& node, std::string_view what, std::string_view meaning) const {
    const toml::table* t = node.as_table();
    if (!t) fail(node, std::string(what) + ": expected a table " + std::string(meaning) + ", got " + kind(node));
    return *t;
}

const toml::array& TomlReader::array(const toml::node& node, std::string_view what, std::string_view meaning) const {
    const toml::array* a = node.as_array();
    if (!a) fail(node, std::string(what) + ": expected an array " + std::string(meaning) + ", got " + kind(node));
    return *a;
}

}  // namespace spindle::scene_detail
