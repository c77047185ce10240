// Scenes the program knows: the built-in ones (configs/scenes/*.toml, embedded in the
// binary at build time) and scene files named on the command line.
#pragma once

#include <span>
#include <string>
#include <string_view>

#include <spindle/scene/scene.hpp>

namespace spindle::app {

struct BuiltinScene {
    const char* name;    // file name without .toml
    const char* source;  // "configs/scenes/<name>.toml", for error messages
    std::string_view text;
};

// Every built-in scene, sorted by name (generated: builtin_scenes.cpp).
std::span<const BuiltinScene> builtin_scenes() noexcept;

// What `spindle run` runs without a scene argument: every shape falling on a mesh
// terrain, lively and light enough to run in real time on one core (the 1240-box
// pyramid is the benchmark, not the demo).
inline constexpr std::string_view kDefaultScene = "pile";

// Empty when the argument is a built-in scene's name or the path of a scene file
// (anything with a '/' or ending in .toml); otherwise what is wrong, listing the
// built-in scenes. The commands check their SCENE with it, so that an unknown name is
// a bad command line.
std::string check_scene(const std::string& name_or_path);

// The scene check_scene accepted: a bad file is a spindle::Error naming
// file:line:column (as is an unknown name, which check_scene would have refused).
SceneDesc resolve_scene(const std::string& name_or_path);

}  // namespace spindle::app
