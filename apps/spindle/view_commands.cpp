// The view page's commands, parsed without trusting a byte of them (view_commands.hpp).
#include "view_commands.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <vector>

namespace spindle::app {
namespace {

struct Verb {
    std::string_view name;
    ViewAction action;
    int numbers;  // how many numbers follow the verb
    bool live;    // meaningful while the physics runs
    bool replay;  // meaningful in a replay
};

constexpr std::array<Verb, 12> kVerbs = {{
    {"pause", ViewAction::Pause, 0, true, true},
    {"resume", ViewAction::Resume, 0, true, true},
    {"step", ViewAction::Step, 0, true, true},
    {"drop", ViewAction::Drop, 0, true, false},
    {"release", ViewAction::Release, 0, true, false},
    {"speed", ViewAction::Speed, 1, true, true},
    {"interpolate", ViewAction::Interpolate, 1, true, false},  // on|off, read as 1|0
    {"contacts", ViewAction::Contacts, 1, true, false},        // on|off, read as 1|0
    {"shoot", ViewAction::Shoot, 6, true, false},
    {"grab", ViewAction::Grab, 6, true, false},
    {"drag", ViewAction::Drag, 6, true, false},
    {"seek", ViewAction::Seek, 1, false, true},
}};

ParsedCommand fail(std::string message) { return {false, {}, std::move(message)}; }

// Printable text only: the words are echoed into error messages and the log.
bool printable(std::string_view text) {
    for (const char c : text) {
        if (c < 0x20 || c > 0x7e) return false;
    }
    return true;
}

std::vector<std::string_view> split(std::string_view text) {
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < text.size()) {
        while (i < text.size() && text[i] == ' ') ++i;
        const std::size_t start = i;
        while (i < text.size() && text[i] != ' ') ++i;
        if (i > start) words.push_back(text.substr(start, i - start));
    }
    return words;
}

bool to_number(std::string_view word, double& out) {
    const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), out);
    return error == std::errc() && end == word.data() + word.size() && std::isfinite(out);
}

}  // namespace

ParsedCommand parse_view_command(std::string_view text, bool replay) {
    if (text.size() > kMaxCommandBytes) {
        return fail("command of " + std::to_string(text.size()) + " bytes, at most " +
                    std::to_string(kMaxCommandBytes) + " allowed");
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
    if (!printable(text)) return fail("command holds a byte that is not printable ASCII");
    const std::vector<std::string_view> words = split(text);
    if (words.empty()) return fail("empty command");
    const std::string verb(words[0]);
    const Verb* found = nullptr;
    for (const Verb& v : kVerbs) {
        if (v.name == verb) found = &v;
    }
    if (!found) return fail("unknown command '" + verb + "'");
    if (replay ? !found->replay : !found->live) {
        return fail("'" + verb + "' " + (replay ? "is not for a replay" : "is only for a replay"));
    }
    const int given = static_cast<int>(words.size()) - 1;
    if (given != found->numbers) {
        return fail("'" + verb + "' takes " + std::to_string(found->numbers) + " value" +
                    (found->numbers == 1 ? "" : "s") + ", got " + std::to_string(given));
    }

    ViewCommand command;
    command.action = found->action;
    if (found->action == ViewAction::Interpolate || found->action == ViewAction::Contacts) {
        if (words[1] != "on" && words[1] != "off") {
            return fail("'" + verb + "' takes on or off, got '" + std::string(words[1]) + "'");
        }
        command.value = words[1] == "on" ? 1 : 0;
        return {true, command, {}};
    }
    std::array<double, 6> numbers{};
    for (int i = 0; i < given; ++i) {
        if (!to_number(words[static_cast<std::size_t>(i) + 1], numbers[static_cast<std::size_t>(i)])) {
            return fail("'" + verb + "': value " + std::to_string(i + 1) + " '" +
                        std::string(words[static_cast<std::size_t>(i) + 1]) + "' is not a finite number");
        }
    }
    switch (found->action) {
        case ViewAction::Speed: {
            const double max = replay ? 8 : 1;
            if (numbers[0] < 0.01 || numbers[0] > max) {
                return fail("'speed' must be in 0.01.." + std::string(replay ? "8" : "1 (slow motion)") + ", got " +
                            std::string(words[1]));
            }
            command.value = numbers[0];
            break;
        }
        case ViewAction::Seek:
            if (numbers[0] < 0) return fail("'seek' must be >= 0 seconds, got " + std::string(words[1]));
            command.value = numbers[0];
            break;
        case ViewAction::Shoot:
        case ViewAction::Grab:
        case ViewAction::Drag: {
            const Vec3 origin(numbers[0], numbers[1], numbers[2]);
            const Vec3 direction(numbers[3], numbers[4], numbers[5]);
            if (origin.cwiseAbs().maxCoeff() > kMaxCoordinate) {
                return fail("'" + verb + "': the ray's origin is further than " + std::to_string(int(kMaxCoordinate)) +
                            " m out");
            }
            if (!(direction.norm() > 1e-9) || !std::isfinite(direction.squaredNorm())) {
                return fail("'" + verb + "': the ray's direction has no length");
            }
            command.origin = origin;
            command.direction = direction.normalized();
            break;
        }
        default: break;
    }
    return {true, command, {}};
}

}  // namespace spindle::app
