#!/usr/bin/env bash
# The CI-sized check of the third-party corpus (docs/corpus.md; make test runs it): renders the quick
# corpus with Mitsuba 3 and Blender Cycles (scripts/corpus/render.py --quick: 64x64 stills of 2 scenes
# per renderer at 4 and 16 spp with 256-spp references; it installs .venv-corpus the first time,
# ~450 MB, and skips what is already rendered) and checks `atrous denoise` on each file as a user
# hands it over against tests/corpus/quick_bounds.json: each scene/spp/method's relMSE at most
# 1.25x its value when the bounds were written (the renders are seeded: two renders of the quick
# set gave relMSE equal to 4 digits). Usage: scripts/corpus_check.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${1:-build}"
python3 scripts/corpus/render.py --quick
# --max-ratio 1: every filter's relMSE below the noisy input's on every quick case (docs/quality.md).
python3 scripts/corpus/cli_quality.py --corpus out/corpus/quick --atrous "$BUILD/atrous" --methods eaw,sure,blend --bounds tests/corpus/quick_bounds.json \
    --max-ratio 1
