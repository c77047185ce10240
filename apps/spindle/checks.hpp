// Checks of command-line values that CLI11 does not make as the commands need them:
// numbers in a range, said in a user's words, and values that are not the next option.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>

namespace spindle::app {

// "-x" and "--x" are options; "-1" and "-.5" are (negative) values.
bool is_option(const std::string& arg);

// A finite number in [min, max], and not an option (see not_an_option). CLI11's Range
// says "Value -1 not in range 0.010000 to 1000000.000000" and lets inf through.
CLI::Validator real_in(double min, double max);

// A decimal integer in [min, max], rewritten to plain digits: CLI11 alone reads 010 as
// octal 8 and 0x10 as 16. For Option::transform, which may change the value.
CLI::Validator integer_in(std::int64_t min, std::int64_t max);

// A value that does not look like an option: CLI11 takes whatever follows an option as
// its value, so `run --trace --seconds 1` would write a trace file named --seconds.
CLI::Validator not_an_option();

// A flag given no value. CLI11 reads --flag=yes as true and, with disable_flag_override,
// refuses it as "flag was given a disallowed flag override"; this says "takes no value".
CLI::Validator no_value();

}  // namespace spindle::app
