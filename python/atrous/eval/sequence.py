"""Frame sequences for the evaluation: the sequence methods (temporal, SVGF, ...) next to the per-frame methods.

Layout (the one include/atrous/io/sequence.h reads): DIR/frame_0000/, frame_0001/, ... each holding
color.exr albedo.exr normal.exr position.exr depth.exr ids.exr motion.exr and optionally
reference.exr, variance.exr, emission.exr. EXRs are read and written by the library's OpenEXR
code (atrous.read_image / atrous.write_image), the same that `atrous render` writes with.
"""
from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np

import atrous

REQUIRED = ("color", "albedo", "normal", "position", "depth", "ids", "motion")
OPTIONAL = ("reference", "variance", "emission")
_FRAME = re.compile(r"^frame_(\d{4,})$")


def list_frames(seq_dir: str) -> List[Path]:
    d = Path(seq_dir)
    if not d.is_dir():
        raise ValueError(f"sequence {seq_dir}: not a directory")
    frames = sorted(((int(m.group(1)), p) for p in d.iterdir()
                     if p.is_dir() and (m := _FRAME.match(p.name))), key=lambda t: t[0])
    if not frames:
        raise ValueError(f"sequence {seq_dir}: no frame_NNNN directories")
    for (a, _), (b, pb) in zip(frames, frames[1:]):
        if b != a + 1:
            raise ValueError(f"sequence {seq_dir}: frame_{a + 1:04d} is missing (gap before {pb.name})")
    return [p for _, p in frames]


def load_frame(frame_dir: Path) -> Dict[str, np.ndarray]:
    bufs: Dict[str, np.ndarray] = {}
    for name in REQUIRED + OPTIONAL:
        p = frame_dir / f"{name}.exr"
        if not p.is_file():
            if name in REQUIRED:
                raise ValueError(f"{p}: missing (every frame needs {name}.exr)")
            continue
        bufs[name] = atrous.read_image(p)
        if bufs[name].shape != bufs["color"].shape:
            raise ValueError(f"{p}: is {bufs[name].shape[1]}x{bufs[name].shape[0]} but color.exr is "
                             f"{bufs['color'].shape[1]}x{bufs['color'].shape[0]}")
    return bufs


def write_static_sequence(seq_dir: str, scene: str, frames: int, width: int, height: int,
                          ref_spp: int = 256, seed: int = 1, reference: Optional[np.ndarray] = None) -> None:
    """A static-camera sequence from the renderer: `frames` 1-spp frames with their own seeds,
    motion 0, one shared reference (ref_spp samples, another seed, or `reference`) in every frame."""
    d = Path(seq_dir)
    d.mkdir(parents=True, exist_ok=True)
    ref = reference
    if ref is None:
        ref = atrous.render(scene, width=width, height=height, spp=ref_spp, seed=1000003)["color"]
    for i in range(frames):
        b = atrous.render(scene, width=width, height=height, spp=1, seed=seed + 7919 * i)
        f = d / f"frame_{i:04d}"
        f.mkdir(exist_ok=True)
        for name in ("color", "albedo", "normal", "position", "depth", "ids", "variance"):
            atrous.write_image(f / f"{name}.exr", b[name])
        atrous.write_image(f / "motion.exr", np.zeros_like(b["color"]))
        atrous.write_image(f / "reference.exr", ref)


def sequence_window(count: int, index: int, method: str, *, motion_given: bool = True, params: Optional[Dict[str, Any]] = None,
                    **still: Any) -> Tuple[int, int]:
    """The first and last frame (inclusive) that sequence method `method` reads for frame `index` of
    `count` frames with these parameters (its own table's, `params`; `still`: the still method's):
    index - its lookbehind .. index + its lookahead (temporal: the window's radius, static_radius
    when larger and the motion is the renderer's), clipped to the sequence."""
    d = atrous.SequenceDenoiser(method, device="cpu", motion_given=motion_given, params=params, **still)
    return max(0, index - d.lookbehind), min(count - 1, index + d.lookahead)


def sequence_outputs(method: str, frames: List[Dict[str, Any]]) -> Tuple[List[Any], List[float]]:
    """Every frame through one stream of `method` (its defaults, on the CPU), in order: the outputs
    and the milliseconds of each (its next(): a window method's frame is denoised once the frames
    after it it reads are in)."""
    d = atrous.SequenceDenoiser(method, device="cpu")
    outs: List[Any] = []
    times: List[float] = []

    def drain() -> None:
        while d.ready:
            t0 = time.perf_counter()
            outs.append(d.next())
            times.append((time.perf_counter() - t0) * 1e3)

    for f in frames:
        d.push(f)
        drain()
    d.finish()
    drain()
    return outs, times


def evaluate_sequence(seq_dir: str, methods: Dict[str, Optional[Callable]],
                      log: Callable[[str], None] = print) -> Dict[str, Any]:
    """Every sequence method of the library (atrous.SEQUENCE_METHODS: the temporal method, frames
    t-3..t+3, t-6..t+6 where still, the CLI's --sequence default; SVGF, history carried over
    frames; a plugin's) through one stream each, and every per-frame method on each frame.

    Metrics per frame against reference.exr when present (FLIP on the last frame only: it costs
    ~0.5 s an image); temporal relMSE = relMSE of frame-to-frame differences against the
    references' differences, normalised by the current reference. Time: median per frame over
    frames after the first (the first warms caches up).
    """
    from . import score

    paths = list_frames(seq_dir)
    streams = list(atrous.SEQUENCE_METHODS)
    names = streams + [m for m in methods]
    # The sequence methods read the frames around each one, or their history: every frame is loaded
    # first, and each method's stream runs over all of them.
    loaded = [load_frame(p) for p in paths]
    window = [{k: v for k, v in b.items() if k != "reference"} for b in loaded]
    sequence_outs = {m: sequence_outputs(m, window) for m in streams}
    frames_out: List[Dict[str, Any]] = []
    times: Dict[str, List[float]] = {m: list(sequence_outs[m][1]) if m in sequence_outs else [] for m in names}
    prev: Dict[str, np.ndarray] = {}
    prev_ref: Optional[np.ndarray] = None
    temporal: Dict[str, List[float]] = {m: [] for m in names}
    last: Dict[str, Any] = {}
    width = height = 0
    for i, p in enumerate(paths):
        b = loaded[i]
        height, width = b["color"].shape[:2]
        b.setdefault("variance", None)
        outs: Dict[str, np.ndarray] = {m: sequence_outs[m][0][i] for m in streams}
        for m, fn in methods.items():
            if fn is None:
                outs[m] = b["color"]
                times[m].append(0.0)
                continue
            t0 = time.perf_counter()
            outs[m] = fn(b)
            times[m].append((time.perf_counter() - t0) * 1e3)
        ref = b.get("reference")
        row: Dict[str, Any] = {"frame": p.name, "relmse": {}}
        if ref is not None:
            for m, o in outs.items():
                row["relmse"][m] = atrous.relmse(o, ref)
                if prev_ref is not None and m in prev:
                    temporal[m].append(atrous.temporal_metrics(o, prev[m], ref, prev_ref)["relmse"])
            if i == len(paths) - 1:
                last = {m: score(o, ref) for m, o in outs.items()}
        prev = dict(outs)
        prev_ref = ref
        frames_out.append(row)
        log(f"sequence {p.name}: " + ", ".join(f"{m} {v:.4f}" for m, v in row["relmse"].items()))
    summary: Dict[str, Dict[str, Any]] = {}
    for m in names:
        rel = [f["relmse"][m] for f in frames_out if m in f["relmse"]]
        t = times[m][1:] if len(times[m]) > 1 else times[m]
        lm = last.get(m, {})
        summary[m] = {"relmse": float(np.mean(rel)) if rel else None,
                      "relmse_last_frame": rel[-1] if rel else None,
                      "psnr": lm.get("psnr"), "ssim": lm.get("ssim"), "flip": lm.get("flip"),
                      "temporal_relmse": float(np.mean(temporal[m])) if temporal[m] else None,
                      "ms": float(np.median(t)) if t else None}
    return {"dir": str(seq_dir), "num_frames": len(paths), "width": width, "height": height,
            "methods": names, "frames": frames_out, "summary": summary,
            "metric_note": "relMSE: mean over frames; PSNR, SSIM and FLIP: last frame only"}
