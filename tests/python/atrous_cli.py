"""Where the Python tests find the atrous CLI: $ATROUS_CLI, else the build that `make test` made
(build/atrous), else an `atrous` on PATH; None when there is none (the tests that need it skip)."""
from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Optional

REPO = Path(__file__).resolve().parents[2]


def atrous_cli() -> Optional[str]:
    for cand in (os.environ.get("ATROUS_CLI"), str(REPO / "build" / "atrous"), shutil.which("atrous")):
        if cand and os.path.isfile(cand) and os.access(cand, os.X_OK):
            return cand
    return None


def toy_plugin_so() -> Optional[str]:
    """The C++ toy method built as a plugin (tests/toy_method.cpp): beside the CLI's build, or None."""
    cli = atrous_cli()
    cand = Path(cli).parent / "tests" / "libatrous_toy_plugin.so" if cli else None
    return str(cand) if cand is not None and cand.is_file() else None
