"""Sequences: the methods that denoise an animation as a sequence (the library's registry:
temporal, svgf, a plugin's), through one interface.

A :class:`SequenceDenoiser` takes the frames of one stream in order (dicts of arrays, the items of
:func:`atrous.render_sequence`) and hands back the denoised frames in order, each once the frames
after it that its method reads are in (``lookahead``: temporal's window radius, 0 for svgf).
:class:`Svgf` and :func:`denoise_temporal` are conveniences over it; :func:`denoise_sequence` is
the session ``atrous denoise --sequence`` runs, from files to files. No method is named here: the
names, parameter tables and what each method reads come from the registry
(:func:`sequence_methods`).
"""
from __future__ import annotations

import os
from typing import Any, Dict, Optional, Sequence, Union

from . import _core
from ._shared import list_params as _list_params, wrap_like as _wrap_like
from .names import SVGF, TEMPORAL
from .vocabulary import _weights_arg

__all__ = ["sequence_methods", "sequence_params", "SequenceDenoiser", "Svgf", "denoise_window", "denoise_temporal",
           "denoise_sequence"]

# SVGF and TEMPORAL (atrous.names): the rows :class:`Svgf` and :func:`denoise_temporal` run, their
# names from the registry's own files, for code that is about one of them (the evaluation's SVGF study).


def sequence_methods() -> list:
    """The sequence methods, one dict per method, the library's list: name, label, summary, causal
    (each frame from the ones before it), causal_mode (has such a mode), history (carries state from
    frame to frame: its frames must come in order), still_method (ends with a still method,
    ``spatial=``), params (its parameter table's name: :func:`sequence_params`; "" for none),
    weights_param (the switch that makes it read the learned weights, or None), reads (the buffers
    it reads, :func:`atrous.buffers`) and registered (added by a plugin)."""
    return [dict(r) for r in _core.sequence_methods()]


def sequence_params(method: str) -> list:
    """The keywords of a sequence method's own table, in the form of :func:`atrous.denoise_params`."""
    return [dict(r) for r in _core.sequence_params(str(method))]


class SequenceDenoiser:
    """One stream of frames through a method of :data:`atrous.SEQUENCE_METHODS` (or a still method
    of :data:`atrous.METHODS`, run on each frame alone)::

        d = atrous.SequenceDenoiser(spatial="eaw")  # the first method, temporal
        for f in frames:
            d.push(f)
            while d.ready:
                out = d.next()
        d.finish()
        while d.ready:
            out = d.next()

    params: the method's own keywords (:func:`sequence_params`); spatial and the other keywords: the
    still method it ends with and that method's (:func:`atrous.denoise_params`); causal: run a
    method that has a causal mode in it; motion_given: the frames' motion vectors are the
    renderer's (False when they are fitted or estimated: temporal's static window is then off).
    Frames are dicts of arrays (color required; albedo, normal, position, depth, variance, ids,
    emission, motion); each result comes back on its frame's colour's device. Raises ValueError for
    bad input."""

    def __init__(self, method: Optional[str] = None, *, device: str = "auto", spatial: Optional[str] = None,
                 learned_weights: Union["os.PathLike", Any, None] = None, causal: bool = False,
                 motion_given: bool = True, params: Optional[Dict[str, Any]] = None, **still: Any) -> None:
        name = str(method) if method is not None else str(_core.sequence_methods()[0]["name"])
        self._impl = _core.SequenceDenoiser(name, str(device), str(spatial or ""), _weights_arg(learned_weights),
                                            dict(params or {}), dict(still), bool(causal), bool(motion_given))

    def push(self, frame: Dict[str, Any]) -> None:
        """The next frame (checked now; denoised by a later :meth:`next`)."""
        self._impl.push(frame)

    @property
    def ready(self) -> bool:
        """Whether :meth:`next` has a frame: ``lookahead`` frames after it are in, or :meth:`finish` was called."""
        return bool(self._impl.ready)

    def next(self) -> Any:
        """The next frame in order, denoised (H x W x 3 float32)."""
        return self._impl.next()

    def skip(self) -> None:
        """Passes the next ready frame over without denoising it (it stays in its neighbours' windows)."""
        self._impl.skip()

    def finish(self) -> None:
        """No more frames: those left come out without the later neighbours they would have had."""
        self._impl.finish()

    def reset(self) -> None:
        """Forgets every frame and the history: the next frame starts a new sequence."""
        self._impl.reset()

    lookahead = property(lambda self: int(self._impl.lookahead), doc="Frames after t pushed before t comes out.")
    lookbehind = property(lambda self: int(self._impl.lookbehind), doc="Frames before t that t's window holds.")
    method = property(lambda self: str(self._impl.method), doc="The method's name.")
    method_used = property(lambda self: str(self._impl.method_used),
                           doc="The still method the last frame ended with (auto resolved), else the method's name.")
    device = property(lambda self: str(self._impl.device), doc="Where it runs: cpu or cuda.")


class Svgf(SequenceDenoiser):
    """Spatiotemporal variance-guided filtering of a stream of 1-spp frames (keeps history): the
    svgf row of :func:`sequence_methods` as a :class:`SequenceDenoiser`.

    params: the rows of :func:`atrous.svgf_params` (docs/svgf.md gives their meaning):

{params}
    """

    def __init__(self, device: str = "auto", *, learned_weights: Union["os.PathLike", Any, None] = None,
                 **params: Any) -> None:
        """device: "auto" (CUDA when this build has a usable GPU, else the CPU, as everywhere in
        atrous), "cpu" or "cuda". Frames on another device than the filter's are copied over.
        learned_weights: for learned_spatial=True, a Weights (:func:`atrous.load_weights`) or a
        weight file (version 4, or 3); None = the built-in weights; a bad file raises ValueError
        naming it; unused without learned_spatial."""
        super().__init__(SVGF, device=device, learned_weights=learned_weights, params=params)

    def denoise_frame(self, color: Any, *, albedo: Any = None, normal: Any = None, depth: Any = None,  # type: ignore[override]
                      ids: Any = None, motion: Any = None, emission: Any = None, position: Any = None,
                      variance: Any = None) -> Any:
        """Denoises the next frame; motion is (dx, dy) in pixels, previous - current. position and
        variance reach the per-frame safety net's still filter (safety_net; SVGF itself has no use
        for them)."""
        frame = dict(color=color, albedo=albedo, normal=normal, depth=depth, ids=ids, motion=motion, emission=emission,
                     position=position, variance=variance)
        self.push(frame)
        return _wrap_like(self.next(), color)


if Svgf.__doc__:
    Svgf.__doc__ = Svgf.__doc__.replace("{params}", _list_params(_core.svgf_params()))


def _frames(frames: Sequence[Dict[str, Any]], center: int) -> list:
    if not isinstance(frames, (list, tuple)) or not frames:
        raise ValueError("frames must be a non-empty list of dicts")
    if isinstance(center, bool) or not isinstance(center, int) or not 0 <= int(center) < len(frames):
        raise ValueError(f"center must be a frame index in 0..{len(frames) - 1}, got {center!r}")
    return list(frames)


def denoise_window(method: str, frames: Sequence[Dict[str, Any]], center: int, *, device: str = "auto",
                   spatial: Optional[str] = None, learned_weights: Union["os.PathLike", Any, None] = None,
                   params: Optional[Dict[str, Any]] = None, **still: Any) -> Any:
    """Denoises frames[center] with the frames around it, through a sequence method without history
    (each frame depends on its window only: temporal, not svgf): the frames its window reads are
    pushed into a new :class:`SequenceDenoiser`, those before the centre skipped. Without motion in
    any frame, the motion comes from each frame's Position pass (a fitted camera) or its colours, as
    ``atrous denoise --sequence`` does. params, spatial and the keywords: as for
    :class:`SequenceDenoiser`. Host (numpy) arrays. Raises ValueError for bad input."""
    import numpy as np

    core = _frames(frames, center if not isinstance(center, np.integer) else int(center))
    out = _core.denoise_window(str(method), core, int(center), str(device), str(spatial or ""), _weights_arg(learned_weights),
                               dict(params or {}), dict(still))
    return _wrap_like(out, frames[int(center)]["color"])


def denoise_temporal(frames: Sequence[Dict[str, Any]], center: int, *, method: Optional[str] = None,
                     device: str = "auto", learned_weights: Union["os.PathLike", Any, None] = None,
                     temporal: Optional[Dict[str, Any]] = None, **params: Any) -> Any:
    """Denoises frames[center] of an animation with the frames around it (docs/temporal.md): the
    offline sequence denoiser that `atrous denoise --sequence` runs by default (:func:`denoise_window`
    with the temporal method).

    frames: a window of consecutive frames, each a dict of H x W x C numpy arrays with the keys of
    :func:`atrous.denoise` (color required; albedo, normal, position, depth, variance, ids, emission)
    and motion (H x W x 2 or 3: dx, dy in pixels, previous - current); every frame has the same keys.
    The items of :func:`atrous.render_sequence` are such dicts. Without motion in any frame but with
    a position in every one, the motion comes from each frame's fitted camera (as the CLI does).
    temporal: the rows of :func:`atrous.temporal_params` (radius: frames on each side, 3; ...).
    method, learned_weights and params: the still method run on the average, as in
    :func:`atrous.denoise`. device: where that still method runs ("auto", "cpu", "cuda"); the
    averaging runs on the CPU. Returns the denoised H x W x 3 float32 array. Raises ValueError for
    bad input."""
    return denoise_window(TEMPORAL, frames, center, device=device, spatial=method,
                          learned_weights=learned_weights, params=temporal, **params)


def denoise_sequence(input: "os.PathLike", out: "os.PathLike", *, method: Optional[str] = None,
                     spatial: Optional[str] = None, device: str = "auto",
                     learned_weights: Union["os.PathLike", Any, None] = None,
                     passes: Optional[Dict[str, str]] = None, layer: str = "", add_pass: str = "",
                     start: Optional[int] = None, end: Optional[int] = None, step: int = 1,
                     exposure: float = 1.0, pngs: bool = True, preview: bool = True,
                     on_frame: Any = None, **params: Any) -> Dict[str, Any]:
    """Denoises an animation from its files into the folder `out`: what `atrous denoise --sequence
    INPUT --out OUT` does (docs/temporal.md), from Python and the Blender add-on.

    input: a folder in any layout the CLI reads (atrous's frame_NNNN folders, one folder per frame
    with a renderer's own names such as LuxCore's, color_0001.exr-style numbered files, Blender's
    numbered multilayer renderNNNN.exr) or a pattern ("renders/render####.exr", "%04d").
    method: a sequence method (:data:`atrous.SEQUENCE_METHODS`; None: the first, temporal: frames
    t-3..t+3, t-6..t+6 where still), or a method of :data:`atrous.METHODS` run on each frame
    alone. spatial: the still method a sequence method ends with (temporal's, on its average).
    passes: {buffer: pass name} for layered frames (the CLI's --pass); layer: the view layer.
    start/end/step: the frames to denoise (None: the first / the last).
    params: a sequence method's own keywords as a dict under its table's name (the ``params`` of
    :func:`sequence_methods`: temporal={"radius": 2}, svgf={...}); the other keywords are the
    still method's rows (:func:`atrous.denoise_params`). on_frame(dict) is called as each frame is
    done. Writes the frames into the folder `out` under their input's names (render0001.exr ->
    out/render0001.exr, a frame folder frame_0001/ -> out/frame_0001.exr), or by a pattern `out` =
    DIR/clean####.exr (the frame number zero-padded to the count of #'s; or %04d), + .png and
    preview.mp4 unless pngs/preview are False, only when every frame is done; `out` must not be
    inside the input's folder. Returns the run's
    report: width, height, buffers (the names every frame has), frames (one dict each: index,
    input, output, method, method_used, ms, reprojected, mse, mse_input, line, and position and
    count: the k-th of the run's N frames, for a k/N counter),
    filter_ms_per_frame, wall_ms_per_frame, preview (the video's path, or None) and notes.
    Raises ValueError for bad input (nothing is written then)."""
    tables = {str(r["params"]) for r in _core.sequence_methods() if r["params"]}
    own = {k: dict(params.pop(k) or {}) for k in list(params) if k in tables}
    pass_specs = [f"{k}={v}" for k, v in (passes or {}).items()]
    weights = _weights_arg(learned_weights)
    return _core.denoise_sequence(os.fsdecode(os.fspath(input)), os.fsdecode(os.fspath(out)), str(method or ""),
                                  str(spatial or ""), device, weights, pass_specs, layer, add_pass,
                                  -1 if start is None else int(start), -1 if end is None else int(end), int(step),
                                  float(exposure), bool(pngs), bool(preview), own, dict(params), on_frame)
