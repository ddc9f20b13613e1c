#!/usr/bin/env bash
# Installs the Python package into the project's venv (scripts/python_install.sh) and runs pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f python/src/bindings.cpp ] || exit 0  # the Python package is not there yet
PY="$PWD/.venv/bin/python"
./scripts/python_install.sh
cd tests/python
"$PY" -m pytest -q
