#!/usr/bin/env bash
# `make sanitize` (docs/reliability.md): an AddressSanitizer + UBSan build in build-asan/ (its own
# tree), then the whole ctest suite and the fuzz harness's CI subset against it. Image buffers come
# from the C allocator there (ATROUS_SANITIZE, src/core/image.cpp) so ASan sees them; UBSan stops at
# the first finding (-fno-sanitize-recover), so "0 findings" is "every test passed".
# Usage: scripts/sanitize.sh [BUILD_DIR] (default build-asan); JOBS=n for the parallelism.
set -euo pipefail
cd "$(dirname "$0")/.."
B="${1:-build-asan}"
JOBS="${JOBS:-$(nproc)}"
FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -DATROUS_SANITIZE=1"
cmake -S . -B "$B" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DATROUS_ENABLE_CUDA=OFF -DATROUS_BUILD_BENCH=OFF \
  -DATROUS_INSTALL=OFF -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_C_FLAGS="$FLAGS" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" > "$B.configure.log" 2>&1 || { cat "$B.configure.log"; exit 1; }
cmake --build "$B" -j "$JOBS"
# Leaks are not findings here (Embree and TBB keep thread-local pools to exit); everything else is.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
(cd "$B" && ctest --output-on-failure -j "$JOBS" --timeout 1800)
python3 tests/fuzz/fuzz.py --cli "$B/atrous" --ci --python-cases 0 --jobs "$JOBS" --timeout 300
echo "sanitize: ctest and the fuzz CI subset passed under ASan + UBSan ($B)"
