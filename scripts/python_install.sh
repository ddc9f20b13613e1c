#!/usr/bin/env bash
# Builds the Python package (nanobind + scikit-build-core) and installs it into the project's venv
# (.venv, made by `scripts/setup.sh --python`). The CUDA backend is left out unless
# ATROUS_PY_CUDA=ON: the C++ build already compiles every .cu file, and the DLPack GPU path needs
# a GPU to be of any use.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="$PWD/.venv/bin/python"
JOBS=${JOBS:-$(nproc)}
echo "python: building and installing the atrous package into .venv (a few minutes)"
CMAKE_BUILD_PARALLEL_LEVEL=$JOBS "$PY" -m pip install -q --no-build-isolation \
  -Ccmake.define.ATROUS_ENABLE_CUDA=${ATROUS_PY_CUDA:-OFF} .
echo "python: done; try  .venv/bin/python -c 'import atrous; print(atrous.builtin_scenes())'"
