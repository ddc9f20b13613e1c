#!/usr/bin/env bash
# Makes .venv-train (the learned filter's training environment: jax, optax, numpy, matplotlib at the
# versions pinned in scripts/train/requirements.txt). Idempotent: a venv that already imports them
# is kept. Training only; building, testing and running atrous never need it.
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV=${VENV_TRAIN:-.venv-train}
if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c "import jax, optax, numpy, matplotlib, OpenEXR" 2>/dev/null; then
    exit 0
fi
python3 -m venv "$VENV"
"$VENV/bin/pip" install --quiet --upgrade pip
"$VENV/bin/pip" install --quiet -r scripts/train/requirements.txt
"$VENV/bin/python" -c "import jax, optax; print('jax', jax.__version__, 'optax', optax.__version__)"
