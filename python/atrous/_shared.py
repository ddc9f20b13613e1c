"""What the package's modules share, with no import of the package's own modules but _core (so that
none of them imports another in a cycle): results handed back as the caller's kind of array, and
the keyword lists of the docstrings, written from the library's tables."""
from __future__ import annotations

import textwrap
from typing import Any

import numpy as np


def _framework(x: Any) -> str:
    mod = type(x).__module__.split(".")[0]
    return mod if mod in ("torch", "cupy") else "numpy"


def wrap_like(result: Any, like: Any) -> Any:
    """A _core result as the same kind of array as the input `like` (numpy, a PyTorch tensor, a
    CuPy array); a GPU result through DLPack, without a copy."""
    fw = _framework(like)
    if isinstance(result, np.ndarray):
        if fw == "torch":
            import torch

            return torch.from_numpy(result)
        return result
    if fw == "torch":
        import torch

        return torch.from_dlpack(result)
    if fw == "cupy":
        import cupy

        return cupy.from_dlpack(result)
    return result


def list_params(rows) -> str:
    """The rows of a parameter table as the indented keyword list of a docstring."""
    out = []
    for r in rows:
        extra = " (" + " | ".join(r["choices"]) + ")" if r["choices"] else ""
        out.append(r["name"] + extra + "".join(", " + a for a in r["aliases"]))
    return textwrap.fill(", ".join(out) + ".", width=96, initial_indent="    ", subsequent_indent="    ",
                         break_on_hyphens=False)


def list_methods(rows) -> str:
    """The registry's still methods as the bulleted list of a docstring: name and summary."""
    return "\n".join(textwrap.fill(f"{r['name']}: {r['summary']}", width=96, initial_indent="    * ",
                                    subsequent_indent="      ") for r in rows)
