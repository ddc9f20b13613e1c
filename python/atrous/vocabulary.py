"""The library's vocabulary: the buffers of a frame (include/atrous/buffers.h) and the learned
filter's network as a resource loaded once (LearnedWeights)."""
from __future__ import annotations

import os
from typing import Any, Union

from . import _core

PathLike = Union[str, "os.PathLike[str]"]
Weights = _core.Weights


def buffers() -> list:
    """The buffers of a frame, one dict each (name, channels, takes_grey, meaning): the vocabulary
    and conventions every reader, the renderer and every denoiser share (include/atrous/buffers.h).
    A frame's `ids` holds object_id in channel 0 and material_id in channel 1."""
    return [dict(r) for r in _core.buffers()]


def load_weights(path: "PathLike") -> "Weights":
    """Reads a weight file of the learned filter (version 4, or 3; docs/learned.md) once: pass the
    result as learned_weights= to every call that should share it (a batch, a sequence). A bad
    file raises ValueError naming it."""
    return _core.load_weights(os.fsdecode(os.fspath(path)))


def _weights_arg(w: Any) -> Any:
    """learned_weights= as the core takes it: None (the built-in weights), a Weights or a path."""
    return w if w is None or isinstance(w, Weights) else os.fsdecode(os.fspath(w))
