"""What the Python benchmark scripts record about the machine and the tree, and how they print it
(standard library only)."""
from __future__ import annotations

import json
import platform
import subprocess
from pathlib import Path
from typing import Optional

ROOT = Path.cwd()  # the repository root: run from it (its out/ and build/ are the defaults)


def cpu_model(unknown: str = "unknown") -> str:
    """The CPU's model name (/proc/cpuinfo), else what platform reports."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or unknown


def git_commit() -> str:
    """HEAD's hash, with "+uncommitted" when tracked files differ from it ("unknown" outside git)."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                              check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                               capture_output=True, text=True, check=True).stdout.strip()
        return head + ("+uncommitted" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def emit(doc: dict, out: Optional[str] = None) -> None:
    """The benchmark's one JSON document: on stdout, and in `out` when given."""
    text = json.dumps(doc, indent=2)
    print(text)
    if out:
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        Path(out).write_text(text + "\n")
