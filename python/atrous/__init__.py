"""atrous: Monte Carlo path tracing and fast wavelet denoising.

    import atrous
    bufs = atrous.render("cornell", width=256, height=256, spp=16)
    clean = atrous.denoise(bufs["color"], albedo=bufs["albedo"], normal=bufs["normal"],
                           position=bufs["position"], variance=bufs["variance"], method="sure")

Arrays are H x W x 3 (or x 4: the first three channels are read; features may also be H x W or
H x W x 1, repeated into 3 channels), linear HDR. The array rule, checked by the library (the
package passes arrays through):

* numpy arrays of float32 or float16 are taken where they are, with any strides (C-contiguous,
  interleaved or planar views, negative strides): no copy of the colour, the variance or the
  emission (the filter's first pass reads them into its own planes); a feature the filter reads
  is copied into planar storage, which ``denoise(..., report=True)`` names (``copies``);
* float64 host arrays are converted to float32; anything that is not an array (a list) goes
  through numpy.asarray;
* anything else (integers, booleans, complex, another number of dimensions or channels, an empty
  array) is a ValueError naming the keyword;
* CUDA arrays (PyTorch tensors, CuPy arrays, anything with ``__dlpack__`` on a CUDA device),
  float32 or float16: on a CUDA build they are denoised on their GPU without a host round trip,
  and the result comes back as the same kind of array on the same device.

Image files: :func:`read_image` and :func:`write_image` use the library's own readers and writers
(OpenEXR, PFM, PNG), so Python reads what ``atrous render`` writes and the CLI reads what Python
writes.

Errors from the library arrive as ValueError (bad input: shapes, sizes, parameters, files) or
RuntimeError (everything else). NaN and Inf in the colour are treated as missing samples; the
output is always finite (a colour with no finite pixel at all is a ValueError).

Alpha: an H x W x 4 colour's 4th channel is alpha; :func:`denoise` returns it unchanged beside the
denoised colour, :func:`read_image` (``alpha=True``) and :func:`write_image` read and write it, as
``atrous denoise`` passes an RGBA file's alpha through (docs/inputs.md, "Alpha").
"""
from __future__ import annotations

import os
from typing import Any, Dict, Iterator, Optional, Sequence, Union

import numpy as np

from . import _core, names
from ._shared import _framework, list_methods as _list_methods, list_params as _list_params, wrap_like as _wrap_like
from .measure import metrics, relmse, temporal_metrics, tonemap
from .sequence import (SequenceDenoiser, Svgf, denoise_sequence, denoise_temporal, denoise_window, sequence_methods,
                       sequence_params)
from .vocabulary import Weights, _weights_arg, buffers, load_weights

__all__ = [
    "denoise",
    "prepared_planes",
    "render",
    "render_sequence",
    "metrics",
    "relmse",
    "temporal_metrics",
    "tonemap",
    "read_image",
    "read_buffers",
    "write_image",
    "Svgf",
    "builtin_scenes",
    "cuda_available",
    "denoise_params",
    "svgf_params",
    "temporal_params",
    "temporal_window_radius",
    "denoise_temporal",
    "denoise_window",
    "denoise_sequence",
    "SequenceDenoiser",
    "sequence_params",
    "render_params",
    "METHODS",
    "SEQUENCE_METHODS",
    "WEIGHTED_METHODS",
    "denoise_methods",
    "sequence_methods",
    "methods",
    "register_method",
    "load_plugin",
    "Weights",
    "load_weights",
    "buffers",
]

__version__ = "0.1.0"

# METHODS (the still methods), SEQUENCE_METHODS (those that denoise a sequence as a sequence:
# the built-in ones and a plugin's) and WEIGHTED_METHODS (those that read the learned filter's weights) are read from
# the library's registry when asked for (module __getattr__), so a method added with
# register_method is in them from then on.
def __getattr__(name: str) -> Any:
    if name == "METHODS":
        return tuple(str(r["name"]) for r in _core.denoise_methods())
    if name == "SEQUENCE_METHODS":
        return tuple(str(r["name"]) for r in _core.sequence_methods())
    if name == "WEIGHTED_METHODS":
        return tuple(str(r["name"]) for r in _core.denoise_methods() if r["uses_weights"])
    raise AttributeError(f"module 'atrous' has no attribute '{name}'")


def methods() -> list:
    """Every method, one dict each, from the library's registries: name, kind ("still": a method of
    :func:`denoise`; "sequence": of :class:`SequenceDenoiser` and :func:`denoise_sequence`),
    summary, registered (added with :func:`register_method` or by a plugin) and params (its
    parameter table: "denoise" for the still methods, i.e. :func:`denoise_params`; a sequence
    method's own, :func:`sequence_params`; "" for none). The still methods come first, in the
    order of the CLI's ``--method`` help."""
    rows = [dict(name=str(r["name"]), kind="still", summary=str(r["summary"]), registered=bool(r["registered"]),
                 params=str(r["params"])) for r in _core.denoise_methods()]
    rows += [dict(name=str(r["name"]), kind="sequence", summary=str(r["summary"]), registered=bool(r["registered"]),
                  params=str(r["params"])) for r in _core.sequence_methods()]
    return rows


def register_method(name: str, cascade: Any, summary: str = "",
                    reads: Sequence[str] = ("variance", "albedo", "normal", "position", "depth", "ids", "emission")) -> None:
    """Adds a still method to the library's registry: from then on it is a `method=` of
    :func:`denoise` (and of the farm's denoise job, docs/farm.md "Plugins"), and in
    :func:`methods`. `cascade(planes, out)` filters: `planes` is a dict of H x W x C float32 arrays,
    read-only views of the filter's own planes, prepared as for every method (sanitised, the
    emission taken out, fireflies clamped, demodulated by the albedo): color and variance (3
    channels), albedo, normal, position (3), depth (1) and ids (2; R object, G material), None when
    not given; `out` (H x W x 3, writable) receives the filtered colour in the same units. The
    library then applies the safety net (when on), remodulates and adds the filtered emission
    back. The views are valid during the call only. `reads`: the buffers the cascade reads (the
    others' planes are None, and a reader need not decode them); the albedo still demodulates
    the colour. The CPU only; the name must be new (letters,
    digits, '_', '-'), else ValueError. An exception in `cascade` reaches the caller of denoise
    as RuntimeError naming it. docs/python.md has an example."""
    if not callable(cascade):
        raise ValueError(f"register_method: cascade must be callable (got {type(cascade).__name__})")
    if isinstance(reads, str):
        reads = (reads,)
    _core.register_method(str(name), str(summary), cascade, [str(r) for r in reads])


def load_plugin(path: "PathLike") -> None:
    """Loads a C++ plugin, a shared library built against include/atrous whose entry point
    registers still and sequence methods (include/atrous/plugins.h): they are then in
    :func:`methods`, :data:`METHODS` / :data:`SEQUENCE_METHODS`, and run through :func:`denoise`,
    :class:`SequenceDenoiser` and :func:`denoise_sequence`, as in the CLI with ``atrous --plugin FILE.so``. Loading one twice does
    nothing; a missing or unloadable file, or a name already taken, raises ValueError."""
    _core.load_plugin(os.fsdecode(os.fspath(path)))


def denoise_methods() -> list:
    """The still methods, one dict per method, the library's registry in its order: name, summary,
    uses_weights (reads the learned filter's weights), registered (added by register_method or a
    plugin), params ("denoise": the table of :func:`denoise_params`), reads (the buffers a call
    with the default options reads, :func:`buffers`' names), param_groups (the groups of
    :func:`denoise_params` it reads), resolves (True for a choice that denoise() resolves into
    another row per call: auto) and combines (the rows whose reads it adds: blend's, auto's)."""
    return [dict(r) for r in _core.denoise_methods()]


def builtin_scenes() -> list:
    """Names of the built-in scenes accepted by :func:`render`."""
    return list(_core.builtin_scenes())


def denoise_params() -> list:
    """The keywords of :func:`denoise`, one dict per parameter, from the library's own table
    (include/atrous/params.h, which the CLI's flags and the viewer's controls come from too):
    name, kind ("int", "float", "bool", "choice", "float_list"), default (the C++ struct's), min,
    max (the allowed range of a number, or of a list's elements; None for the others), min_open
    (True when min itself is excluded), zero (what
    0 means when it is allowed outside [min, max], e.g. "off"), rule (the range as the error
    message says it), choices, doc, group (the C++ struct: eaw, sure, firefly, safety, or "" for
    DenoiseOptions' own fields), flag (the CLI's) and aliases (other accepted keywords: a negated
    switch's CLI name, no_firefly=True is firefly=False)."""
    return [dict(r) for r in _core.denoise_params()]


def svgf_params() -> list:
    """The keywords of :class:`Svgf` (:func:`sequence_params` of its row), in the form of :func:`denoise_params`."""
    return [dict(r) for r in _core.svgf_params()]


def temporal_params() -> list:
    """The keywords of :func:`denoise_temporal`'s ``temporal`` dict, in the form of :func:`denoise_params`."""
    return [dict(r) for r in _core.temporal_params()]


def temporal_window_radius(temporal: Optional[Dict[str, Any]] = None) -> int:
    """Frames on each side of t that :func:`denoise_temporal` reads with these ``temporal`` keywords."""
    return int(_core.temporal_window_radius(dict(temporal or {})))


def render_params() -> list:
    """The keywords of :func:`render` and :func:`render_sequence` (the C++ RenderSettings), in the
    form of :func:`denoise_params` (kind "uint" for the seed and the first sample index)."""
    return [dict(r) for r in _core.render_params()]


def _render_settings(settings: Dict[str, Any]) -> Dict[str, Any]:
    # Integers must be integers (a float width is a mistake, not a request to truncate); the
    # library checks the names and ranges (ValueError naming the keyword).
    kinds = {r["name"]: r["kind"] for r in _core.render_params()}
    for name, v in settings.items():
        if kinds.get(name) in ("int", "uint") and (not isinstance(v, (int, np.integer)) or isinstance(v, bool)):
            raise ValueError(f"{name} must be an integer, got {v!r}")
    return {k: (int(v) if isinstance(v, np.integer) else v) for k, v in settings.items()}


def cuda_available() -> bool:
    """True when this build has the CUDA backend and a GPU is present."""
    return bool(_core.cuda_available())


def denoise(
    color: Any,
    *,
    albedo: Any = None,
    normal: Any = None,
    position: Any = None,
    depth: Any = None,
    variance: Any = None,
    ids: Any = None,
    emission: Any = None,
    method: Optional[str] = None,
    device: str = "auto",
    learned_weights: Union["PathLike", "Weights", None] = None,
    ldr: bool = False,
    report: bool = False,
    **params: Any,
) -> Any:
    """Denoises a Monte Carlo rendering with one of the library's still methods.

    The buffers and their conventions are :func:`buffers`' (one table for the renderer, the
    readers and every denoiser). color: H x W x 3 mean radiance (linear HDR), or H x W x 4 with
    alpha: the alpha is not denoised and comes back as it was (the same values, as float32).
    variance: the variance of that mean per channel (not the sample variance); without it the noise
    is estimated from the image. albedo, normal (world-space, unit), position (world-space), depth
    (view depth, channel 0), ids (object id, and the material id in a second channel when given;
    -1 background): optional features; a missing one simply has no edge stop. emission: the emitted
    radiance seen at the primary hit; the filter works on color - emission and adds it back, so a
    visible light's edge is not smeared. Every array follows the module's array rule (float32 or
    float16, any strides, taken without a copy).

    method: a name of :data:`METHODS` (the library's registry, :func:`denoise_methods`), None for
    the library's default:

{methods}

    learned_weights: the network of the methods that read it (:data:`WEIGHTED_METHODS`): a Weights
    from :func:`load_weights` (read once, shared by calls), a weight file's path (version 4, or 3;
    read by this call) or None (the built-in weights); a bad file raises ValueError naming it.
    device: "auto" (the arrays' device: CUDA arrays on the GPU, numpy on the CPU), "cpu" or
    "cuda" (numpy inputs are then filtered on the GPU and the result comes back to the host).

    ldr: the colour is LDR, display-referred values in [0, 1] (what :func:`read_image` returns for
    an 8-bit PNG or JPEG: its codes through the sRGB curve), as OIDN's hdr=False: the output is
    clamped to [0, 1], and a variance is refused (ValueError); `atrous denoise --color FILE.png` does
    this for an 8-bit file by itself (docs/inputs.md, "LDR input").

    params: the filter parameters, the rows of :func:`denoise_params` (the CLI's flags with '_'
    for '-'; docs/denoising.md gives their meaning and defaults):

{params}

    Returns the denoised H x W x 3 (x 4 with alpha) float32 image as the same kind of array as
    `color`; with report=True, a pair (image, report): the report is a dict of what the call did
    (the C++ DenoiseReport): method_used (auto resolved), noise_estimated, variance_ignored,
    noise_sigma, non_finite_pixels, fireflies_clamped, buffers_used (the CLI's line), milliseconds
    (the filter), stages (a list of (name, ms)) and copies (the buffers copied into planar storage
    before filtering, e.g. "albedo (float16, 3 channels)"; never the colour, the variance or the
    emission).
    """
    if ldr and variance is not None:
        raise ValueError("variance: ldr=True takes no variance (the variance of display-encoded values is not the "
                         "variance of the pixel mean atrous filters with); give the HDR colour with it, or drop it")
    out, rep = _core.denoise(color, albedo, normal, position, depth, variance, ids, emission, method or "",
                             str(device), _weights_arg(learned_weights), dict(params), bool(report))
    image = _finish(_wrap_like(out, color), ldr, _alpha_of(color))
    return (image, dict(rep)) if report else image


def _alpha_of(color: Any) -> Any:
    """The 4th channel of an H x W x 4 colour (a view), else None: the library reads the first three."""
    shape = getattr(color, "shape", None)
    if shape is None:
        color = np.asarray(color)
        shape = color.shape
    return color[:, :, 3:] if len(shape) == 3 and shape[2] == 4 else None


def _finish(out: Any, ldr: bool, alpha: Any) -> Any:
    """denoise's output: clamped to [0, 1] for LDR input, the colour's alpha added back unchanged."""
    fw = _framework(out)
    if ldr:
        if fw == "torch":
            out = out.clamp_(0.0, 1.0)
        elif fw == "cupy":  # pragma: no cover - needs a GPU
            import cupy

            cupy.clip(out, 0.0, 1.0, out=out)
        else:
            np.clip(out, 0.0, 1.0, out=out)
    if alpha is None:
        return out
    if fw == "torch":
        import torch

        a = alpha if _framework(alpha) == "torch" else torch.from_numpy(np.ascontiguousarray(alpha))
        return torch.cat([out, a.to(device=out.device, dtype=out.dtype)], dim=2)
    if fw == "cupy":  # pragma: no cover - needs a GPU
        import cupy

        return cupy.concatenate([out, cupy.asarray(alpha, dtype=out.dtype)], axis=2)
    return np.concatenate([out, np.asarray(alpha, dtype=out.dtype)], axis=2)


def prepared_planes(color: Any, variance: Any = None, albedo: Any = None, normal: Any = None,
                    depth: Any = None, emission: Any = None, *, position: Any = None, ids: Any = None,
                    method: Optional[str] = None, **params: Any) -> Dict[str, np.ndarray]:
    """The planes a still method's cascade reads (C++ preparePlanes, docs/learned.md), from the
    library's own preparation: what :func:`denoise` does before any filter (NaN/Inf repair, the
    emission split and the emission filter, the firefly clamp, the per-pixel noise estimate without
    a variance, albedo demodulation), on the CPU. For training: the network then sees exactly what
    it sees in the library; and for checking a cascade against :func:`denoise`.

    method: the method whose preparation this is (None: the learned filter's, the first of
    :data:`WEIGHTED_METHODS`); the other arguments, keywords and errors are those of
    :func:`denoise` (host arrays only). Returns a dict of H x W x C float32 arrays, named as the
    C++ PreparedPlanes' fields: ``color`` (3: the demodulated, firefly-clamped colour),
    ``variance`` (3: its variance, given or estimated, demodulated), ``albedo`` (3: the sanitised
    albedo the colour was divided by; absent without an albedo or with demodulate=False),
    ``normal`` (3), ``position`` (3), ``depth`` (1), ``ids`` (2; each absent when not given or not
    read by the method),
    ``modulation`` (3: the per-pixel factor the library's output multiplies the filtered
    ``color`` by; 1 without an albedo) and ``emission`` (3: the filtered emission added after; 0
    without one). With the safety net off, the library's output is
    ``filtered(color) * modulation + emission``.
    """
    return dict(_core.prepared_planes(color, variance, albedo, normal, depth, emission, position, ids, method or "",
                                      dict(params)))


def render(scene: str, **settings: Any) -> Dict[str, np.ndarray]:
    """Path-traces `scene` (a built-in name or a JSON scene file) on the CPU.

    settings: the rows of :func:`render_params` (the CLI's ``atrous render`` flags with '_' for
    '-'; defaults 512 x 512, 16 spp, seed 1, max_depth 8, all threads):

{params}

    Returns a dict of H x W x 3 float32 arrays: color, variance (of the mean), albedo, normal,
    position, depth, ids, emission (docs/rendering.md). Same seed, same pixels, whatever the
    thread count.
    """
    return dict(_core.render(str(scene), _render_settings(settings)))


def render_sequence(scene: str, frames: int, *, camera_path: str = "auto", spp: int = 1,
                    **settings: Any) -> Iterator[Dict[str, Any]]:
    """Renders the animation of `scene` frame by frame, as `atrous render --frames` does.

    settings: those of :func:`render` (spp defaults to 1 here). A generator: each item is the dict
    of :func:`render` plus ``motion`` (H x W x 3, R = dx,
    G = dy in pixels, previous - current; frame 0 has none) and ``time`` (t in [0, 1]). Frame f is
    at t = f / (frames - 1), with seed ``seed + f`` (so its samples are fresh), exactly the frames
    the CLI writes. camera_path: "auto" (the scene's keyframes, else static), "static", "orbit",
    "dolly" or "keyframes" (docs/scenes.md). Feed the items to :class:`Svgf`::

        s = atrous.Svgf()
        for b in atrous.render_sequence("cornell-moving", 32, width=256, height=256):
            out = s.denoise_frame(b["color"], albedo=b["albedo"], normal=b["normal"], depth=b["depth"],
                                  ids=b["ids"], motion=b["motion"], emission=b["emission"])
    """
    if not isinstance(frames, (int, np.integer)) or isinstance(frames, bool):
        raise ValueError(f"frames must be an integer, got {frames!r}")
    if int(frames) < 1:
        raise ValueError(f"frames must be at least 1, got {frames}")
    rs = _render_settings(dict(settings, spp=spp))
    for f in range(int(frames)):
        yield dict(_core.render_frame(str(scene), f, int(frames), str(camera_path), rs))


PathLike = Union[str, "os.PathLike[str]"]


def read_image(path: PathLike, *, alpha: bool = False) -> np.ndarray:
    """Reads an image file as an H x W x 3 float32 numpy array (linear RGB).

    The format follows the extension, read by the C++ library: .exr (OpenEXR: R, G, B channels;
    or Y, or a single channel, repeated into R, G, B; any compression and pixel type OpenEXR
    reads), .pfm (colour or grey), .png/.jpg (8- and 16-bit files through the sRGB curve into
    linear [0, 1]: LDR, see :func:`denoise`'s ldr; the exact inverse of :func:`write_image`'s PNG),
    .hdr. alpha=True: H x W x 4 when the file has an alpha channel (an EXR's A beside the colour, a
    PNG's alpha), the alpha as stored; H x W x 3 when it has none. Raises ValueError naming the file
    when it is missing, unreadable, truncated, not an image, has channels that do not make RGB, or
    an alpha channel of another size than the colour.
    """
    return _core.read_image(os.fsdecode(os.fspath(path)), bool(alpha))


def read_buffers(path: PathLike, *, passes: Optional[Dict[str, str]] = None, layer: str = "",
                 motion: bool = False) -> Dict[str, Any]:
    """One render's buffers as its renderer wrote them, the way `atrous denoise --in PATH` reads
    them (docs/inputs.md): a layered EXR (Blender's multilayer file, Mitsuba's AOV output) or a
    render folder (atrous's names, LuxCore's). passes: {buffer: pass name} where the automatic
    mapping needs help ("albedo": "ViewLayer.Denoising Albedo"); layer: the view layer of a file
    with several.

    Returns {name: H x W x C float32 array} for each buffer found, ready for :func:`denoise`
    (``atrous.denoise(**atrous.read_buffers(path))``): color, variance, albedo, normal, position
    (3 channels), depth (1: view depth), ids (2: object, material id; -1 background), emission
    (3); with motion=True also motion (2: previous - current, pixels, y down), for sequences.
    Which file and pass each came from, and the conventions applied, are printed by
    `atrous inspect PATH`. Raises ValueError naming the file for what cannot be read."""
    d = _core.read_buffers(os.fsdecode(os.fspath(path)),
                           [f"{k}={v}" for k, v in (passes or {}).items()], layer)
    if not motion:
        d.pop("motion", None)
    return d


def write_image(path: PathLike, image: Any) -> None:
    """Writes an H x W x 3 (or H x W / H x W x 1 grey, or H x W x 4 with alpha) image by the file's
    extension.

    .exr: 32-bit float R, G, B (and A), ZIP compressed (lossless: :func:`read_image` returns the same
    float32 values; grey is written into all three channels); .pfm: colour or grey (no alpha: an
    H x W x 4 image is a ValueError); .png: an 8-bit sRGB preview (clamped to [0, 1]; alpha as 8-bit
    linear coverage). The array rule of the module docstring applies (other float
    dtypes are converted to float32, integers are rejected). The file is written under a temporary
    name and renamed, so a failure never leaves half a file. Raises ValueError naming the file for
    a bad shape or dtype, an unknown extension or a directory that does not exist or cannot be
    written; RuntimeError when the encoder itself fails.
    """
    _core.write_image(os.fsdecode(os.fspath(path)), image)


# The docstrings list the keywords from the library's table, so they cannot fall behind it.
if denoise.__doc__:
    denoise.__doc__ = denoise.__doc__.replace("{params}", _list_params(denoise_params())).replace(
        "{methods}", _list_methods(denoise_methods()))
if render.__doc__:
    render.__doc__ = render.__doc__.replace("{params}", _list_params(render_params()))

