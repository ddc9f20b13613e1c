"""atrous-eval: the evaluation of the atrous denoisers against Intel Open Image Denoise.

    python -m atrous.eval --quick --out eval-out        # CI-sized: 2 scenes, 64x64, spp 4/16
    python -m atrous.eval --out eval-out                # all built-in scenes, 256x256, spp 4/16/64

For every scene x spp it renders a noisy input and a reference (the same renderer at --ref-spp
samples with another seed), runs each method (noisy = the input itself, eaw, sure, oidn; learned
and auto on request), and
measures relMSE, PSNR, SSIM (atrous.metrics), FLIP (HDR, flip_evaluator) and the denoise time
(median of --runs runs after a warm-up). It adds an equal-time comparison (the denoiser's time
spent on more samples instead, rendered and measured), runtime vs resolution, and, when given a
frame sequence (--sequence DIR, or --static-sequence N to synthesise one), the SVGF column. It
writes OUT/results.json, OUT/*.png plots and a self-contained OUT/report.html (docs/eval.md).
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import platform
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

import atrous
from atrous import names

__all__ = ["EvalConfig", "run_eval", "main", "load_oidn", "oidn_inputs", "time_call", "score"]



def all_methods() -> tuple:
    """What --methods may name: noisy, the library's still methods (as registered now), oidn."""
    return ("noisy",) + atrous.METHODS + ("oidn",)


# The default set (--methods not given): the wavelet filters EAW and SURE (their names from the
# registry) between the input and OIDN. learned (the learned à-trous filter, docs/learned.md),
# blend and auto are taken when asked for: --methods noisy,eaw,sure,learned,oidn.
DEFAULT_METHODS = ("noisy", names.EAW, names.SURE, "oidn")
QUICK_SCENES = ("cornell", "cornell-spheres")


@dataclass
class EvalConfig:
    """What to evaluate. `quick_config()` / the CLI fill it in."""

    out: str = "eval-out"
    scenes: List[str] = field(default_factory=lambda: list(atrous.builtin_scenes()))
    spp: List[int] = field(default_factory=lambda: [4, 16, 64])
    width: int = 256
    height: int = 256
    ref_spp: int = 1024
    methods: List[str] = field(default_factory=lambda: list(DEFAULT_METHODS))
    learned_weights: Optional[str] = None  # weight file of learned/auto (None: the built-in weights)
    runs: int = 5
    seed: int = 1
    ref_seed: int = 1000003
    resolutions: List[int] = field(default_factory=lambda: [128, 256, 512])
    equal_time: bool = True
    sequence: Optional[str] = None
    static_sequence: int = 0
    # cornell-point has no emitter in view: atrous.render returns no emission buffer, and without
    # one SVGF demodulates a visible light by its (zero) albedo and smears it over its neighbours.
    sequence_scene: str = "cornell-point"
    quick: bool = False


def quick_config(out: str = "eval-out") -> EvalConfig:
    return EvalConfig(out=out, scenes=list(QUICK_SCENES), spp=[4, 16], width=64, height=64,
                      ref_spp=256, runs=3, resolutions=[32, 64, 128], quick=True)


# ------------------------------------------------------------------------------------ methods

def oidn_inputs(b: Dict[str, np.ndarray]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(color, albedo, normal) as OIDN takes them: finite non-negative HDR colour, albedo in [0, 1],
    normals in [-1, 1], float32, C-contiguous."""
    color = np.ascontiguousarray(np.maximum(np.nan_to_num(b["color"], nan=0.0, posinf=0.0), 0.0), np.float32)
    albedo = np.ascontiguousarray(np.clip(np.nan_to_num(b["albedo"]), 0.0, 1.0), np.float32)
    normal = np.ascontiguousarray(np.clip(np.nan_to_num(b["normal"]), -1.0, 1.0), np.float32)
    return color, albedo, normal


def load_oidn() -> Tuple[Optional[Callable], str]:
    """The OIDN denoiser as f(bufs) -> image, or (None, why it is missing)."""
    try:
        import pyoidn  # noqa: F401  (bundles Intel Open Image Denoise)
    except Exception as e:  # ImportError, or a broken native library
        return None, f"pyoidn could not be imported ({type(e).__name__}: {e}); the OIDN column is skipped"

    def run(b: Dict[str, np.ndarray]) -> np.ndarray:
        # OIDN wants finite non-negative HDR colour, albedo in [0, 1] and normals in [-1, 1]; the
        # "RT" filter with both auxiliary images (they are noisy too, so cleanAux stays off).
        return pyoidn.denoise(*oidn_inputs(b), hdr=True, quality="high")

    version = getattr(getattr(pyoidn, "version", None), "__version__", None)
    return run, f"pyoidn {version or ''}".strip()


def _takes_emission() -> bool:
    import inspect

    try:
        return "emission" in inspect.signature(atrous.denoise).parameters
    except (TypeError, ValueError):
        return False


def _atrous_method(name: str, learned_weights: Optional[str] = None) -> Callable:
    # Sequences from `atrous render --frames` carry emission.exr; newer atrous.denoise filters
    # colour - emission and adds it back (no leak of visible lights), older ones have no keyword.
    extra_kw = ("emission",) if _takes_emission() else ()
    # The weight file is read once for every call (atrous.load_weights), not by each denoise().
    weights = atrous.load_weights(learned_weights) if learned_weights and name in atrous.WEIGHTED_METHODS else None

    def run(b: Dict[str, np.ndarray]) -> np.ndarray:
        # At 1 spp the renderer cannot estimate a variance and writes zeros; a zero variance
        # would tell the filters the input is clean, so they estimate the noise themselves.
        var = b.get("variance")
        if var is not None and not np.any(var > 0):
            var = None
        kw = {k: b[k] for k in extra_kw if b.get(k) is not None}
        if weights is not None:
            kw["learned_weights"] = weights
        return atrous.denoise(b["color"], albedo=b.get("albedo"), normal=b.get("normal"),
                              position=b.get("position"), depth=b.get("depth"),
                              variance=var, ids=b.get("ids"), method=name, **kw)
    return run


def build_methods(names: Sequence[str], notes: List[str],
                  learned_weights: Optional[str] = None) -> Dict[str, Optional[Callable]]:
    """name -> callable (None for "noisy"); unavailable methods are left out with a note.
    learned_weights: the weight file of learned/auto (None: the built-in weights)."""
    out: Dict[str, Optional[Callable]] = {}
    for name in names:
        if name == "noisy":
            out[name] = None
        elif name in atrous.METHODS:
            out[name] = _atrous_method(name, learned_weights)
        elif name == "oidn":
            fn, note = load_oidn()
            if fn is None:
                notes.append(note)
            else:
                out[name] = fn
        else:
            raise ValueError(f"--methods: unknown method '{name}' (expected {', '.join(all_methods())})")
    return out


def time_call(fn: Callable[[], Any], runs: int, warmup: int = 1) -> Tuple[Any, float, List[float]]:
    """Runs fn `warmup` times (at least once) to warm up (caches, thread pools, OIDN's lazy device),
    then `runs` times; returns (the last result, median ms, every run's ms)."""
    for _ in range(max(1, warmup)):
        result = fn()
    times = []
    for _ in range(max(1, runs)):
        t0 = time.perf_counter()
        result = fn()
        times.append((time.perf_counter() - t0) * 1e3)
    return result, float(np.median(times)), times


# ------------------------------------------------------------------------------------ metrics

def _flip():
    try:
        import flip_evaluator
        return flip_evaluator
    except Exception:
        return None


def score(image: np.ndarray, reference: np.ndarray, want_map: bool = False) -> Dict[str, Any]:
    """relMSE, PSNR, SSIM, MSE (atrous.metrics, docs/eval.md, "What is measured") and mean HDR-FLIP.

    FLIP's HDR mode needs non-negative finite input: negatives and NaN become 0 for FLIP only.
    With want_map, "flip_map" holds FLIP's magma-coloured error map (H x W x 3 in [0, 1]).
    """
    m = {k: float(v) for k, v in atrous.metrics(image, reference).items()}
    flip = _flip()
    if flip is None:
        m["flip"] = None
        return m
    ref = np.maximum(np.nan_to_num(reference, nan=0.0, posinf=0.0), 0.0).astype(np.float32)
    img = np.maximum(np.nan_to_num(image, nan=0.0, posinf=0.0), 0.0).astype(np.float32)
    err, mean, _ = flip.evaluate(ref, img, "HDR")
    m["flip"] = float(mean)
    if want_map:
        m["flip_map"] = np.asarray(err, np.float32)
    return m


def reference_floor(ref_bufs: Dict[str, np.ndarray]) -> float:
    """The relMSE the reference's own noise adds to every measurement: mean(var / (r^2 + 0.01)),
    with var the renderer's variance of the reference's mean (an estimate itself)."""
    r = ref_bufs["color"].astype(np.float64)
    v = np.maximum(ref_bufs["variance"].astype(np.float64), 0.0)
    return float(np.mean(v / (r * r + 0.01)))


# ------------------------------------------------------------------------------------ the run

class _Renders:
    """Renders by (scene, w, h, spp, seed), timed, computed once per run."""

    def __init__(self) -> None:
        self._cache: Dict[tuple, Tuple[Dict[str, np.ndarray], float]] = {}

    def get(self, scene: str, w: int, h: int, spp: int, seed: int) -> Tuple[Dict[str, np.ndarray], float]:
        key = (scene, w, h, spp, seed)
        if key not in self._cache:
            t0 = time.perf_counter()
            bufs = atrous.render(scene, width=w, height=h, spp=spp, seed=seed)
            self._cache[key] = (bufs, (time.perf_counter() - t0) * 1e3)
        return self._cache[key]


def _log(msg: str) -> None:
    print(f"[atrous-eval] {msg}", file=sys.stderr, flush=True)


def _environment(method_notes: List[str]) -> Dict[str, Any]:
    env = {
        "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "python": platform.python_version(),
        "machine": platform.machine(),
        "cpu_count": os.cpu_count(),
        "atrous": atrous.__version__,
        "numpy": np.__version__,
    }
    try:
        env["load_average"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        pass
    for mod in ("pyoidn", "flip_evaluator", "matplotlib"):
        try:
            from importlib.metadata import version
            env[mod] = version(mod.replace("_", "-"))
        except Exception:
            env[mod] = None
    return env


def run_eval(cfg: EvalConfig) -> Dict[str, Any]:
    """Runs the whole evaluation, writes OUT/results.json, the plots and OUT/report.html, and
    returns the results dict (the JSON plus the in-memory images under "_images")."""
    from . import report

    out = Path(cfg.out)
    out.mkdir(parents=True, exist_ok=True)
    notes: List[str] = []
    methods = build_methods(cfg.methods, notes, cfg.learned_weights)
    for s in cfg.spp:
        if cfg.ref_spp < 64 * s:
            notes.append(f"the reference ({cfg.ref_spp} spp) has only {cfg.ref_spp // s}x the samples of "
                         f"the {s}-spp input (a reference should have >= 64x the samples): its own noise, listed as "
                         "the reference floor, is part of every relMSE at that spp")
            break
    w, h = cfg.width, cfg.height
    renders = _Renders()
    results: List[Dict[str, Any]] = []
    references: Dict[str, Dict[str, Any]] = {}
    images: Dict[str, Dict[str, Any]] = {}
    equal_time: List[Dict[str, Any]] = []
    t_start = time.perf_counter()

    for scene in cfg.scenes:
        _log(f"{scene}: reference {w}x{h} at {cfg.ref_spp} spp")
        ref_bufs, ref_ms = renders.get(scene, w, h, cfg.ref_spp, cfg.ref_seed)
        ref = ref_bufs["color"]
        ms_per_spp = ref_ms / cfg.ref_spp
        references[scene] = {"spp": cfg.ref_spp, "seed": cfg.ref_seed, "render_ms": ref_ms,
                             "ms_per_spp": ms_per_spp, "floor_relmse": reference_floor(ref_bufs)}
        images[scene] = {"reference": ref, "spp": {}}
        for spp in cfg.spp:
            bufs, render_ms = renders.get(scene, w, h, spp, cfg.seed)
            per = {}
            for name, fn in methods.items():
                if fn is None:
                    img, ms, runs = bufs["color"], 0.0, []
                else:
                    img, ms, runs = time_call(lambda: fn(bufs), cfg.runs)
                m = score(img, ref, want_map=True)
                flip_map = m.pop("flip_map", None)
                per[name] = {"image": img, "flip_map": flip_map}
                results.append({"scene": scene, "spp": spp, "method": name, **m, "ms": ms,
                                "ms_runs": runs, "render_ms": render_ms})
                _log(f"{scene} {spp:>4} spp {name:>5}: relMSE {m['relmse']:.5f} PSNR {m['psnr']:.2f} "
                     f"SSIM {m['ssim']:.4f} FLIP {m['flip'] if m['flip'] is None else round(m['flip'], 4)} "
                     f"{ms:.1f} ms")
            images[scene]["spp"][spp] = per
        if cfg.equal_time:
            equal_time += _equal_time(cfg, scene, ref, ms_per_spp, results, renders)

    runtime = runtime_vs_resolution(cfg, methods, renders) if cfg.resolutions else []
    sequence = None
    if cfg.sequence or cfg.static_sequence:
        from . import sequence as seq
        seq_dir = cfg.sequence
        tmp_seq = None
        if not seq_dir:
            # Uncompressed 1-spp EXRs (~0.8 MB a buffer at 256x256): written to a temporary
            # directory and removed once evaluated.
            import tempfile
            tmp_seq = tempfile.TemporaryDirectory(prefix="atrous-static-seq-")
            seq_dir = tmp_seq.name
            _log(f"writing a {cfg.static_sequence}-frame static-camera sequence of {cfg.sequence_scene} to {seq_dir}")
            seq_ref = renders.get(cfg.sequence_scene, w, h, cfg.ref_spp, cfg.ref_seed)[0]["color"]
            seq.write_static_sequence(seq_dir, cfg.sequence_scene, cfg.static_sequence, w, h,
                                      ref_spp=cfg.ref_spp, seed=cfg.seed, reference=seq_ref)
        sequence = seq.evaluate_sequence(seq_dir, methods, log=_log)
        if tmp_seq is not None:
            tmp_seq.cleanup()
            sequence["dir"] = "(temporary static sequence)"
        if not cfg.sequence:
            sequence["note"] = (f"synthesised by --static-sequence: scene {cfg.sequence_scene}, static camera "
                                "(motion 0), each frame 1 spp with its own seed, one shared reference; SVGF's "
                                "easiest case, pure temporal accumulation. atrous.render has no emission "
                                "buffer (`atrous render --frames` has), so the scene has no emitter in view: "
                                "without emission SVGF's demodulation blows visible lights up.")
    else:
        notes.append("no frame sequence given (--sequence DIR, e.g. from `atrous render --frames F "
                     "--reference-spp N --out DIR`, or --static-sequence N): the SVGF column is left out")

    data = {
        "config": asdict(cfg),
        "environment": _environment(notes),
        "notes": notes,
        "methods": list(methods),
        "references": references,
        "results": results,
        "equal_time": equal_time,
        "runtime_vs_resolution": runtime,
        "sequence": sequence,
        "elapsed_s": time.perf_counter() - t_start,
    }
    data["summary"] = report.summarise(data)
    data["plots"] = report.write_plots(data, out)
    _write_json(out / "results.json", data)
    report.write_html(data, images, out / "report.html")
    (out / "results.md").write_text(report.markdown_table(data))
    _log(f"done in {data['elapsed_s']:.1f} s: {out / 'report.html'}")
    data["_images"] = images
    return data


def _equal_time(cfg: EvalConfig, scene: str, ref: np.ndarray, ms_per_spp: float,
                results: List[Dict[str, Any]], renders: _Renders) -> List[Dict[str, Any]]:
    """Denoised at N spp vs noisy at the spp that the same total time buys.

    The time of N spp is modelled as N x (reference render time / reference spp), measured on the
    long reference render where start-up costs vanish; the denoiser's median time then buys
    round(t_denoise / ms_per_spp) more samples, which are rendered (same seed) and measured.
    """
    rows = []
    w, h = cfg.width, cfg.height
    noisy = {r["spp"]: r["relmse"] for r in results if r["scene"] == scene and r["method"] == "noisy"}
    for r in [r for r in results if r["scene"] == scene and r["method"] != "noisy"]:
        n = r["spp"]
        extra = r["ms"] / ms_per_spp
        eq_spp = n + int(round(extra))
        eq_bufs = renders.get(scene, w, h, eq_spp, cfg.seed)[0]
        eq_relmse = atrous.metrics(eq_bufs["color"], ref)["relmse"]
        # Samples pure rendering would need to reach the denoised relMSE, if its error fell as
        # 1/spp from the noisy N-spp image (an extrapolation, labelled as such in the report).
        base = noisy.get(n)
        match_spp = base * n / r["relmse"] if base and r["relmse"] > 0 else None
        rows.append({"scene": scene, "spp": n, "method": r["method"], "denoise_ms": r["ms"],
                     "render_ms": n * ms_per_spp, "total_ms": n * ms_per_spp + r["ms"],
                     "extra_spp": extra, "equal_time_spp": eq_spp, "denoised_relmse": r["relmse"],
                     "noisy_equal_time_relmse": float(eq_relmse),
                     "advantage": float(eq_relmse) / r["relmse"] if r["relmse"] > 0 else None,
                     "noisy_spp_to_match_est": match_spp})
    return rows


def runtime_vs_resolution(cfg: EvalConfig, methods: Dict[str, Optional[Callable]],
                          renders: _Renders) -> List[Dict[str, Any]]:
    """Median denoise ms per method at square sizes cfg.resolutions (first scene, 4-spp input),
    with the render time of one sample per pixel at that size for scale."""
    rows = []
    scene = cfg.scenes[0]
    for size in cfg.resolutions:
        _log(f"runtime at {size}x{size}")
        spp = 4
        bufs, render_ms = renders.get(scene, size, size, spp, cfg.seed + 7)
        for name, fn in methods.items():
            if fn is None:
                continue
            _, ms, runs = time_call(lambda: fn(bufs), cfg.runs)
            rows.append({"method": name, "width": size, "height": size, "megapixels": size * size / 1e6,
                         "ms": ms, "ms_runs": runs})
        rows.append({"method": "render 1 spp", "width": size, "height": size,
                     "megapixels": size * size / 1e6, "ms": render_ms / spp, "ms_runs": []})
    return rows


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items() if not str(k).startswith("_")}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.ndarray):
        return None
    return x


def _write_json(path: Path, data: Dict[str, Any]) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(_jsonable(data), indent=1))
    tmp.replace(path)


# ------------------------------------------------------------------------------------ CLI
# The command line's parsing and checks: args.py (re-exported here).
from .args import UsageError, out_dir_problem, parse_args  # noqa: E402


def main(argv: Optional[Sequence[str]] = None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    try:
        cfg = parse_args(argv)
    except UsageError as e:
        print(f"atrous-eval: error: {e}", file=sys.stderr)
        return 2
    out = Path(cfg.out)
    existed = out.exists()
    try:
        run_eval(cfg)
    except (ValueError, RuntimeError, OSError) as e:
        print(f"atrous-eval: error: {e}", file=sys.stderr)
        if not existed and out.is_dir() and not any(out.iterdir()):
            out.rmdir()  # made by this run and still empty: leave nothing behind
        return 2
    return 0
