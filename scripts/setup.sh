#!/usr/bin/env bash
# Installs what atrous needs on a fresh Debian 12 machine: the C++ libraries from Debian's
# packages (only those missing), and with --python a local venv in .venv with the Python side's
# requirements (nanobind, numpy, pytest, matplotlib, pyoidn, flip-evaluator: ~400 MB, so
# `make demo`, which needs none of it, skips it).
set -euo pipefail
cd "$(dirname "$0")/.."
WITH_PYTHON=0
[ "${1:-}" = "--python" ] && WITH_PYTHON=1

PKGS=(build-essential cmake pkg-config
      libembree-dev libtbb-dev libopenexr-dev libdeflate-dev libturbojpeg0-dev libcli11-dev libtinyobjloader-dev libstb-dev
      nlohmann-json3-dev libdnnl-dev ocl-icd-opencl-dev libgtest-dev libbenchmark-dev libglfw3-dev libimgui-dev xvfb ffmpeg
      qemu-user   # qemu-x86_64 -cpu Westmere: tests/cpu_isa_test.cpp runs atrous without AVX
      clang libclang-rt-dev)  # the libFuzzer targets (scripts/libfuzz.sh): clang and its runtimes (libclang-rt-14-dev on Debian 12)

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [ "$WITH_PYTHON" = 1 ] && [ -f python/requirements.txt ]; then
  if [ ! -x .venv/bin/python ]; then
    echo "setup: creating .venv"
    python3 -m venv .venv
  fi
  stamp=.venv/.requirements.stamp
  if [ ! -f "$stamp" ] || ! cmp -s python/requirements.txt "$stamp"; then
    .venv/bin/python -m pip install -q --upgrade pip
    echo "setup: installing the Python requirements into .venv (a few minutes the first time)"
    .venv/bin/python -m pip install -q -r python/requirements.txt
    cp python/requirements.txt "$stamp"
  fi
fi
