// Command-line arguments of one spindle command: options (--name VALUE or
// --name=VALUE), flags and positionals, with a UsageError naming what was wrong.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace spindle::app {

// A bad command line. main() prints it with the command's name and exits with 2.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class Args {
public:
    Args(std::string command, std::vector<std::string> args);

    const std::string& command() const noexcept { return m_command; }
    // --help or -h anywhere.
    bool help() const;

    // The value of --name, or none when absent. "--name" last, or followed by another
    // option, is a missing value.
    std::optional<std::string> option(std::string_view name);
    std::optional<double> number(std::string_view name, double min, double max);
    std::optional<std::int64_t> integer(std::string_view name, std::int64_t min, std::int64_t max);
    // True when --name is given (a flag takes no value: --name=VALUE is a usage error).
    bool flag(std::string_view name);

    // What is left, after every option was taken: unknown options and more than
    // `max` positionals are usage errors.
    std::vector<std::string> positionals(std::size_t max);

private:
    std::string m_command;
    std::vector<std::string> m_args;
    std::vector<bool> m_used;
};

}  // namespace spindle::app
