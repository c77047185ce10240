# Writes OUTPUT, a C++ file holding every SCENE_DIR/*.toml as a raw string literal
# (run at build time by apps/CMakeLists.txt: cmake -DSCENE_DIR=.. -DOUTPUT=.. -P embed_scenes.cmake).
file(GLOB files ${SCENE_DIR}/*.toml)
list(SORT files)
set(delimiter "spindle_scene")
set(entries "")
foreach(file ${files})
  get_filename_component(name ${file} NAME_WE)
  file(READ ${file} text)
  string(FIND "${text}" ")${delimiter}\"" clash)
  if(NOT clash EQUAL -1)
    message(FATAL_ERROR "${file} contains the raw-string delimiter )${delimiter}\"")
  endif()
  string(APPEND entries "    {\"${name}\", \"configs/scenes/${name}.toml\", R\"${delimiter}(${text})${delimiter}\"},\n")
endforeach()
set(content "// Generated from configs/scenes/*.toml by apps/embed_scenes.cmake; do not edit.
#include \"scenes.hpp\"

namespace spindle::app {
namespace {
constexpr BuiltinScene kScenes[] = {
${entries}};
}  // namespace

std::span<const BuiltinScene> builtin_scenes() noexcept { return kScenes; }

}  // namespace spindle::app
")
file(WRITE ${OUTPUT} "${content}")
