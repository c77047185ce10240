#!/usr/bin/env bash
# Jolt's PerformanceTest beside `spindle bench` on the same scenes, in alternating pairs
# (issue 19): this VM switches between a fast and a slow mode within minutes, so only a pair
# run back to back compares. Jolt is not part of Spindle's build: build its PerformanceTest
# yourself (jrouwe/JoltPhysics, cmake -S Build -DCMAKE_BUILD_TYPE=Distribution, target PerformanceTest).
#
#   scripts/peers/jolt_side_by_side.sh JOLT_PERFORMANCETEST SPINDLE [PAIRS] [THREADS...] [-- SCENE...]
#
# Scenes by Jolt's names: Pyramid, ConvexVsMesh, Ragdoll (Spindle's pyramid, convex_vs_mesh,
# ragdolls; configs/scenes says how each differs). Both run STEPS steps at 60 Hz (default 500,
# PerformanceTest's own), Jolt with -q=Discrete -t=THREADS and -f, whose per-frame times let its
# first step be left out as Spindle's ms_per_step leaves it out. Jolt's Ragdoll needs its
# Assets folder (Human.tof, terrain2.bof) above the program or in the current directory.
#
# Prints one line per pair: scene, threads, both engines' steps/s after the first step, their
# first steps in ms and their hashes; then the medians per scene and thread count.
set -euo pipefail

usage() { sed -n '7p' "$0" | sed 's/^#  */usage: /' >&2; exit 2; }
[[ $# -ge 2 ]] || usage
jolt=$(realpath -q "$1" || echo "$1")
spindle=$(realpath -q "$2" || echo "$2")
here=$(dirname "$(realpath "$0")")
shift 2
[[ -f $jolt && -x $jolt ]] || { echo "jolt_side_by_side: $jolt is not an executable" >&2; exit 2; }
[[ -f $spindle && -x $spindle ]] || { echo "jolt_side_by_side: $spindle is not an executable" >&2; exit 2; }
pairs=3
if [[ $# -gt 0 && $1 != -- ]]; then pairs=$1; shift; fi
[[ $pairs =~ ^[1-9][0-9]*$ ]] || { echo "jolt_side_by_side: PAIRS must be a positive count, got '$pairs'" >&2; exit 2; }
threads=()
while [[ $# -gt 0 && $1 != -- ]]; do
    [[ $1 =~ ^[1-9][0-9]*$ ]] || { echo "jolt_side_by_side: a thread count must be positive, got '$1'" >&2; exit 2; }
    threads+=("$1")
    shift
done
[[ ${#threads[@]} -gt 0 ]] || threads=(1 2)
[[ $# -gt 0 && $1 == -- ]] && shift
steps=${STEPS:-500}
[[ $steps =~ ^[1-9][0-9]*$ && $steps -ge 2 ]] || { echo "jolt_side_by_side: STEPS must be 2 or more, got '$steps'" >&2; exit 2; }

# Jolt's name, then Spindle's built-in scene that reproduces it (configs/scenes).
declare -A spindle_name=([Pyramid]=pyramid [ConvexVsMesh]=convex_vs_mesh [Ragdoll]=ragdolls)
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(Pyramid ConvexVsMesh)
for scene in "${scenes[@]}"; do
    [[ -n ${spindle_name[$scene]:-} ]] || {
        echo "jolt_side_by_side: unknown scene '$scene' (known: Pyramid ConvexVsMesh Ragdoll)" >&2
        exit 2
    }
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
results="$work/results"

for scene in "${scenes[@]}"; do
    for t in "${threads[@]}"; do
        for ((p = 1; p <= pairs; p++)); do
            rm -f "$work"/per_frame_*.csv
            if ! out=$(cd "$work" && "$jolt" -s="$scene" -t="$t" -q=Discrete -i="$steps" -f 2>&1); then
                echo "jolt_side_by_side: Jolt's PerformanceTest failed on $scene:" >&2
                echo "$out" | tail -3 >&2
                exit 1
            fi
            jhash=$(sed -n 's/^Discrete, [0-9]*, [0-9.]*, \(0x[0-9a-f]*\)$/\1/p' <<<"$out" | head -1)
            csv="$work/per_frame_discrete_th$t.csv"
            [[ -n $jhash && -s $csv ]] || { echo "jolt_side_by_side: no result from Jolt for $scene" >&2; exit 1; }
            # Frame 0 is the first step; the rest give steps/s as Spindle's ms_per_step does.
            read -r jfirst jrate < <(awk -F', ' 'NR == 2 { first = $2 } NR > 2 { sum += $2; n++ }
                END { printf "%.3f %.1f\n", first, n * 1000 / sum }' "$csv")
            line=$("$spindle" bench "${spindle_name[$scene]}" --threads "$t" --steps "$steps")
            sms=$(sed -n 's/.* ms_per_step=\([0-9.]*\).*/\1/p' <<<"$line")
            sfirst=$(sed -n 's/.* first_step_ms=\([0-9.]*\).*/\1/p' <<<"$line")
            shash=$(sed -n 's/.* hash=\(0x[0-9a-f]*\).*/\1/p' <<<"$line")
            [[ -n $sms && -n $shash ]] || { echo "jolt_side_by_side: no result from Spindle for $scene" >&2; exit 1; }
            sp=$(awk -v ms="$sms" 'BEGIN { printf "%.1f", 1000 / ms }')
            echo "$scene threads=$t steps=$steps jolt=$jrate spindle=$sp ratio=$(awk -v a="$sp" -v b="$jrate" 'BEGIN { printf "%.2f", a / b }')" \
                "jolt_first_ms=$jfirst spindle_first_ms=$sfirst jolt_hash=$jhash spindle_hash=$shash" | tee -a "$results"
        done
    done
done

echo "medians (steps/s after the first step; ratio = Spindle / Jolt, the median of the pairs' ratios; first steps in ms):"
for scene in "${scenes[@]}"; do
    for t in "${threads[@]}"; do
        grep "^$scene threads=$t " "$results" |
            awk -f "$here/medians.awk" -v name="$scene" -v t="$t" -v fields="jolt spindle ratio jolt_first_ms spindle_first_ms" \
                -v labels="Jolt,Spindle,ratio,first step: Jolt,Spindle"
    done
done
