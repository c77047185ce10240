#!/usr/bin/env bash
# Box3D's benchmark program beside `spindle bench` on the same scenes, in alternating
# pairs (issue 19): this VM switches between a fast and a slow mode within minutes, so
# only a pair run back to back compares. Box3D is not part of Spindle's build: build its
# `benchmark` program yourself (erincatto/box3d, cmake -DBOX3D_BENCHMARKS=ON, Release).
#
#   scripts/peers/side_by_side.sh BOX3D_BENCHMARK SPINDLE [PAIRS] [THREADS...] [-- SCENE...]
#
# Prints one line per pair: scene, threads, Box3D's and Spindle's steps/s with the first
# step left out (as Box3D's program leaves it out), and Spindle's state hash; then the
# medians per scene and thread count.
set -euo pipefail

usage() { sed -n '6p' "$0" | sed 's/^#  */usage: /' >&2; exit 2; }
[[ $# -ge 2 ]] || usage
box3d=$(realpath "$1")
spindle=$(realpath "$2")
here=$(dirname "$(realpath "$0")")
shift 2
[[ -x $box3d ]] || { echo "side_by_side: $box3d is not an executable" >&2; exit 2; }
[[ -x $spindle ]] || { echo "side_by_side: $spindle is not an executable" >&2; exit 2; }
pairs=3
if [[ $# -gt 0 && $1 != -- ]]; then pairs=$1; shift; fi
threads=()
while [[ $# -gt 0 && $1 != -- ]]; do threads+=("$1"); shift; done
[[ ${#threads[@]} -gt 0 ]] || threads=(1 2)
[[ $# -gt 0 && $1 == -- ]] && shift
# Box3D's name, then Spindle's built-in scene that reproduces it (configs/scenes).
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(large_pyramid many_pyramids joint_grid convex_pile washer junkyard trees100 rain large_world)
spindle_name() { [[ $1 == trees100 ]] && echo trees || echo "$1"; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
results="$work/results"

for scene in "${scenes[@]}"; do
    for t in "${threads[@]}"; do
        for ((p = 1; p <= pairs; p++)); do
            out=$(cd "$work" && "$box3d" -t="$t" -w="$t" --benchmark="$scene" -r=1)
            steps=$(sed -n 's/.*steps = \([0-9]*\).*/\1/p' <<<"$out" | head -1)
            ms=$(sed -n 's/^run 0 : \([0-9.e+]*\) (ms).*/\1/p' <<<"$out" | head -1)
            [[ -n $steps && -n $ms ]] || { echo "side_by_side: no result from Box3D for $scene" >&2; exit 1; }
            line=$("$spindle" bench "$(spindle_name "$scene")" --threads "$t" --steps "$steps")
            sms=$(sed -n 's/.* ms_per_step=\([0-9.]*\).*/\1/p' <<<"$line")
            hash=$(sed -n 's/.* hash=\(0x[0-9a-f]*\).*/\1/p' <<<"$line")
            b3=$(awk -v s="$steps" -v ms="$ms" 'BEGIN { printf "%.1f", (s - 1) * 1000 / ms }')
            sp=$(awk -v ms="$sms" 'BEGIN { printf "%.1f", 1000 / ms }')
            echo "$scene threads=$t steps=$steps box3d=$b3 spindle=$sp ratio=$(awk -v a="$sp" -v b="$b3" 'BEGIN { printf "%.2f", a / b }') hash=$hash" |
                tee -a "$results"
        done
    done
done

echo "medians (steps/s; ratio = Spindle / Box3D, the median of the pairs' ratios):"
for scene in "${scenes[@]}"; do
    for t in "${threads[@]}"; do
        grep "^$scene threads=$t " "$results" |
            awk -f "$here/medians.awk" -v name="$scene" -v t="$t" -v fields="box3d spindle ratio" -v labels="Box3D,Spindle,ratio"
    done
done
