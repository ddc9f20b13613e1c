#!/usr/bin/env bash
# make bench: the main benchmark programs, JSON into out/bench/ (medians after warm-up, device
# named in each file). The full matrix (every size, CUDA rows, per-stage tables) is in
# docs/benchmarks.md with its commands.
set -euo pipefail
BUILD=${1:-build}
OUT=out/bench
mkdir -p "$OUT"
run() {  # name, command...
  local name=$1; shift
  echo "bench: $name"
  "$@" > "$OUT/$name.json.tmp" && mv "$OUT/$name.json.tmp" "$OUT/$name.json"
}
run render "$BUILD/bench/bench_render"
run denoise "$BUILD/bench/bench_denoise" --runs 20
run atrous_bench "$BUILD/atrous" bench --json --sizes 512x512,1920x1080
echo "bench: JSON in $OUT/"
ls -1 "$OUT"/*.json | sed 's/^/  /'
