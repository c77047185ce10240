#!/usr/bin/env bash
# The state this VM is in (issue 19): the round trip of a cache line between CPUs 0 and 1,
# before and after two threads compute beside one. Run it beside a benchmark to write down
# the mode measured, not guessed from the benchmark's own speed.
#
#   scripts/machine_state.sh [ROUNDS]
set -euo pipefail
rounds=${1:-1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
g++ -std=c++20 -O2 -pthread -o "$work/machine_state" "$(dirname "$(realpath "$0")")/machine_state.cpp"
for ((r = 0; r < rounds; r++)); do "$work/machine_state"; done
