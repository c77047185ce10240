#!/usr/bin/env bash
# Builds scripts/peers/jolt_delicate.cpp against the Jolt build folder named (the one holding
# libJolt.a and JoltConfig.cmake), with that build's own defines, instruction set and build type,
# so the program and the library agree on Jolt's configuration. Never needed by make run or test.
#
#   scripts/peers/build_jolt_delicate.sh JOLT_BUILD_DIR [OUT]   (OUT defaults to ./jolt_delicate)
set -euo pipefail

[[ $# -ge 1 ]] || { sed -n '6p' "$0" | sed 's/^#  */usage: /' >&2; exit 2; }
build=$(realpath -q "$1" || echo "$1")
out=$(realpath -m "${2:-jolt_delicate}")
here=$(dirname "$(realpath "$0")")
[[ -f $build/JoltConfig.cmake && -f $build/CMakeCache.txt ]] ||
    { echo "build_jolt_delicate: $build holds no configured Jolt build (no JoltConfig.cmake or CMakeCache.txt)" >&2; exit 2; }
config=$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$build/CMakeCache.txt")
ipo=$(sed -n 's/^INTERPROCEDURAL_OPTIMIZATION:BOOL=//p' "$build/CMakeCache.txt")

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.20)
project(jolt_delicate CXX)
find_package(Jolt REQUIRED CONFIG PATHS "$build" NO_DEFAULT_PATH)
add_executable(jolt_delicate "$here/jolt_delicate.cpp")
target_link_libraries(jolt_delicate PRIVATE Jolt::Jolt)
set_target_properties(jolt_delicate PROPERTIES CXX_STANDARD 17 INTERPROCEDURAL_OPTIMIZATION ${ipo:-OFF})
CMAKE
cmake -S "$work" -B "$work/build" -DCMAKE_BUILD_TYPE="${config:-Release}" >/dev/null
cmake --build "$work/build" >/dev/null
cp "$work/build/jolt_delicate" "$out"
echo "$out"
