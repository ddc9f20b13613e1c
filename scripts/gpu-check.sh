#!/usr/bin/env bash
# The one script a session lent a GPU machine runs there (docs/benchmarks.md, "GPU"), on the pack
# that `make gpu-pack` built here (build-gpu/pack/, carried to the machine):
#   setup      unpack the binaries and the Debian libraries (dpkg -x into build-gpu/run/prefix,
#              LD_LIBRARY_PATH), re-create the /tmp/atrous-gpu/{src,build} paths compiled into the tests
#   info       nvidia-smi;  bandwidth  measured D2D copy bandwidth (gpu_bandwidth) against the peak
#   tests      every CUDA test binary (tests/cuda/*_test.cu, and tests/cuda/host_gpu_tests.txt's host
#              binaries with GPU cases; GoogleTest JSON per binary)
#   bench      atrous bench --device cuda --json (render, EAW, SURE, SVGF) at 512x512, 1280x720,
#              1920x1080, 3840x2160, one call per size; bench_gpu_render at 1920x1080
#   sanitizer  compute-sanitizer memcheck on a CUDA render (built-in and OBJ scenes), CUDA EAW, SURE,
#              learned and SVGF denoises; racecheck on the SURE, learned and SVGF denoises
#   variants   the pack's other builds of atrous (variants.tar.xz), benched against it in 3 turns
#   profile    Nsight Compute (ncu) over each kernel of a 1080p EAW and SURE denoise and of two
#              1080p SVGF frames (profile/*.csv)
#   oidn       oidnBenchmark on OIDN's CUDA device (RT filter, hdr + albedo + normal, quality high)
#              at the same four sizes (a CNN: its time does not depend on the pixels)
# Each command runs under `timeout`, within a total budget (default 420 s), and the script goes on
# past a failed step. Everything lands in $OUT (or --out): summary.json (each step's status, rc,
# seconds, log), bandwidth.json, tests/*.json, bench/*.json, oidn/*.json, logs/*.log, manifest.json.
# Exit 0 when every step passed.
#
# --dry-run (here, without a GPU): checks that the pack holds everything (binaries with sm_90 code,
# every library they load, debs, OIDN, size <= 64 MiB, the test list matching tests/cuda), runs the
# same steps on the CPU where they can (the CUDA test binaries must exit 0 with their GPU tests
# skipped; the bench, oidnBenchmark and the sanitizer's atrous commands with --device cpu; the
# CUDA-only commands must fail cleanly), and prints the `run` invocation for a GPU session.
#
# usage: scripts/gpu-check.sh [--dry-run] [--pack DIR] [--out DIR] [--budget SECONDS]
#                             [--only info,bandwidth,tests,bench,oidn,sanitizer,profile,variants]   (setup always runs)
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
DRY=0
PACK=build-gpu/pack
OUTDIR=${OUT:-}
BUDGET=420
ONLY=""
while [ $# -gt 0 ]; do
  case $1 in
    --dry-run) DRY=1 ;;
    --pack) PACK=$2; shift ;;
    --out) OUTDIR=$2; shift ;;
    --budget) BUDGET=$2; shift ;;
    --only) ONLY=$2; shift ;;
    -h|--help) awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$0"; exit 0 ;;
    *) echo "gpu-check: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
[ -n "$OUTDIR" ] || OUTDIR=$ROOT/out/gpu-check$([ "$DRY" = 1 ] && echo -dry)
case $PACK in /*) ;; *) PACK=$ROOT/$PACK ;; esac
mkdir -p "$OUTDIR" && OUTDIR=$(cd "$OUTDIR" && pwd)
LINK=/tmp/atrous-gpu
# Unpacked under the repository's ignored build-gpu/ (not /tmp, which may be mounted noexec);
# /tmp/atrous-gpu holds only the symlinks whose paths are compiled into the tests.
RUN=$ROOT/build-gpu/run
WORK=$RUN/bin           # the binaries; $LINK/build points here (the tests' ATROUS_CLI path)
PREFIX=$RUN/prefix      # the unpacked Debian libraries
OIDN=$RUN/oidn          # oidnBenchmark and its libraries
SCRATCH=$RUN/scratch    # renders for the sanitizer steps
LOGS=$OUTDIR/logs
STEPS=$OUTDIR/steps.tsv
rm -rf "$LOGS" "$OUTDIR/tests" "$OUTDIR/bench" "$OUTDIR/oidn" "$STEPS" "$OUTDIR/summary.json"
mkdir -p "$LOGS" "$OUTDIR/tests" "$OUTDIR/bench" "$OUTDIR/oidn"
: > "$STEPS"
START=$(date +%s)
DEADLINE=$((START + BUDGET))
SIZES="512x512 1280x720 1920x1080 3840x2160"
TOOL="python3 $ROOT/scripts/gpu_pack_tool.py"
if [ "$DRY" = 1 ]; then DEV=cpu; else DEV=cuda; fi
export ROOT DRY PACK OUTDIR LINK WORK PREFIX OIDN SCRATCH LOGS DEV TOOL
say() { echo "gpu-check: $*"; }
wants() { [ -z "$ONLY" ] || case ",$ONLY," in *",$1,"*) true ;; *) false ;; esac; }

record() {  # name status rc seconds log note
  printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$4" "${5#$OUTDIR/}" "$6" >> "$STEPS"
  printf 'gpu-check: %-28s %-8s rc=%-4s %6ss  %s\n' "$1" "$2" "$3" "$4" "$6"
}
# step NAME LIMIT_S FUNCTION [ARGS...]: run an exported function under timeout (never past the
# deadline), output in logs/NAME.log; the function's own stdout redirections write the results.
step() {
  local name=$1 limit=$2; shift 2
  local left=$((DEADLINE - $(date +%s)))
  if [ "$left" -lt 5 ]; then record "$name" out-of-time "" 0 "" "not run: budget of ${BUDGET}s spent"; return 1; fi
  [ "$limit" -gt "$left" ] && limit=$left
  local t0 t1 rc status note=""
  t0=$(date +%s.%N)
  timeout -k 5 "$limit" bash -c '"$@"' _ "$@" > "$LOGS/$name.log" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  case $rc in
    0) status=ok ;;
    124|137) status=timeout; note="killed after ${limit}s" ;;
    *) status=failed; note=$(grep -v '^\s*$' "$LOGS/$name.log" | tail -1 | cut -c1-160 | tr '\t' ' ') ;;
  esac
  [ -f "$LOGS/$name.note" ] && note="$(cat "$LOGS/$name.note")${note:+; $note}" && rm -f "$LOGS/$name.note"
  record "$name" "$status" "$rc" "$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.1f", b-a}')" "$LOGS/$name.log" "$note"
  return $rc
}

# ---------------------------------------------------------------- setup (in this shell: it sets the environment)
oidn_archive() {  # the OIDN archive: in the pack, or the second pack gpu-pack.sh makes beside it
  local f
  for f in "$PACK/oidn.tar.xz" "$PACK/oidn.tar.gz" "$ROOT/build-gpu/pack-oidn/oidn.tar.xz"; do
    [ -f "$f" ] && { echo "$f"; return 0; }
  done
  return 1
}
unpack_oidn() {
  local a
  a=$(oidn_archive) || { echo "no OIDN archive (build-gpu/pack-oidn/oidn.tar.xz): the OIDN step is skipped"; return 0; }
  rm -rf "$OIDN" && mkdir -p "$RUN" && tar -xaf "$a" -C "$RUN" && echo "OIDN from $a"
}
setup() {
  local bad=0
  [ -d "$PACK" ] || { echo "no pack at $PACK: run 'make gpu-pack' on the build machine and carry build-gpu/pack"; return 1; }
  if [ ! -f "$PACK/bin.tar.xz" ] && oidn_archive > /dev/null; then
    # The OIDN pack alone (a second call): keep the binaries a first call on this machine unpacked.
    echo "OIDN pack only: atrous's binaries $([ -x "$WORK/atrous" ] && echo "kept from an earlier call" || echo "absent (a fresh machine)")"
    [ -d "$PREFIX" ] && export LD_LIBRARY_PATH="$PREFIX/usr/lib/x86_64-linux-gnu:$PREFIX/lib/x86_64-linux-gnu:$PREFIX/fallback/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    [ -x "$WORK/atrous" ] && mkdir -p "$LINK" && rm -rf "$LINK/build" "$LINK/src" && ln -s "$WORK" "$LINK/build" && ln -s "$WORK/src" "$LINK/src"
    unpack_oidn
    return
  fi
  for f in bin.tar.xz tests.txt manifest.json; do [ -f "$PACK/$f" ] || { echo "missing $PACK/$f"; bad=1; }; done
  [ "$bad" = 0 ] || return 1
  rm -rf "$RUN" && mkdir -p "$WORK" "$PREFIX" "$LINK" || return 1
  if ! tar -xJf "$PACK/bin.tar.xz" -C "$WORK" 2> /dev/null; then
    echo "tar -xJ failed (no xz?): unpacking with Python's tarfile"
    $TOOL untar "$PACK/bin.tar.xz" "$WORK" || return 1
  fi
  rm -rf "$LINK/build" "$LINK/src"  # symlinks (rm does not follow them), or left-overs
  ln -s "$WORK" "$LINK/build" && ln -s "$WORK/src" "$LINK/src" || return 1
  for d in "$PACK"/debs/*.deb; do
    if command -v dpkg > /dev/null; then dpkg -x "$d" "$PREFIX" || return 1
    else $TOOL deb-extract "$d" "$PREFIX" || return 1; fi
  done
  LIBDIRS="$PREFIX/usr/lib/x86_64-linux-gnu:$PREFIX/lib/x86_64-linux-gnu"
  export LD_LIBRARY_PATH="$LIBDIRS${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  if grep -q "version .* not found" <<< "$(ldd "$WORK/atrous" 2>&1)"; then  # (no pipe: pipefail and grep -q)
    echo "the system's libstdc++/libgcc are too old: using the carried ones"
    for d in "$PACK"/debs/fallback/*.deb; do
      if command -v dpkg > /dev/null; then dpkg -x "$d" "$PREFIX/fallback"; else $TOOL deb-extract "$d" "$PREFIX/fallback"; fi
    done
    export LD_LIBRARY_PATH="$LD_LIBRARY_PATH:$PREFIX/fallback/usr/lib/x86_64-linux-gnu:$PREFIX/fallback/lib/x86_64-linux-gnu"
  fi
  # Every library each binary loads must come from the pack or be one a bare image has.
  local base='linux-vdso|ld-linux-x86-64|libc\.so|libm\.so|libstdc\+\+|libgcc_s|libz\.so|libpthread|libdl\.so|librt\.so'
  for b in "$WORK/atrous" "$WORK/gpu_bandwidth" "$WORK/bench/bench_gpu_render" "$WORK"/tests/*; do
    local l
    l=$(ldd "$b" 2>&1)
    if echo "$l" | grep -q "not found"; then echo "$b: $(echo "$l" | grep 'not found' | tr '\n' ' ')"; bad=1; fi
    if echo "$l" | awk '$2 == "=>" {print $1, $3}' | grep -vE "^($base)" | grep -v " $PREFIX/" | grep -q .; then
      echo "$b loads libraries from outside the pack that a bare image may lack:"
      echo "$l" | awk '$2 == "=>" {print $1, $3}' | grep -vE "^($base)" | grep -v " $PREFIX/"
      bad=1
    fi
  done
  unpack_oidn || bad=1
  cp "$PACK/manifest.json" "$OUTDIR/manifest.json"
  echo "LD_LIBRARY_PATH=$LD_LIBRARY_PATH"
  ldd "$WORK/atrous"
  return $bad
}

# ---------------------------------------------------------------- dry-run checks of the pack itself
check_pack() {
  local bad=0
  [ -f "$PACK/manifest.json" ] || { echo "no $PACK/manifest.json: run make gpu-pack"; return 1; }
  local total limit
  total=$(du -sb "$PACK" | cut -f1)
  limit=$((64 * 1024 * 1024))
  echo "pack size: $total bytes ($((total / 1024)) KiB; carry limit $limit)"
  [ "$total" -le "$limit" ] || { echo "pack over 64 MiB"; bad=1; }
  # the CUDA test binaries of this tree, against the pack's list
  local want have
  want=$( (for f in "$ROOT"/tests/cuda/*_test.cu; do basename "$f" .cu; done; grep -v '^#' "$ROOT/tests/cuda/host_gpu_tests.txt") |
         sort | tr '\n' ' ')
  have=$(sort "$PACK/tests.txt" | tr '\n' ' ')
  [ "$want" = "$have" ] || { echo "tests/cuda has '$want' but the pack '$have': run make gpu-pack"; bad=1; }
  for t in $(cat "$PACK/tests.txt"); do [ -x "$WORK/tests/$t" ] || { echo "missing binary tests/$t"; bad=1; }; done
  for b in atrous gpu_bandwidth bench/bench_gpu_render; do [ -x "$WORK/$b" ] || { echo "missing binary $b"; bad=1; }; done
  # SASS for sm_90 in every binary (cuobjdump when the toolkit has it, else the fat binary's headers)
  local bins=("$WORK/atrous" "$WORK/gpu_bandwidth" "$WORK/bench/bench_gpu_render" "$WORK"/tests/*)
  for b in "${bins[@]}"; do
    if command -v cuobjdump > /dev/null; then
      grep -q sm_90 <<< "$(cuobjdump --list-elf "$b")" || { echo "$b: no sm_90 ELF (cuobjdump)"; bad=1; }
    fi
  done
  $TOOL fatbin-arch "${bins[@]}" > "$OUTDIR/fatbin.json" || bad=1
  python3 - "$OUTDIR/fatbin.json" <<'EOF' || bad=1
import json, sys
j = json.load(open(sys.argv[1]))
bad = [f for f, v in j.items() if "sm_90" not in v["sass"]]
for f, v in j.items(): print(f"{f.rsplit('/run/', 1)[-1]}: SASS {v['sass']} PTX {v['ptx']}")
sys.exit(f"no sm_90 SASS in {bad}" if bad else 0)
EOF
  ls "$PACK"/debs/*.deb > /dev/null 2>&1 || { echo "no debs in $PACK/debs"; bad=1; }
  oidn_archive > /dev/null || echo "no OIDN archive (build-gpu/pack-oidn): the OIDN step will be skipped"
  local pc hc
  pc=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["commit"])' "$PACK/manifest.json")
  hc=$(git -C "$ROOT" rev-parse HEAD 2> /dev/null || echo unknown)
  [ "$pc" = "$hc" ] || echo "note: the pack is of commit $pc, HEAD is $hc (make gpu-pack rebuilds it)"
  for s in gpu-check.sh gpu-pack.sh; do bash -n "$ROOT/scripts/$s" || bad=1; done
  # The GPU machine gets a copy of the tracked and the untracked-but-not-ignored files: say if that is big.
  local extra
  extra=$(cd "$ROOT" && git ls-files -z --others --exclude-standard 2> /dev/null | du -cb --files0-from=- 2> /dev/null | tail -1 | cut -f1)
  [ "${extra:-0}" -gt $((50 * 1024 * 1024)) ] && echo "warning: $((extra / 1048576)) MiB of untracked, not ignored files would be copied to the GPU machine with the working tree: $(cd "$ROOT" && git ls-files --others --exclude-standard --directory | head -5 | tr '\n' ' ')"
  return $bad
}

# ---------------------------------------------------------------- the steps (exported: they run under timeout)
info() {
  if command -v nvidia-smi > /dev/null; then
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.max.mem,power.limit --format=csv
    nvidia-smi -q > "$OUTDIR/nvidia-smi.txt"
  else
    [ "$DRY" = 1 ] || { echo "nvidia-smi not found"; return 1; }
    echo "no nvidia-smi here (dry run)"
  fi
  command -v nvcc > /dev/null && nvcc --version | tail -2
  command -v compute-sanitizer > /dev/null && compute-sanitizer --version | tail -1
  nproc; uname -a; cat /etc/os-release 2> /dev/null | head -2
  return 0
}
bandwidth() {
  "$WORK/gpu_bandwidth" --mb 1024 --runs 20 > "$OUTDIR/bandwidth.json"
  local rc=$?
  cat "$OUTDIR/bandwidth.json"
  if [ "$DRY" = 1 ]; then  # no GPU: exit 3 with a JSON error
    [ $rc = 3 ] && grep -q '"error"' "$OUTDIR/bandwidth.json" && rm -f "$OUTDIR/bandwidth.json" && return 0
    return 1
  fi
  return $rc
}
gtest() {  # binary name
  cd "$WORK/tests" && "$WORK/tests/$1" --gtest_output="json:$OUTDIR/tests/$1.json"
  local rc=$?
  local c
  c=$($TOOL gtest-count "$OUTDIR/tests/$1.json")
  echo "$c"
  local skipped
  skipped=$(echo "$c" | python3 -c 'import json,sys; print(json.load(sys.stdin)["skipped"])')
  if [ "$DRY" = 1 ]; then
    echo "$c skipped without a GPU" > "$LOGS/test-$1.note"
  elif [ "$skipped" != 0 ]; then
    echo "$skipped test(s) skipped on a GPU machine" > "$LOGS/test-$1.note"
    return 1
  fi
  return $rc
}
bench_size() {  # WxH
  if [ "$DRY" = 1 ]; then
    # flags and JSON through the CPU path, then the CUDA path must refuse cleanly (exit 2) without a GPU
    "$WORK/atrous" bench --device cpu --json --sizes 64x64 --what render,eaw,sure,svgf,learned --runs 1 --warmup 0 \
      > "$OUTDIR/bench/atrous_bench_cpu_dry.json" || return 1
    "$WORK/atrous" bench --device cpu --json --sizes 64x64 --what refine --runs 1 --warmup 0 \
      > "$OUTDIR/bench/atrous_bench_cpu_refine_dry.json" || return 1
    python3 -m json.tool "$OUTDIR/bench/atrous_bench_cpu_dry.json" > /dev/null || return 1
    "$WORK/atrous" bench --device cuda --json --sizes "$1" --what render,eaw,sure,svgf,learned > /dev/null 2> "$LOGS/bench-cuda-dry.err"
    local rc=$?
    cat "$LOGS/bench-cuda-dry.err"
    [ $rc = 2 ] || { echo "atrous bench --device cuda without a GPU: exit $rc, expected 2"; return 1; }
    return 0
  fi
  "$WORK/atrous" bench --device cuda --json --sizes "$1" --what render,eaw,sure,svgf,learned > "$OUTDIR/bench/atrous_bench_cuda_$1.json" \
    && python3 -m json.tool "$OUTDIR/bench/atrous_bench_cuda_$1.json" > /dev/null || return 1
  # the refine method (SURE and the refine stage; issue 47, docs/refine.md)
  "$WORK/atrous" bench --device cuda --json --sizes "$1" --what refine > "$OUTDIR/bench/atrous_bench_cuda_refine_$1.json" \
    && python3 -m json.tool "$OUTDIR/bench/atrous_bench_cuda_refine_$1.json" > /dev/null
}
bench_render() {
  local args=(--scene cornell --width 1920 --height 1080 --spp 1 --runs 5)
  [ "$DRY" = 1 ] && args=(--scene cornell --width 64 --height 64 --spp 1 --runs 1)
  "$WORK/bench/bench_gpu_render" "${args[@]}" > "$OUTDIR/bench/bench_gpu_render.json" \
    && python3 -m json.tool "$OUTDIR/bench/bench_gpu_render.json"
}
oidn() {  # WxH
  local w=${1%x*} h=${1#*x} dev=cuda n=20
  [ "$DRY" = 1 ] && { dev=cpu; w=64; h=64; n=1; }
  LD_LIBRARY_PATH="$OIDN/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$OIDN/bin/oidnBenchmark" -d $dev -r "RT.hdr_alb_nrm.${w}x${h}" -s "$w" "$h" -n $n -q high -v 1 \
    > "$LOGS/oidn-$1.out" 2>&1
  local rc=$?
  cat "$LOGS/oidn-$1.out"
  [ $rc = 0 ] || return $rc
  $TOOL oidn-json "$LOGS/oidn-$1.out" > "$OUTDIR/oidn/oidn_${dev}_$1.json"
  grep -q msec_per_image "$OUTDIR/oidn/oidn_${dev}_$1.json" || { echo "no timing line in oidnBenchmark's output"; return 1; }
  if [ "$DRY" = 1 ]; then  # the CUDA device needs the driver: without one, a clean error
    LD_LIBRARY_PATH="$OIDN/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$OIDN/bin/oidnBenchmark" -d cuda -r RT.hdr_alb_nrm.64x64 -s 64 64 -n 1 2>&1 | tail -1
  fi
  return 0
}
sanitize_prep() {  # denoiser inputs: a CPU render and a short sequence (not sanitised themselves)
  rm -rf "$SCRATCH" && mkdir -p "$SCRATCH"
  "$WORK/atrous" render --scene cornell --width 128 --height 128 --spp 4 --device cpu --quiet --out "$SCRATCH/r" \
    && "$WORK/atrous" render --scene cornell-moving --width 96 --height 96 --frames 3 --spp 1 --device cpu --quiet --out "$SCRATCH/seq"
}
sanitize() {  # tool what
  local tool=$1 what=$2 san=()
  if [ "$DRY" = 0 ]; then
    local cs
    cs=$(command -v compute-sanitizer || ls /usr/local/cuda/bin/compute-sanitizer /usr/local/cuda*/bin/compute-sanitizer 2> /dev/null | head -1)
    [ -n "$cs" ] || { echo "compute-sanitizer not found"; return 1; }
    san=("$cs" --tool "$tool" --error-exitcode 86 --print-limit 20)
  fi
  local A="$WORK/atrous"
  case $what in
    render) "${san[@]}" "$A" render --scene cornell --width 128 --height 128 --spp 4 --device "$DEV" --quiet --out "$SCRATCH/rc" ;;
    render-obj) "${san[@]}" "$A" render --scene "$WORK/src/scenes/example.json" --width 96 --height 96 --spp 2 --device "$DEV" --quiet --out "$SCRATCH/ro" ;;
    eaw|sure|learned) "${san[@]}" "$A" denoise --in "$SCRATCH/r" --device "$DEV" --method "$what" --out "$SCRATCH/$tool-$what.exr" ;;
    svgf) "${san[@]}" "$A" denoise --sequence "$SCRATCH/seq" --method svgf --device "$DEV" --out "$SCRATCH/$tool-svgf" ;;
  esac
}
variants() {  # the pack's other builds of atrous (gpu-pack's GPU_PACK_VARIANTS), timed against it in turns
  local d=$RUN/variants
  rm -rf "$d" && mkdir -p "$d" && tar -xJf "$PACK/variants.tar.xz" -C "$d" || return 1
  local round v s
  for round in 1 2 3; do
    for v in main $(ls "$d"); do
      local bin=$d/$v/atrous
      [ "$v" = main ] && bin=$WORK/atrous
      for s in 1920x1080 512x512; do
        "$bin" bench --device "$DEV" --json --sizes "$s" --what eaw,sure,svgf,learned \
          > "$OUTDIR/bench/variant_${v}_${s}_r$round.json" || return 1
      done
    done
  done
  python3 "$ROOT/scripts/gpu_pack_tool.py" variants "$OUTDIR/bench"
}
profile() {  # Nsight Compute on each kernel of one 1080p EAW and SURE denoise: the data for tuning them
  mkdir -p "$OUTDIR/profile" "$SCRATCH"
  local ncu
  ncu=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu /usr/local/cuda/bin/ncu 2> /dev/null | head -1)
  if [ -z "$ncu" ]; then
    [ "$DRY" = 1 ] && { echo "no ncu here (dry run)"; return 0; }
    echo "ncu not found"; return 1
  fi
  "$WORK/atrous" render --scene cornell --width 1920 --height 1080 --spp 1 --device "$DEV" --quiet --out "$SCRATCH/p1080" || return 1
  local m
  for m in eaw sure; do
    "$ncu" --clock-control none --section SpeedOfLight --section MemoryWorkloadAnalysis --section LaunchStats \
      --section Occupancy --csv --page details "$WORK/atrous" denoise --in "$SCRATCH/p1080" --device "$DEV" \
      --method $m --out "$SCRATCH/p-$m.exr" > "$OUTDIR/profile/ncu_${m}_1080p.csv" || return 1
  done
  # SVGF with its safety net over a 2-frame 1080p sequence (the second frame has a history)
  "$WORK/atrous" render --scene cornell-moving --frames 2 --width 1920 --height 1080 --spp 1 --device cpu --quiet \
    --out "$SCRATCH/s1080" || return 1
  "$ncu" --clock-control none --section SpeedOfLight --section LaunchStats --csv --page details "$WORK/atrous" denoise \
    --sequence "$SCRATCH/s1080" --device "$DEV" --method svgf --out "$SCRATCH/s-svgf" > "$OUTDIR/profile/ncu_svgf_1080p.csv" || return 1
}
export -f info bandwidth gtest bench_size bench_render oidn sanitize_prep sanitize profile variants

# ---------------------------------------------------------------- run
say "$([ "$DRY" = 1 ] && echo "dry run (no GPU)" || echo "GPU run"); pack $PACK; out $OUTDIR; budget ${BUDGET}s"
# inshell NAME FUNCTION [NOTE_PATTERN]: a step run in this shell (setup sets the environment), output
# in logs/NAME.log and shown when it fails; the note is the log's line matching NOTE_PATTERN when
# it succeeds, else its first line.
inshell() {
  local name=$1 fn=$2 pattern=${3:-} t0 rc note
  t0=$(date +%s.%N)
  "$fn" > "$LOGS/$name.log" 2>&1
  rc=$?
  if [ $rc = 0 ]; then note=$([ -n "$pattern" ] && grep "$pattern" "$LOGS/$name.log")
  else note=$(grep -v '^\s*$' "$LOGS/$name.log" | head -1 | cut -c1-160); fi
  record "$name" "$([ $rc = 0 ] && echo ok || echo failed)" $rc \
    "$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN{printf "%.1f", b-a}')" "$LOGS/$name.log" "$note"
  [ $rc = 0 ] || cat "$LOGS/$name.log"
}
inshell setup setup
[ "$DRY" = 1 ] && inshell pack check_pack '^pack size'
if [ -x "$WORK/atrous" ]; then
  wants info && step info 30 info
  wants bandwidth && step bandwidth 30 bandwidth
  if wants tests; then
    for t in $(cat "$PACK/tests.txt"); do step "test-$t" 90 gtest "$t"; done
  fi
  if wants bench; then
    if [ "$DRY" = 1 ]; then step bench-dry 60 bench_size 512x512
    else for s in $SIZES; do step "bench-$s" 120 bench_size "$s"; done; fi
    step bench-gpu-render 60 bench_render
  fi
  if wants sanitizer; then
    if step sanitizer-inputs 60 sanitize_prep; then
      for w in render render-obj eaw sure learned svgf; do step "memcheck-$w" 90 sanitize memcheck "$w"; done
      for w in sure learned svgf; do step "racecheck-$w" 90 sanitize racecheck "$w"; done
    fi
  fi
  wants profile && step profile 120 profile
  wants variants && [ -f "$PACK/variants.tar.xz" ] && step variants 150 variants
fi
if wants oidn; then
  if [ ! -x "$OIDN/bin/oidnBenchmark" ]; then record oidn skipped "" 0 "" "no OIDN archive carried"
  elif [ "$DRY" = 1 ]; then step oidn-dry 60 oidn 64x64
  else for s in $SIZES; do step "oidn-$s" 60 oidn "$s"; done; fi
fi
$TOOL summary "$STEPS" "$OUTDIR/summary.json" > "$LOGS/summary.out" 2>&1
ok=$(python3 -c 'import json,sys; print(int(json.load(open(sys.argv[1]))["ok"]))' "$OUTDIR/summary.json" 2> /dev/null || echo 0)
say "summary: $OUTDIR/summary.json ($(cat "$LOGS/summary.out")); $(( $(date +%s) - START ))s"
if [ "$DRY" = 0 ]; then
  # At most 8 files come back from the GPU machine: everything goes into one archive, summary beside it.
  cat "$OUTDIR/summary.json"
  tar -C "$OUTDIR" -czf /tmp/gpu-check.tar.gz --exclude=gpu-check.tar.gz . && mv /tmp/gpu-check.tar.gz "$OUTDIR/" \
    && find "$OUTDIR" -mindepth 1 -maxdepth 1 ! -name gpu-check.tar.gz ! -name summary.json -exec rm -rf {} +
fi
if [ "$DRY" = 1 ]; then
  cat <<EOF

A session lent a GPU machine runs, in one call (the pack is carried; \$OUT comes back):

  run(command="bash scripts/gpu-check.sh --budget 400", carry=["build-gpu/pack"], timeout_s=480)
  run(command="bash scripts/gpu-check.sh --pack build-gpu/pack-oidn --only bench,oidn --budget 200",
      carry=["build-gpu/pack-oidn"], timeout_s=260)      # at once, while the machine is warm

(\$OUT comes back as gpu-check.tar.gz with summary.json beside it; a call sends the tracked tree
plus what it carries, at most 64 MiB, so OIDN travels in the second call)

then reads \$OUT/summary.json (step status), bandwidth.json, bench/*.json, oidn/*.json, tests/*.json,
and records the figures in docs/benchmarks.md ("GPU"). To rerun a part: --only tests,bench,oidn,sanitizer,...
EOF
fi
[ "$ok" = 1 ]
