// Command-line parsing for the spindle commands.
#include "args.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>

namespace spindle::app {
namespace {

// "-x" and "--x" are options; "-1" and "-.5" are (negative) values.
bool is_option(std::string_view arg) {
    return arg.size() > 1 && arg[0] == '-' && !std::isdigit(static_cast<unsigned char>(arg[1])) && arg[1] != '.';
}

std::string show(double value) {
    std::string s = std::to_string(value);
    s.erase(s.find_last_not_of('0') + 1);
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
}

}  // namespace

Args::Args(std::string command, std::vector<std::string> args)
    : m_command(std::move(command)), m_args(std::move(args)), m_used(m_args.size(), false) {}

bool Args::help() const {
    for (const std::string& a : m_args) {
        if (a == "--help" || a == "-h") return true;
    }
    return false;
}

std::optional<std::string> Args::option(std::string_view name) {
    const std::string flag = "--" + std::string(name);
    std::optional<std::string> value;
    for (std::size_t i = 0; i < m_args.size(); ++i) {
        if (m_used[i]) continue;
        const std::string& a = m_args[i];
        if (a == flag) {
            if (i + 1 >= m_args.size() || is_option(m_args[i + 1])) {
                throw UsageError(flag + ": missing value");
            }
            if (value) throw UsageError(flag + ": given twice");
            m_used[i] = m_used[i + 1] = true;
            value = m_args[++i];
        } else if (a.rfind(flag + "=", 0) == 0) {
            if (value) throw UsageError(flag + ": given twice");
            m_used[i] = true;
            value = a.substr(flag.size() + 1);
            if (value->empty()) throw UsageError(flag + ": missing value");
        }
    }
    return value;
}

bool Args::flag(std::string_view name) {
    const std::string flag = "--" + std::string(name);
    bool found = false;
    for (std::size_t i = 0; i < m_args.size(); ++i) {
        if (m_used[i]) continue;
        const std::string& a = m_args[i];
        if (a == flag) {
            m_used[i] = true;
            found = true;
        } else if (a.rfind(flag + "=", 0) == 0) {
            throw UsageError(flag + ": takes no value");
        }
    }
    return found;
}

std::optional<double> Args::number(std::string_view name, double min, double max) {
    const std::optional<std::string> text = option(name);
    if (!text) return std::nullopt;
    const std::string flag = "--" + std::string(name);
    char* end = nullptr;
    const double value = std::strtod(text->c_str(), &end);
    if (end == text->c_str() || *end != '\0' || !std::isfinite(value)) {
        throw UsageError(flag + ": expected a number, got '" + *text + "'");
    }
    if (value < min || value > max) {
        throw UsageError(flag + ": expected a number in [" + show(min) + ", " + show(max) + "], got " + *text);
    }
    return value;
}

std::optional<std::int64_t> Args::integer(std::string_view name, std::int64_t min, std::int64_t max) {
    const std::optional<std::string> text = option(name);
    if (!text) return std::nullopt;
    const std::string flag = "--" + std::string(name);
    std::int64_t value = 0;
    const char* first = text->data();
    const char* last = first + text->size();
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec != std::errc{} || ptr != last) throw UsageError(flag + ": expected an integer, got '" + *text + "'");
    if (value < min || value > max) {
        throw UsageError(flag + ": expected an integer in [" + std::to_string(min) + ", " + std::to_string(max) +
                         "], got " + *text);
    }
    return value;
}

std::vector<std::string> Args::positionals(std::size_t max) {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < m_args.size(); ++i) {
        if (m_used[i]) continue;
        if (is_option(m_args[i])) throw UsageError("unknown option '" + m_args[i] + "'");
        out.push_back(m_args[i]);
    }
    if (out.size() > max) throw UsageError("unexpected argument '" + out[max] + "'");
    return out;
}

}  // namespace spindle::app
