#!/usr/bin/env bash
# Installs the atrous wheel that scripts/python_install.sh builds (build-py/wheel/; built first,
# with the project's .venv, when there is none) into another venv of the same Python (3.11):
# .venv-corpus for the Blender add-on's check, .venv-train for training. Without its dependencies
# (the venv has numpy). Usage: scripts/install_wheel.sh VENV_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${1:?usage: scripts/install_wheel.sh VENV_DIR}
if ! ls build-py/wheel/atrous-*.whl >/dev/null 2>&1; then
    ./scripts/setup.sh --python
    ./scripts/python_install.sh
fi
"$VENV/bin/python" -m pip install -q --no-deps --force-reinstall build-py/wheel/atrous-*.whl
