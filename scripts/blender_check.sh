#!/usr/bin/env bash
# The Blender add-on's headless check (make test runs it; docs/blender.md): installs the atrous wheel
# that scripts/python_install.sh built (build-py/wheel/) into .venv-corpus, where Blender's bpy
# module lives (scripts/corpus/setup.sh makes it), and runs tests/blender/addon_check.py: a Cycles
# animation rendered with bpy, denoised through the add-on's operator, checked against a 256-spp
# reference, and its bad-input cases. Usage: scripts/blender_check.sh
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/corpus/setup.sh
./scripts/install_wheel.sh .venv-corpus
.venv-corpus/bin/python tests/blender/addon_check.py
