#!/usr/bin/env bash
# The Blender add-on's headless check (make test runs it; docs/blender.md): installs the atrous wheel
# that scripts/python_install.sh built (build-py/wheel/) into .venv-corpus, where Blender's bpy
# module lives (scripts/corpus/setup.sh makes it), and runs tests/blender/addon_check.py: a Cycles
# animation rendered with bpy, denoised through the add-on's operator, checked against a 256-spp
# reference, and its bad-input cases. Usage: scripts/blender_check.sh
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/corpus/setup.sh
WHEEL=$(ls build-py/wheel/atrous-*.whl 2>/dev/null | head -1 || true)
[ -n "$WHEEL" ] || ./scripts/python_install.sh
WHEEL=$(ls build-py/wheel/atrous-*.whl | head -1)
.venv-corpus/bin/python -m pip install -q --no-deps --force-reinstall "$WHEEL"
.venv-corpus/bin/python tests/blender/addon_check.py
