#!/usr/bin/env bash
# Installs the Python package into the project's venv (.venv, made by scripts/setup.sh) and runs
# pytest. The CUDA backend is left out of this second build to keep `make test` short: the C++
# build already compiles every .cu file, and no GPU is present where CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f python/src/bindings.cpp ] || exit 0  # the Python package is not there yet
PY="$PWD/.venv/bin/python"
JOBS=${JOBS:-$(nproc)}
CMAKE_BUILD_PARALLEL_LEVEL=$JOBS "$PY" -m pip install -q --no-build-isolation \
  -Ccmake.define.ATROUS_ENABLE_CUDA=${ATROUS_PY_CUDA:-OFF} .
cd tests/python
"$PY" -m pytest -q
