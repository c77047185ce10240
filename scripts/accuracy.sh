#!/usr/bin/env bash
# Regenerates docs/accuracy.md and docs/accuracy.png from a fresh accuracy sweep.
# usage: scripts/accuracy.sh BUILD_DIR [bench_accuracy flags...]   (make accuracy calls it)
set -euo pipefail

build=${1:?usage: scripts/accuracy.sh BUILD_DIR [flags...]}
shift
root=$(cd "$(dirname "$0")/.." && pwd)
out="$build/accuracy"   # CSV, plot data and script beside the program: build products, not docs
mkdir -p "$out"
command -v gnuplot >/dev/null || { echo "accuracy: gnuplot not found (scripts/setup.sh installs gnuplot-nox)" >&2; exit 1; }

start=$SECONDS
"$build/accuracy/bench_accuracy" --out "$out" --docs "$root/docs" "$@"
gnuplot "$out/accuracy.gp"
echo "accuracy: docs/accuracy.md, docs/accuracy.png and $out/accuracy.csv in $((SECONDS - start)) s"
