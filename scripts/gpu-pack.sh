#!/usr/bin/env bash
# make gpu-pack: build, on this machine (no GPU needed), everything scripts/gpu-check.sh runs on a
# lent GPU machine, and gather it into build-gpu/pack/ (ignored; the one folder a GPU session
# carries). The GPU machine has the CUDA driver, nvcc, CMake and Python 3.12 but none of the
# Debian libraries atrous links (Embree, TBB, OpenEXR, ...), so the pack holds:
#   bin.tar.xz      atrous, the CUDA test binaries (tests/cuda/*_test.cu, and the host test binaries
#                   with GPU cases that tests/cuda/host_gpu_tests.txt names), bench_gpu_render, the
#                   copy-bandwidth probe (scripts/gpu_bandwidth.cu), scenes/ (stripped; one solid
#                   xz archive: the binaries share most of their bytes)
#   debs/           the Debian packages of every shared library those binaries load that a bare
#                   Debian/Ubuntu + CUDA image lacks (ldd + dpkg -S + apt-get download);
#                   debs/fallback/ libstdc++6 and libgcc-s1, used only if the machine's are too old
#   tests.txt       the GPU test binaries, one a line;  manifest.json  what is in it, sizes, commit
# and build-gpu/pack-oidn/ (carried by a second call: each call sends the tracked tree, 18 MB, plus
# what it carries, and the two together pass the 64 MiB a call may send):
#   oidn.tar.xz     Intel Open Image Denoise from the pyoidn wheel, cut to what oidnBenchmark needs
#                   for its CUDA device (core + CUDA + CPU devices, TBB): the OIDN comparison
# The build is of the committed tree (a `git archive HEAD` snapshot in build-gpu/src), not of the
# working tree, so that the figures belong to a commit; GPU_PACK_SOURCE=worktree builds the working
# tree instead. Compiled-in paths (the tests' ATROUS_CLI and ATROUS_SOURCE_DIR) go through
# /tmp/atrous-gpu/{src,build}, symlinks that gpu-check.sh re-creates on the GPU machine.
# Env: JOBS (default 2), GPU_PACK_SOURCE (head | worktree), GPU_PACK_OIDN=0 to leave OIDN out,
# GPU_PACK_VARIANTS and GPU_PACK_BEFORE (other builds of atrous to time beside it; below).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
JOBS=${JOBS:-2}
SOURCE=${GPU_PACK_SOURCE:-head}
WITH_OIDN=${GPU_PACK_OIDN:-1}
G=$ROOT/build-gpu
CM=$G/cmake
PACK=$G/pack
OPACK=$G/pack-oidn
LINK=/tmp/atrous-gpu
LIMIT=$((64 * 1024 * 1024))
# Packages of a bare Debian/Ubuntu image (with the CUDA driver): not carried.
BASE_PKGS=" libc6 libgcc-s1 libstdc++6 zlib1g "
say() { echo "gpu-pack: $*"; }

command -v nvcc > /dev/null || { echo "gpu-pack: nvcc not found (the pack needs the CUDA backend)" >&2; exit 1; }
mkdir -p "$G" "$CM" "$LINK"

# ---- sources ----
if [ "$SOURCE" = worktree ]; then
  SRC=$ROOT
  COMMIT="$(git rev-parse HEAD)+worktree"
else
  COMMIT=$(git rev-parse HEAD)
  rm -rf "$G/src.new" && mkdir -p "$G/src.new"
  git archive --format=tar HEAD | tar -x -C "$G/src.new"
  python3 scripts/gpu_pack_tool.py sync "$G/src.new" "$G/src"
  rm -rf "$G/src.new"
  SRC=$G/src
fi
for l in src build; do  # symlinks from an earlier pack or dry run (rm does not follow them)
  if [ -e "$LINK/$l" ] && [ ! -L "$LINK/$l" ]; then echo "gpu-pack: $LINK/$l is not a symlink: remove it" >&2; exit 1; fi
  rm -f "$LINK/$l"
done
ln -s "$SRC" "$LINK/src"
ln -s "$CM" "$LINK/build"
say "sources: $SOURCE ($COMMIT)"

# ---- configure + build (Release, SASS for sm_90 only, no viewer: the GPU machine has no GL) ----
cmake -S "$LINK/src" -B "$LINK/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES=90 \
  -DATROUS_BUILD_VIEWER=OFF -DATROUS_INSTALL=OFF -DATROUS_BUILD_PYTHON=OFF -DATROUS_ONEDNN=OFF \
  > "$G/configure.log" 2>&1 || { cat "$G/configure.log"; exit 1; }
grep -q "CUDA backend ON" "$G/configure.log" || { echo "gpu-pack: CUDA backend is OFF (see $G/configure.log)" >&2; exit 1; }
TESTS=()
for f in "$SRC"/tests/cuda/*_test.cu; do TESTS+=("$(basename "$f" .cu)"); done
TESTS+=($(grep -v '^#' "$SRC/tests/cuda/host_gpu_tests.txt"))  # host binaries with GPU cases
say "building atrous, ${TESTS[*]}, bench_gpu_render (-j$JOBS; log in $G/build.log)"
cmake --build "$LINK/build" -j "$JOBS" --target atrous "${TESTS[@]}" bench_gpu_render > "$G/build.log" 2>&1 \
  || { tail -40 "$G/build.log"; exit 1; }
nvcc -O2 -arch=sm_90 -o "$CM/gpu_bandwidth" "$ROOT/scripts/gpu_bandwidth.cu" > "$G/bandwidth-build.log" 2>&1 \
  || { cat "$G/bandwidth-build.log"; exit 1; }

# ---- stage the binaries (the paths below /tmp/atrous-gpu/build that the tests expect) ----
rm -rf "$PACK" && mkdir -p "$PACK/debs/fallback" "$G/stage"
ST=$G/stage
rm -rf "$ST" && mkdir -p "$ST/tests" "$ST/bench" "$ST/src"
cp "$CM/atrous" "$CM/gpu_bandwidth" "$ST/"
cp "$CM/bench/bench_gpu_render" "$ST/bench/"
for t in "${TESTS[@]}"; do cp "$CM/tests/$t" "$ST/tests/"; done
cp -r "$SRC/scenes" "$ST/src/scenes"
# Data files the CUDA tests read through ATROUS_SOURCE_DIR (the learned filter's JAX parity fixture).
mkdir -p "$ST/src/tests" && cp "$SRC/tests/learned_fixture.bin" "$ST/src/tests/"
BINS=("$ST/atrous" "$ST/gpu_bandwidth" "$ST/bench/bench_gpu_render")
for t in "${TESTS[@]}"; do BINS+=("$ST/tests/$t"); done
strip --strip-unneeded "${BINS[@]}"
printf '%s\n' "${TESTS[@]}" > "$PACK/tests.txt"
python3 scripts/gpu_pack_tool.py fatbin-arch "${BINS[@]}" | sed "s#$ST/##" > "$PACK/fatbin.json"
if grep -q '"sass": \[\]' "$PACK/fatbin.json" || [ "$(grep -c '"sm_90"' "$PACK/fatbin.json")" -ne "${#BINS[@]}" ]; then
  echo "gpu-pack: a binary lacks sm_90 code:" >&2; cat "$PACK/fatbin.json" >&2; exit 1
fi
say "compressing the binaries (xz, solid)"
tar -C "$ST" -cf - . | xz -T1 -6 > "$PACK/bin.tar.xz"

# ---- variants of `atrous` to time against it on the GPU in one call (gpu-check.sh's variants step) ----
# GPU_PACK_VARIANTS="NAME=CMAKE_ARG[,CMAKE_ARG...] ..." builds atrous again with those cache
# arguments (e.g. r64=-DCMAKE_CUDA_FLAGS=-maxrregcount=64); GPU_PACK_BEFORE=COMMIT adds "before",
# that commit's atrous. Each in build-gpu/var-NAME; all in the pack's variants.tar.xz.
VARS=(${GPU_PACK_VARIANTS:-})
if [ -n "${GPU_PACK_BEFORE:-}" ]; then
  rm -rf "$G/src-before" && mkdir -p "$G/src-before"
  git archive --format=tar "$GPU_PACK_BEFORE" | tar -x -C "$G/src-before"
  VARS+=("before=")
fi
if [ ${#VARS[@]} -gt 0 ]; then
  rm -rf "$G/variants" && mkdir -p "$G/variants"
  for v in "${VARS[@]}"; do
    name=${v%%=*} args=${v#*=} vsrc=$LINK/src
    [ "$name" = before ] && vsrc=$G/src-before
    IFS=',' read -r -a extra <<< "$args"
    say "variant $name: ${extra[*]:-(commit ${GPU_PACK_BEFORE:-})}"
    cmake -S "$vsrc" -B "$G/var-$name" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES=90 \
      -DATROUS_BUILD_VIEWER=OFF -DATROUS_INSTALL=OFF -DATROUS_BUILD_PYTHON=OFF -DATROUS_ONEDNN=OFF "${extra[@]}" \
      > "$G/var-$name.log" 2>&1 && cmake --build "$G/var-$name" -j "$JOBS" --target atrous >> "$G/var-$name.log" 2>&1 \
      || { tail -30 "$G/var-$name.log"; exit 1; }
    mkdir -p "$G/variants/$name" && cp "$G/var-$name/atrous" "$G/variants/$name/" && strip --strip-unneeded "$G/variants/$name/atrous"
  done
  tar -C "$G/variants" -cf - . | xz -T1 -6 > "$PACK/variants.tar.xz"
fi

# ---- Debian packages of the shared libraries ----
declare -A PKG=()
for b in "${BINS[@]}"; do
  while read -r lib; do
    p=""
    for cand in "$lib" "$(readlink -f "$lib")" "/usr$lib" "$(readlink -f "/usr$lib" 2>/dev/null || true)"; do
      [ -n "$cand" ] || continue
      p=$(dpkg -S "$cand" 2>/dev/null | head -1 | cut -d: -f1) && [ -n "$p" ] && break
    done
    [ -n "$p" ] || { echo "gpu-pack: no Debian package owns $lib (needed by $b)" >&2; exit 1; }
    PKG[$p]=1
  done < <(ldd "$b" | awk '$2 == "=>" && $3 ~ /^\// {print $3}')
done
CARRY=()
for p in "${!PKG[@]}"; do case "$BASE_PKGS" in *" $p "*) ;; *) CARRY+=("$p") ;; esac; done
mkdir -p "$G/deb-cache"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
( cd "$G/deb-cache"
  for p in "${CARRY[@]}" libstdc++6 libgcc-s1; do
    ls "${p}"_*.deb > /dev/null 2>&1 && continue
    apt-get download "$p" > /dev/null 2>&1 || { $SUDO apt-get update -qq && apt-get download "$p" > /dev/null; } \
      || { echo "gpu-pack: apt-get download $p failed" >&2; exit 1; }
  done )
newest() { ls "$G/deb-cache/${1}"_*.deb | sort -V | tail -1; }  # the cache may hold an older version too
for p in "${CARRY[@]}"; do cp "$(newest "$p")" "$PACK/debs/"; done
for p in libstdc++6 libgcc-s1; do cp "$(newest "$p")" "$PACK/debs/fallback/"; done
say "debs: ${CARRY[*]} (+ fallback libstdc++6 libgcc-s1)"

# ---- OIDN (from pyoidn's wheel: the .venv's copy, or a downloaded wheel) ----
OIDN_NOTE="left out (GPU_PACK_OIDN=0)"
if [ "$WITH_OIDN" = 1 ]; then
  OD="" FROM=""
  for d in "$ROOT"/.venv/lib/python3*/site-packages/pyoidn/oidn; do [ -x "$d/bin/oidnBenchmark" ] && OD=$d FROM=.venv; done
  if [ -z "$OD" ]; then
    mkdir -p "$G/whl"
    ls "$G"/whl/pyoidn-*.whl > /dev/null 2>&1 || python3 -m pip download -q pyoidn --no-deps --only-binary=:all: \
      --python-version 3.12 --platform manylinux2014_x86_64 -d "$G/whl" > "$G/whl/pip.log" 2>&1 || true
    whl=$(ls "$G"/whl/pyoidn-*.whl 2>/dev/null | tail -1)
    if [ -n "$whl" ]; then
      rm -rf "$G/whl/x" && mkdir -p "$G/whl/x"
      (cd "$G/whl/x" && python3 -m zipfile -e "$whl" .)
      chmod +x "$G"/whl/x/pyoidn/oidn/bin/* 2>/dev/null || true
      OD=$G/whl/x/pyoidn/oidn FROM=$(basename "$whl")
    fi
  fi
  if [ -n "$OD" ]; then
    rm -rf "$G/oidn-stage" && mkdir -p "$G/oidn-stage/oidn/bin" "$G/oidn-stage/oidn/lib"
    cp "$OD/bin/oidnBenchmark" "$G/oidn-stage/oidn/bin/"
    # Only what the CUDA (and, for the dry run, CPU) devices load; SYCL/HIP and their runtimes stay behind.
    # TBB too: the pack's debs bring Debian's libtbb12 (oneTBB 2021.8), which exports every TBB
    # symbol OIDN 2.5.1's libraries use (18, checked with objdump -T on 2026-12-07), and the wheel's
    # copy (1 MB compressed) no longer fits beside the tree (20 MB) in the 64 MiB a call sends.
    (cd "$OD/lib" && cp -L libOpenImageDenoise.so.2 libOpenImageDenoise_core.so.2.* libOpenImageDenoise_device_cuda.so.2.* \
       libOpenImageDenoise_device_cpu.so.2.* "$G/oidn-stage/oidn/lib/")
    rm -rf "$OPACK" && mkdir -p "$OPACK"
    tar -C "$G/oidn-stage" -cf - oidn | xz -9 -T"$JOBS" > "$OPACK/oidn.tar.xz"
    cp "$PACK/tests.txt" "$OPACK/" 2> /dev/null || true
    OIDN_NOTE="OIDN $(ls "$OD"/lib/libOpenImageDenoise.so.2.* | sed 's/.*\.so\.//') (oidnBenchmark, core, CUDA + CPU devices; TBB from the debs) from pyoidn in $FROM"
  else
    OIDN_NOTE="pyoidn wheel not found (.venv or pip download): no OIDN comparison"
  fi
fi
say "oidn: $OIDN_NOTE"

# ---- manifest and size check ----
GLIBC=$(for b in "${BINS[@]}"; do objdump -T "$b"; done | grep -o 'GLIBC_[0-9.]*' | sort -uV | tail -1)
GLIBCXX=$(for b in "${BINS[@]}"; do objdump -T "$b"; done | grep -o 'GLIBCXX_[0-9.]*' | sort -uV | tail -1)
TOTAL=$(du -sb "$PACK" | cut -f1)
python3 - "$PACK" "$COMMIT" "$TOTAL" "$LIMIT" "$GLIBC" "$GLIBCXX" "$OIDN_NOTE" "$(nvcc --version | tail -1)" <<'EOF'
import json, os, sys, datetime
pack, commit, total, limit, glibc, glibcxx, oidn, nvcc = sys.argv[1:]
files = {os.path.relpath(os.path.join(r, f), pack): os.path.getsize(os.path.join(r, f))
         for r, _, fs in os.walk(pack) for f in fs}
json.dump({"commit": commit, "built_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
           "cuda_architectures": "90", "nvcc": nvcc, "needs": [glibc, glibcxx], "oidn": oidn,
           "total_bytes": int(total), "limit_bytes": int(limit), "files": dict(sorted(files.items()))},
          open(os.path.join(pack, "manifest.json"), "w"), indent=1)
EOF
TOTAL=$(du -sb "$PACK" | cut -f1)
# What a call sends: the tracked (and untracked, not ignored) files plus the carried pack.
TREE=$( (git ls-files -z; git ls-files -z --others --exclude-standard) | du -cb --files0-from=- 2> /dev/null | tail -1 | cut -f1)
say "pack: $PACK, $((TOTAL / 1024)) KiB + the tree's $((TREE / 1024)) KiB of the 65536 KiB a call sends (binaries need $GLIBC, $GLIBCXX)"
BAD=0
[ $((TOTAL + TREE)) -le "$LIMIT" ] || { echo "gpu-pack: pack + tree are over 64 MiB" >&2; BAD=1; }
if [ -f "$OPACK/oidn.tar.xz" ]; then
  OT=$(du -sb "$OPACK" | cut -f1)
  say "pack-oidn: $OPACK, $((OT / 1024)) KiB + the tree's $((TREE / 1024)) KiB of 65536 KiB"
  [ $((OT + TREE)) -le "$LIMIT" ] || { echo "gpu-pack: pack-oidn + tree are over 64 MiB" >&2; BAD=1; }
fi
[ "$BAD" = 0 ] || exit 1
say "next: scripts/gpu-check.sh --dry-run (prints the run invocation for a GPU session)"
