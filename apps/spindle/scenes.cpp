// Built-in scene lookup, scene files from the command line, and `spindle scenes`.
#include "scenes.hpp"

#include <spindle/platform/error.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>

#include "commands.hpp"

namespace spindle::app {
namespace {

std::string builtin_names() {
    std::string names;
    for (const BuiltinScene& s : builtin_scenes()) names += std::string(names.empty() ? "" : ", ") + s.name;
    return names;
}

bool looks_like_path(std::string_view arg) {
    return arg.find('/') != std::string_view::npos || (arg.size() > 5 && arg.substr(arg.size() - 5) == ".toml");
}

const BuiltinScene* find_builtin(std::string_view name) {
    for (const BuiltinScene& s : builtin_scenes()) {
        if (name == s.name) return &s;
    }
    return nullptr;
}

}  // namespace

std::string check_scene(const std::string& name_or_path) {
    if (looks_like_path(name_or_path) || find_builtin(name_or_path)) return {};
    return "unknown scene '" + name_or_path + "' (built-in scenes: " + builtin_names() +
           "; or give the path of a .toml scene file)";
}

SceneDesc resolve_scene(const std::string& name_or_path) {
    if (looks_like_path(name_or_path)) return load_scene(name_or_path);
    if (const BuiltinScene* s = find_builtin(name_or_path)) return parse_scene(s->text, s->source);
    throw Error(check_scene(name_or_path));
}

namespace {

int list_scenes() {
    std::printf("%-16s %8s %7s  %s\n", "scene", "dynamic", "other", "description");
    for (const BuiltinScene& s : builtin_scenes()) {
        const SceneDesc scene = parse_scene(s.text, s.source);
        const std::size_t dynamic = scene.dynamic_body_count();
        std::printf("%-16s %8zu %7zu  %s%s\n", s.name, dynamic, scene.bodies.size() - dynamic,
                    scene.description.c_str(), s.name == kDefaultScene ? " (default)" : "");
    }
    return 0;
}

}  // namespace

Command add_scenes_command(CLI::App& program) {
    CLI::App* cli = program.add_subcommand("scenes", "list the built-in scenes");
    cli->footer("Lists the built-in scenes (configs/scenes/*.toml, embedded in the program) with their\n"
                "dynamic and other (static, kinematic) body counts. Run one with `spindle run NAME`.");
    return {cli, list_scenes};
}

}  // namespace spindle::app
