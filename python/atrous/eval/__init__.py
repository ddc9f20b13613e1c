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

__all__ = ["EvalConfig", "run_eval", "main", "load_oidn", "oidn_inputs", "time_call", "score"]



def all_methods() -> tuple:
    """What --methods may name: noisy, the library's still methods (as registered now), oidn."""
    return ("noisy",) + atrous.METHODS + ("oidn",)


# The default set (--methods not given). learned (the learned à-trous filter, docs/learned.md) and
# auto (learned with an albedo and a normal, which every render here has: the same as learned) are
# taken when asked for: --methods noisy,eaw,sure,learned,oidn.
DEFAULT_METHODS = ("noisy", "eaw", "sure", "oidn")
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

    def run(b: Dict[str, np.ndarray]) -> np.ndarray:
        # At 1 spp the renderer cannot estimate a variance and writes zeros; a zero variance
        # would tell the filters the input is clean, so they estimate the noise themselves.
        var = b.get("variance")
        if var is not None and not np.any(var > 0):
            var = None
        kw = {k: b[k] for k in extra_kw if b.get(k) is not None}
        if name in atrous.WEIGHTED_METHODS and learned_weights:
            kw["learned_weights"] = learned_weights
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

class UsageError(SystemExit):
    """Bad input on the command line, raised before anything is rendered or written; main()
    prints it as one line on stderr and returns exit status 2 (the project's CLI rule)."""

    def __init__(self, message: str):
        super().__init__(2)
        self.message = message

    def __str__(self) -> str:
        return self.message


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse's own errors (unknown flag, --runs abc): one line, 2
        raise UsageError(f"{message} (see --help)")


def _int_list(text: str, flag: str) -> List[int]:
    try:
        vals = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UsageError(f"{flag}: expected a comma list of integers, got '{text}'")
    if not vals or any(v <= 0 for v in vals):
        raise UsageError(f"{flag}: values must be positive, got '{text}'")
    return vals


def out_dir_problem(out) -> Optional[str]:
    """Why --out cannot be used as the output directory (it must be a writable directory or
    creatable as one), or None; nothing is created here. Also atrous.farm's check."""
    p = Path(out)
    if p.exists():
        if not p.is_dir():
            return f"--out '{out}': exists and is not a directory"
        if not os.access(p, os.W_OK | os.X_OK):
            return f"--out '{out}': directory is not writable"
        return None
    parent = p.absolute().parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        return f"--out '{out}': {parent} is not a directory"
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"--out '{out}': cannot create it ({parent} is not writable)"
    return None


def _check_out_dir(out: str) -> None:
    problem = out_dir_problem(out)
    if problem:
        raise UsageError(problem)


def _check_sequence(seq_dir: str) -> None:
    """The frame directories and their required buffers exist (pixels are read later)."""
    from . import sequence as seq

    try:
        frames = seq.list_frames(seq_dir)
    except ValueError as e:
        raise UsageError(f"--sequence: {e}")
    for f in frames:
        for name in seq.REQUIRED:
            if not (f / f"{name}.exr").is_file():
                raise UsageError(f"--sequence: {f / (name + '.exr')}: missing (every frame needs {name}.exr)")


def parse_args(argv: Optional[Sequence[str]] = None) -> EvalConfig:
    """The EvalConfig of a command line. Every argument is checked here, before any work: bad
    input raises UsageError (a SystemExit with status 2 after one line on stderr)."""
    p = _Parser(prog="atrous-eval", description=__doc__.split("\n\n")[0],
                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="eval-out", help="output directory (report.html, *.png, results.json)")
    p.add_argument("--quick", action="store_true",
                   help="CI size: scenes cornell,cornell-spheres, 64x64, spp 4,16, reference 256 spp, 3 runs")
    p.add_argument("--scenes", help="comma list of built-in scenes or scene .json files (default: all built-in)")
    p.add_argument("--spp", help="comma list of input samples per pixel (default 4,16,64)")
    p.add_argument("--size", help="image size, N or WxH (default 256)")
    p.add_argument("--ref-spp", type=int, help="samples per pixel of the references (default 1024)")
    p.add_argument("--methods", help=f"comma list from {','.join(all_methods())} "
                   f"(default: {','.join(DEFAULT_METHODS)})")
    p.add_argument("--learned-weights", metavar="FILE",
                   help="weight file of the learned filter for learned/auto (default: the built-in weights)")
    p.add_argument("--runs", type=int, help="timed runs per method, after a warm-up; the median is kept (default 5)")
    p.add_argument("--seed", type=int, help="seed of the noisy inputs, 0..2^32-1 (references use another)")
    p.add_argument("--resolutions", help="comma list of square sizes for runtime vs resolution (default 128,256,512; "
                   "'0' to skip)")
    p.add_argument("--no-equal-time", action="store_true", help="skip the equal-time renders")
    p.add_argument("--sequence", help="frame-sequence directory (frame_NNNN/color.exr ...) to add the SVGF column")
    p.add_argument("--static-sequence", type=int, default=0, metavar="N",
                   help="synthesise an N-frame static-camera sequence (1 spp frames) and evaluate it")
    p.add_argument("--sequence-scene", default="cornell-point",
                   help="scene of --static-sequence (default cornell-point: no emitter in view)")
    a = p.parse_args(argv)
    cfg = quick_config(a.out) if a.quick else EvalConfig(out=a.out)
    if a.scenes is not None:
        cfg.scenes = [s.strip() for s in a.scenes.split(",") if s.strip()]
        if not cfg.scenes:
            raise UsageError(f"--scenes: no scene in '{a.scenes}'")
    if a.spp is not None:
        cfg.spp = _int_list(a.spp, "--spp")
    if a.size is not None:
        try:
            parts = [int(v) for v in a.size.lower().split("x")]
            if len(parts) > 2:
                raise ValueError(a.size)
            cfg.width, cfg.height = (parts[0], parts[0]) if len(parts) == 1 else (parts[0], parts[1])
        except (ValueError, IndexError):
            raise UsageError(f"--size: expected N or WxH, got '{a.size}'")
        if cfg.width <= 0 or cfg.height <= 0:
            raise UsageError(f"--size: must be positive, got '{a.size}'")
    if a.ref_spp is not None:
        if a.ref_spp <= 0:
            raise UsageError(f"--ref-spp: must be positive, got {a.ref_spp}")
        cfg.ref_spp = a.ref_spp
    if a.methods is not None:
        cfg.methods = [m.strip() for m in a.methods.split(",") if m.strip()]
        bad = [m for m in cfg.methods if m not in all_methods()]
        if bad or not cfg.methods:
            raise UsageError(f"--methods: unknown {', '.join(bad) or repr(a.methods)} "
                             f"(expected {', '.join(all_methods())})")
    if a.learned_weights is not None:
        if not os.path.isfile(a.learned_weights):
            raise UsageError(f"--learned-weights: '{a.learned_weights}' is not a file")
        cfg.learned_weights = a.learned_weights
    if a.runs is not None:
        if a.runs < 1:
            raise UsageError(f"--runs: must be at least 1, got {a.runs}")
        cfg.runs = a.runs
    if a.seed is not None:
        if not 0 <= a.seed < 2 ** 32:
            raise UsageError(f"--seed: must be in 0..{2 ** 32 - 1}, got {a.seed}")
        cfg.seed = a.seed
    if a.resolutions is not None:
        cfg.resolutions = [] if a.resolutions.strip() == "0" else _int_list(a.resolutions, "--resolutions")
    cfg.equal_time = not a.no_equal_time
    if a.static_sequence < 0:
        raise UsageError(f"--static-sequence: must be 0 or more, got {a.static_sequence}")
    cfg.sequence = a.sequence
    cfg.static_sequence = a.static_sequence
    cfg.sequence_scene = a.sequence_scene
    if cfg.static_sequence and cfg.sequence:
        raise UsageError("give --sequence or --static-sequence, not both")
    known = set(atrous.builtin_scenes())
    for s in cfg.scenes:
        if s not in known and not Path(s).is_file():
            raise UsageError(f"--scenes: '{s}' is neither a built-in scene ({', '.join(sorted(known))}) nor a scene file")
    if cfg.static_sequence and cfg.sequence_scene not in known and not Path(cfg.sequence_scene).is_file():
        raise UsageError(f"--sequence-scene: '{cfg.sequence_scene}' is neither a built-in scene "
                         f"({', '.join(sorted(known))}) nor a scene file")
    if cfg.sequence is not None:
        _check_sequence(cfg.sequence)
    _check_out_dir(cfg.out)
    return cfg


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
