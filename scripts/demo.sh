#!/usr/bin/env bash
# make demo: render the built-in Cornell box at 16 spp with every buffer, denoise it with EAW and
# SURE, and say where the pictures are.
set -euo pipefail
BUILD=${1:-build}
OUT=out/demo
"$BUILD/atrous" render --scene cornell --width 512 --height 512 --spp 16 --seed 1 --out "$OUT" --denoise eaw,sure
echo
echo "demo: images in $OUT/"
ls -1 "$OUT" | sed 's/^/  /'
