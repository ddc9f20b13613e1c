#!/usr/bin/env bash
# Creates .venv-corpus/ (ignored) with the third-party renderers used by
# scripts/corpus/render.py: Mitsuba 3 and Blender's bpy (Cycles), plus OpenEXR
# and numpy, and pyluxcore (LuxCoreRender) when it installs. Idempotent: does nothing when the venv already has them.
# Usage: scripts/corpus/setup.sh   (from anywhere)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
VENV="$ROOT/.venv-corpus"
PY="${PYTHON:-python3}"
# Mitsuba's llvm_ad_rgb variant (1.7x faster than scalar_rgb here) needs libLLVM >= 16 (Debian 12's
# 15 fails to JIT 'fminimum'): install libllvm19 with apt when we can; without it the scripts fall
# back to scalar_rgb.
if ! ls /usr/lib/x86_64-linux-gnu/libLLVM-19.so* >/dev/null 2>&1 && command -v apt-get >/dev/null; then
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo -n"
  # A fresh machine may have no package lists yet: update once when the package is unknown.
  apt-cache show libllvm19 >/dev/null 2>&1 || $SUDO apt-get update -qq >/dev/null 2>&1 || true
  $SUDO apt-get install -y -q libllvm19 >/dev/null 2>&1 || echo "setup.sh: libllvm19 not installed; Mitsuba uses scalar_rgb" >&2
fi
# pyluxcore (LuxCoreRender) renders the training split's third renderer (luxcore_train.py); optional:
# without it render.py --train renders Mitsuba and Cycles only and says so.
luxcore() {
  "$VENV/bin/python" -c 'import pyluxcore' >/dev/null 2>&1 ||
    "$VENV/bin/python" -m pip install --quiet pyluxcore >/dev/null 2>&1 ||
    echo "setup.sh: pyluxcore not installed; the training split has no LuxCore scenes" >&2
}
if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c 'import mitsuba, bpy, OpenEXR, numpy' 2>/dev/null; then
  luxcore
  exit 0
fi
"$PY" - <<'P'
import sys
if sys.version_info[:2] != (3, 11):
    sys.exit("scripts/corpus/setup.sh: bpy wheels need Python 3.11; set PYTHON=python3.11")
P
[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet mitsuba OpenEXR numpy
"$VENV/bin/python" -m pip install --quiet bpy
luxcore
"$VENV/bin/python" -c 'import mitsuba, bpy, OpenEXR; print("mitsuba", mitsuba.__version__, "bpy", bpy.app.version_string)'
