#!/usr/bin/env bash
# Makes .venv-train (the learned filter's training environment: jax, optax, numpy, matplotlib at the
# versions pinned in scripts/train/requirements.txt) and installs the atrous package into it (the
# wheel scripts/python_install.sh builds in build-py/wheel/; built first when missing), so that the
# training scripts import atrous.learn as the package it is. Idempotent: the requirements are kept
# when the venv already imports them; the wheel is installed again each time (a few seconds), so
# .venv-train has the atrous of the last build. Training only; building, testing and running atrous
# never need it.
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV=${VENV_TRAIN:-.venv-train}
if ! { [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c "import jax, optax, numpy, matplotlib, OpenEXR" 2>/dev/null; }; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install --quiet --upgrade pip
    "$VENV/bin/pip" install --quiet -r scripts/train/requirements.txt
    "$VENV/bin/python" -c "import jax, optax; print('jax', jax.__version__, 'optax', optax.__version__)"
fi
./scripts/install_wheel.sh "$VENV"
