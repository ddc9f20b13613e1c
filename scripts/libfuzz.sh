#!/usr/bin/env bash
# The libFuzzer targets of atrous's input readers (tests/fuzz/libfuzzer/, docs/reliability.md):
# builds build-fuzz/ (clang, ASan + UBSan; incremental), then runs each target for N seconds on its
# committed seed corpus (tests/fuzz/libfuzzer/corpus/<target>/) plus a scratch corpus that grows
# run after run (out/libfuzz/<target>/corpus/), up to J targets at a time. Prints one line per
# target (seed, seconds, runs, coverage, corpus, peak memory, result) and exits 1 on any finding;
# the input that found it stays in out/libfuzz/<target>/ (crash-*, leak-*, timeout-*, oom-*) and
# the run's output in out/libfuzz/<target>/log.
#
#   scripts/libfuzz.sh [--seconds N] [--targets a,b] [--jobs J] [--seed S] [--strict] [--no-build]
#
# --seconds N   per target (default 60; `make fuzz` gives FUZZ_SECONDS, 600; .ci/run 20)
# --seed S      libFuzzer's -seed for every target (default: a fresh one per target, printed)
# --strict      ATROUS_FUZZ_STRICT=1: the known problems the targets skip are findings too
# --no-build    use build-fuzz/ as it is
# --report      print the table of the last run (out/libfuzz/) again, running nothing
# Reproduce a finding: build-fuzz/fuzz_<target> out/libfuzz/<target>/crash-<sha1>
set -euo pipefail
cd "$(dirname "$0")/.."

ALL=(exr_single exr_layered pfm png scene_json obj_mtl weights pass_resolver)
SECS=60
TARGETS=""
JOBS=$(nproc)
SEED=""
STRICT=0
BUILD=1
REPORT_ONLY=0
BUILD_DIR=${FUZZ_BUILD_DIR:-build-fuzz}
OUT=${FUZZ_OUT:-out/libfuzz}
usage() { sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) SECS="$2"; shift 2 ;;
    --targets) TARGETS="$2"; shift 2 ;;
    --jobs) JOBS="$2"; shift 2 ;;
    --seed) SEED="$2"; shift 2 ;;
    --strict) STRICT=1; shift ;;
    --no-build) BUILD=0; shift ;;
    --report) REPORT_ONLY=1; BUILD=0; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "libfuzz: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
[[ "$SECS" =~ ^[0-9]+$ && "$SECS" -gt 0 ]] || { echo "libfuzz: --seconds wants a positive number" >&2; exit 2; }
[[ "$JOBS" =~ ^[0-9]+$ && "$JOBS" -gt 0 ]] || { echo "libfuzz: --jobs wants a positive number" >&2; exit 2; }
[ -z "$SEED" ] || [[ "$SEED" =~ ^[0-9]+$ && "$SEED" -gt 0 ]] || { echo "libfuzz: --seed wants a positive number" >&2; exit 2; }
if [ -z "$TARGETS" ]; then
  LIST=("${ALL[@]}")
else
  IFS=, read -r -a LIST <<< "$TARGETS"
  for t in "${LIST[@]}"; do
    [[ " ${ALL[*]} " == *" $t "* ]] || { echo "libfuzz: unknown target '$t' (targets: ${ALL[*]})" >&2; exit 2; }
  done
fi

# Per target: the longest input (the readers' memory grows with the file: see the targets' notes)
# and the dictionary.
max_len() { case "$1" in exr_single|exr_layered) echo 16384 ;; pfm|pass_resolver) echo 4096 ;; *) echo 8192 ;; esac; }
dict() {
  case "$1" in
    exr_single|exr_layered) echo exr ;; png) echo png ;; scene_json) echo json ;; obj_mtl) echo obj ;;
    pass_resolver) echo pass ;; *) echo "" ;;
  esac
}

if [ "$BUILD" = 1 ]; then
  command -v clang++ > /dev/null || { echo "libfuzz: clang++ not found (scripts/setup.sh installs clang)" >&2; exit 2; }
  start=$(date +%s)
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    mkdir -p "$BUILD_DIR"
    CC=clang CXX=clang++ cmake -S tests/fuzz/libfuzzer -B "$BUILD_DIR" > "$BUILD_DIR/configure.log" 2>&1 \
      || { cat "$BUILD_DIR/configure.log"; exit 2; }
  fi
  cmake --build "$BUILD_DIR" -j "$JOBS" --target $(printf 'fuzz_%s ' "${LIST[@]}") > "$BUILD_DIR/build.log" 2>&1 \
    || { tail -50 "$BUILD_DIR/build.log"; echo "libfuzz: build failed (log: $BUILD_DIR/build.log)" >&2; exit 2; }
  echo "libfuzz: built $BUILD_DIR in $(( $(date +%s) - start )) s"
fi

run_one() {
  local t=$1 dir="$OUT/$1" seed tmp rc
  mkdir -p "$dir/corpus"
  seed=${SEED:-$(( (RANDOM << 15 | RANDOM) + 1 ))}
  tmp=$(mktemp -d /dev/shm/atrous-libfuzz-"$t".XXXXXX 2>/dev/null || mktemp -d)
  local args=("$dir/corpus" "tests/fuzz/libfuzzer/corpus/$t" -seed="$seed" -max_total_time="$SECS"
              -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=30 -max_len="$(max_len "$t")"
              -artifact_prefix="$dir/" -print_final_stats=1)
  local d; d=$(dict "$t")
  [ -z "$d" ] || args+=(-dict="tests/fuzz/libfuzzer/dict/$d.dict")
  set +e
  ATROUS_FUZZ_TMP="$tmp" ATROUS_FUZZ_STRICT="$STRICT" \
  ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}" \
  UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}" \
    "$BUILD_DIR/fuzz_$t" "${args[@]}" > "$dir/log" 2>&1
  rc=$?
  set -e
  rm -rf "$tmp"
  echo "$seed $rc $SECS" > "$dir/result"
}

# Lines of the summary table from a target's log and result.
report() {
  local t=$1 dir="$OUT/$1" seed rc secs execs cov ft corp rss res known artifact
  read -r seed rc secs < "$dir/result"
  execs=$(grep -a '^stat::number_of_executed_units:' "$dir/log" | tail -1 | tr -cd '0-9' || true)
  rss=$(grep -a '^stat::peak_rss_mb:' "$dir/log" | tail -1 | tr -cd '0-9' || true)
  local last; last=$(grep -aE '^#[0-9]+.*cov: ' "$dir/log" | tail -1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<< "$last" || true)
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$last")
  corp=$(sed -n 's/.* corp: \([0-9]*\/[0-9]*[a-zA-Z]*\).*/\1/p' <<< "$last")
  known=$(grep -a '^==atrous-fuzz== KNOWN ' "$dir/log" | cut -d' ' -f3 | tr -cd '[:alnum:]-\n' | sort -u | paste -sd, - || true)
  artifact=$(grep -a 'Test unit written to ' "$dir/log" | tail -1 | sed 's/.*Test unit written to //' || true)
  if [ "$rc" = 0 ] && [ -z "$artifact" ]; then
    res="ok"
  else
    res="FINDING rc=$rc ${artifact:-(no input written: see $dir/log)}"
    FAILED=1
  fi
  [ -z "$known" ] || res="$res; known skipped: $known"
  printf '%-14s %10s %5s %9s %6s %7s %12s %6s  %s\n' "$t" "$seed" "${secs:-$SECS}" "${execs:-?}" "${cov:-?}" "${ft:-?}" \
    "${corp:-?}" "${rss:-?}" "$res"
}

if [ "$REPORT_ONLY" = 0 ]; then
  echo "libfuzz: ${#LIST[@]} target(s), ${SECS} s each, ${JOBS} at a time, $(date -u '+%Y-%m-%d %H:%M UTC'), $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
  for t in "${LIST[@]}"; do
    rm -f "$OUT/$t/result"
    run_one "$t" &
    while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n || true; done
  done
  wait
else
  for t in "${LIST[@]}"; do
    [ -f "$OUT/$t/result" ] || { echo "libfuzz: no result for $t in $OUT" >&2; exit 2; }
  done
fi
FAILED=0
printf '%-14s %10s %5s %9s %6s %7s %12s %6s  %s\n' target seed secs runs cov ft corpus rss_mb result
for t in "${LIST[@]}"; do report "$t"; done
if [ "$FAILED" = 1 ]; then
  echo "libfuzz: FINDINGS (the inputs above; reproduce with $BUILD_DIR/fuzz_<target> <input>)" >&2
  exit 1
fi
