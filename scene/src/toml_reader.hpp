// TomlReader: typed reads of toml++ nodes for the scene loader. Every read checks the
// type and range and, on failure, throws spindle::Error "source:line:column: <what> ..."
// at the offending node, so each parse function stays a list of keys.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include <spindle/engine/math.hpp>

namespace spindle::scene_detail {

class TomlReader {
public:
    explicit TomlReader(std::string_view source) : m_source(source) {}

    std::string_view source() const noexcept { return m_source; }

    [[noreturn]] void fail(const toml::source_region& where, const std::string& what) const;
    [[noreturn]] void fail(const toml::node& node, const std::string& what) const { fail(node.source(), what); }

    // Every key of `table` must be one of `allowed`; `where` names the table ("body", "settings").
    void check_keys(const toml::table& table, std::string_view where,
                    const std::vector<std::string_view>& allowed) const;
    // The node at `key` of `table`, or a failure at the table "where: missing key 'key'".
    const toml::node& require(const toml::table& table, std::string_view where, std::string_view key) const;

    // `what` is the dotted key ("body.friction") used in the message.
    Real number(const toml::node& node, std::string_view what) const;  // integer or float, finite
    Real positive(const toml::node& node, std::string_view what) const;
    Real non_negative(const toml::node& node, std::string_view what) const;
    std::int64_t integer(const toml::node& node, std::string_view what, std::int64_t min, std::int64_t max) const;
    bool boolean(const toml::node& node, std::string_view what) const;
    std::string string(const toml::node& node, std::string_view what) const;
    // An array of exactly n numbers.
    std::vector<Real> numbers(const toml::node& node, std::string_view what, std::size_t n,
                              std::string_view meaning) const;
    Vec3 vec3(const toml::node& node, std::string_view what, std::string_view meaning = "x, y, z") const;
    Vec3 positive_vec3(const toml::node& node, std::string_view what, std::string_view meaning) const;
    const toml::table& table(const toml::node& node, std::string_view what, std::string_view meaning) const;
    const toml::array& array(const toml::node& node, std::string_view what, std::string_view meaning) const;

private:
    std::string_view m_source;
};

// "a, b, c" for messages that list what was expected.
std::string join(const std::vector<std::string_view>& words);
// The number as TOML would write it, for "got ..." in messages.
std::string show(Real value);

}  // namespace spindle::scene_detail
