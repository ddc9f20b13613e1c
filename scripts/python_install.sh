#!/usr/bin/env bash
# Builds the Python package (nanobind + scikit-build-core) as a wheel in build-py/wheel/ and installs
# it into the project's venv (.venv, made by `scripts/setup.sh --python`); scripts/blender_check.sh
# installs the same wheel into .venv-corpus, where Blender's bpy lives. The CUDA backend is left out unless
# ATROUS_PY_CUDA=ON: the C++ build already compiles every .cu file, and the DLPack GPU path needs
# a GPU to be of any use.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="$PWD/.venv/bin/python"
JOBS=${JOBS:-$(nproc)}
echo "python: building and installing the atrous package into .venv (a few minutes)"
rm -rf build-py/wheel
CMAKE_BUILD_PARALLEL_LEVEL=$JOBS "$PY" -m pip wheel -q --no-build-isolation --no-deps -w build-py/wheel \
  -Ccmake.define.ATROUS_ENABLE_CUDA=${ATROUS_PY_CUDA:-OFF} .
"$PY" -m pip install -q --no-deps --force-reinstall build-py/wheel/atrous-*.whl
echo "python: done; try  .venv/bin/python -c 'import atrous; print(atrous.builtin_scenes())'"
