// Built-in scene lookup, scene files from the command line, and `spindle scenes`.
#include "scenes.hpp"

#include "commands.hpp"

#include <cstdio>
#include <iostream>

namespace spindle::app {
namespace {

std::string builtin_names() {
    std::string names;
    for (const BuiltinScene& s : builtin_scenes()) names += std::string(names.empty() ? "" : ", ") + s.name;
    return names;
}

bool looks_like_path(std::string_view arg) {
    return arg.find('/') != std::string_view::npos ||
           (arg.size() > 5 && arg.substr(arg.size() - 5) == ".toml");
}

}  // namespace

SceneDesc resolve_scene(const std::string& name_or_path) {
    if (looks_like_path(name_or_path)) return load_scene(name_or_path);
    for (const BuiltinScene& s : builtin_scenes()) {
        if (name_or_path == s.name) return parse_scene(s.text, s.source);
    }
    throw UsageError("unknown scene '" + name_or_path + "' (built-in scenes: " + builtin_names() +
                     "; or give the path of a .toml scene file)");
}

int scenes_command(Args& args) {
    if (args.help()) {
        std::cout << "usage: spindle scenes\n"
                     "Lists the built-in scenes (configs/scenes/*.toml, embedded in the program) with their\n"
                     "dynamic and other (static, kinematic) body counts. Run one with `spindle run NAME`.\n";
        return 0;
    }
    args.positionals(0);
    std::printf("%-16s %8s %7s  %s\n", "scene", "dynamic", "other", "description");
    for (const BuiltinScene& s : builtin_scenes()) {
        const SceneDesc scene = parse_scene(s.text, s.source);
        const std::size_t dynamic = scene.dynamic_body_count();
        std::printf("%-16s %8zu %7zu  %s%s\n", s.name, dynamic, scene.bodies.size() - dynamic,
                    scene.description.c_str(), s.name == kDefaultScene ? " (default)" : "");
    }
    return 0;
}

}  // namespace spindle::app
