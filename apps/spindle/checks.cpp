// Checks of command-line values: numbers in a range, values that are not options.
#include "checks.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>

namespace spindle::app {
namespace {

// 0.01 and 1000000, not 0.010000 and 1e+06.
std::string show(double value) {
    std::string s = std::to_string(value);
    s.erase(s.find_last_not_of('0') + 1);
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
}

std::string missing_value(const std::string& option) { return "missing value (got the option '" + option + "')"; }

}  // namespace

bool is_option(const std::string& arg) {
    return arg.size() > 1 && arg[0] == '-' && !std::isdigit(static_cast<unsigned char>(arg[1])) && arg[1] != '.';
}

CLI::Validator real_in(double min, double max) {
    return CLI::Validator(
        [min, max](std::string& text) -> std::string {
            if (is_option(text)) return missing_value(text);
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value)) {
                return "expected a number, got '" + text + "'";
            }
            if (value < min || value > max) {
                return "expected a number in [" + show(min) + ", " + show(max) + "], got " + text;
            }
            return {};
        },
        "", "real_in");
}

CLI::Validator integer_in(std::int64_t min, std::int64_t max) {
    return CLI::Validator(
        [min, max](std::string& text) -> std::string {
            if (is_option(text)) return missing_value(text);
            std::int64_t value = 0;
            const char* last = text.data() + text.size();
            const auto [ptr, ec] = std::from_chars(text.data(), last, value);
            if (text.empty() || ec != std::errc{} || ptr != last) return "expected an integer, got '" + text + "'";
            if (value < min || value > max) {
                return "expected an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " + text;
            }
            text = std::to_string(value);
            return {};
        },
        "", "integer_in");
}

CLI::Validator not_an_option() {
    return CLI::Validator(
        [](std::string& text) -> std::string { return is_option(text) ? missing_value(text) : std::string(); }, "",
        "not_an_option");
}

CLI::Validator no_value() {
    // CLI11 gives a flag without a value the result "true" (as it would --flag=true).
    return CLI::Validator(
        [](std::string& text) -> std::string {
            return text == "true" ? std::string() : "takes no value, got '" + text + "'";
        },
        "", "no_value");
}

}  // namespace spindle::app
