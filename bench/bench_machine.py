"""What the Python benchmark scripts record about the machine (standard library only)."""
from __future__ import annotations

import platform
from pathlib import Path


def cpu_model(unknown: str = "unknown") -> str:
    """The CPU's model name (/proc/cpuinfo), else what platform reports."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or unknown
