"""The four jobs as Python functions: each checks its arguments (FarmInputError before anything is
written), plans its items and runs them with runner.run_job. The CLI (cli.py) calls these."""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Union

import atrous

from . import dataset as _dataset
from .items import (EVAL_METHODS, FarmInputError, Item, check_denoise_params, check_scenes, denoise_choices, sequence_row,
                    discover_inputs, eval_choices, grid_points, int_list, name_list, params_label, positive_int, scene_label)
from .manifest import Manifest
from ..plugins import PluginError, load_plugins, resolve_plugins
from .runner import JobResult, run_job

PathLike = Union[str, "os.PathLike[str]"]
_SEED_MAX = 2 ** 32 - 1
CAMERA_PATHS = ("auto", "static", "orbit", "dolly", "keyframes")


def _size(width: Any, height: Any) -> Dict[str, int]:
    return {"width": positive_int(width, "width", 1, 16384), "height": positive_int(height, "height", 1, 16384)}


def render(out: PathLike, scenes: Any, spp: Any = (16,), *, width: int = 512, height: int = 512,
           seeds: Any = (1,), max_depth: int = 8, denoise: Any = (), frames: int = 0,
           camera_path: str = "auto", reference_spp: int = 0, **run: Any) -> JobResult:
    """scenes x spp x seeds (x frames) through `atrous render`: one item per still image, in
    OUT/<scene>_spp<N>[_seed<K>]/ (the files of `atrous render --out`), or per frame with frames > 0,
    in OUT/<scene>_spp<N>[_seed<K>]/frame_NNNN/ (those of `atrous render --frames`)."""
    scenes = check_scenes(scenes)
    spp = int_list(spp, "spp", 1, 1 << 20)
    seeds = int_list(seeds, "seeds", 0, _SEED_MAX)
    size = _size(width, height)
    max_depth = positive_int(max_depth, "max_depth", 1, 1000)
    frames = positive_int(frames, "frames", 0, 100000)
    methods = name_list(denoise, "denoise") if denoise else []
    for m in methods:
        if m not in atrous.METHODS:
            raise FarmInputError(f"denoise: unknown method '{m}' (expected {', '.join(atrous.METHODS)})")
    if frames and methods:
        raise FarmInputError("denoise: not with frames (denoise the sequence with the denoise job)")
    if camera_path not in CAMERA_PATHS:
        raise FarmInputError(f"camera_path: unknown '{camera_path}' (expected {', '.join(CAMERA_PATHS)})")
    reference_spp = positive_int(reference_spp, "reference_spp", 0, 1 << 20)
    if not frames and (reference_spp or camera_path != "auto"):
        raise FarmInputError("reference_spp and camera_path: only with frames")
    items: List[Item] = []
    for scene in scenes:
        for n in spp:
            for seed in seeds:
                base = f"{scene_label(scene)}_spp{n}" + (f"_seed{seed}" if len(seeds) > 1 else "")
                p = {"scene": scene, **size, "spp": n, "seed": seed, "max_depth": max_depth}
                if not frames:
                    items.append(Item(base, "render", dict(p, denoise=methods), [base]))
                for f in range(frames):
                    fid = f"{base}/frame_{f:04d}"
                    items.append(Item(fid, "frame", dict(p, frame=f, frames=frames, camera_path=camera_path,
                                                         reference_spp=reference_spp), [fid]))
    spec = {"scenes": scenes, "spp": spp, "seeds": seeds, **size, "max_depth": max_depth, "denoise": methods,
            "frames": frames, "camera_path": camera_path, "reference_spp": reference_spp}
    return run_job("render", spec, items, Path(out), **run)


def render_dataset(out: PathLike, spec: Union[Dict[str, Any], PathLike], **run: Any) -> JobResult:
    """A training set of spec["count"] randomised scenes (dataset.py): OUT/scene_NNNNNN/ with
    scene.json, spp_<N>/ per input spp and reference.exr, or target.exr + target.json (an OIDN-high
    denoise of a target_spp render) with reference.exr for every reference_every-th scene."""
    s = _dataset.check_spec(spec) if isinstance(spec, dict) else _dataset.load_spec(spec)
    ref_seed = (s["seed"] * 7919 + 1000003) % (_SEED_MAX + 1)  # never an input's seed stream
    items = []
    for i in range(s["count"]):
        iid = f"scene_{i:06d}"
        p = {"scene": _dataset.random_scene(s["seed"], i), "index": i, "width": s["width"], "height": s["height"],
             "spp": s["spp"], "seed": (s["seed"] + i) % (_SEED_MAX + 1), "reference_spp": s["reference_spp"],
             "reference_seed": (ref_seed + i) % (_SEED_MAX + 1), "max_depth": s["max_depth"],
             "target": s["target"], "reference": s["target"] == "reference" or
             (s["reference_every"] > 0 and i % s["reference_every"] == 0)}
        if s["target"] == "oidn":  # a third seed stream, neither an input's nor a reference's
            p.update(target_spp=s["target_spp"], target_seed=(ref_seed + 0x5BD1E995 + i) % (_SEED_MAX + 1))
        items.append(Item(iid, "dataset", p, [iid]))
    return run_job("render", {"dataset": s}, items, Path(out), **run)


def denoise(out: PathLike, inputs: Any, method: Optional[str] = None, params: Optional[Dict[str, Any]] = None,
            plugins: Any = None, **run: Any) -> JobResult:
    """Render directories and frame sequences through one method: OUT/<name>/denoised_<method>.exr
    and .png per render directory, OUT/<sequence>/frame_NNNN.exr and .png per frame (a sequence
    method with history, svgf: one item per sequence, its frames in order; one without, temporal:
    one item per frame, which reads the frames around it: params <table>_<name> are its own,
    spatial=METHOD its still method; farm/items.py split_sequence_params). plugins: shared
    libraries, Python files or modules that register methods (atrous.load_plugin,
    atrous.register_method), loaded here and in every worker (atrous/plugins.py)."""
    try:
        plugins = resolve_plugins(plugins)
        load_plugins(plugins)
    except PluginError as e:
        raise FarmInputError(str(e)) from None
    method = method or atrous.names.DEFAULT  # the library's default still method
    if method not in denoise_choices():
        raise FarmInputError(f"method: unknown '{method}' (expected {', '.join(denoise_choices())})")
    params = dict(params or {})
    check_denoise_params(method, params, "params")
    found = discover_inputs([str(p) for p in ([inputs] if isinstance(inputs, (str, os.PathLike)) else inputs)],
                            "inputs")
    items = []
    for f in found:
        base = {"method": method, "params": params, **({"plugins": plugins} if plugins else {})}
        row = sequence_row(method)
        if row is not None and f["kind"] != "sequence":
            raise FarmInputError(f"inputs: {f['path']}: {method} denoises frame sequences (frame_NNNN/), "
                                 "this is a single render")
        if row is not None and row["history"]:  # one item per sequence, its frames in order
            items.append(Item(f["name"], "sequence", dict(base, input=f["path"], frames=f["frames"]), [f["name"]]))
        elif row is not None:  # one item per frame, each reading the frames around it
            for i, fr in enumerate(f["frames"]):
                iid = f"{f['name']}/{fr}"
                items.append(Item(iid, "window", dict(base, input=f["path"], frames=f["frames"], index=i),
                                  [iid + ".exr", iid + ".png"]))
        elif f["kind"] == "render":
            iid = f"{f['name']}/denoised_{method}"
            items.append(Item(iid, "denoise", dict(base, input=f["path"]), [iid + ".exr", iid + ".png"]))
        else:
            for fr in f["frames"]:
                iid = f"{f['name']}/{fr}"
                items.append(Item(iid, "denoise", dict(base, input=str(Path(f["path"]) / fr)),
                                  [iid + ".exr", iid + ".png"]))
    spec = {"inputs": [f["path"] for f in found], "method": method, "params": params,
            **({"plugins": plugins} if plugins else {})}
    return run_job("denoise", spec, items, Path(out), **run)


def _references(scenes: List[str], size: Dict[str, int], ref_spp: int, ref_seed: int, max_depth: int) -> List[Item]:
    return [Item(f"references/{scene_label(s)}", "reference",
                 {"scene": s, **size, "spp": ref_spp, "seed": ref_seed, "max_depth": max_depth},
                 [f"references/{scene_label(s)}"]) for s in scenes]


def _scored(kind: str, scenes, spp, size, seed, max_depth, method, points, runs) -> List[Item]:
    items = []
    for s in scenes:
        lab = scene_label(s)
        for n in spp:
            for point in points:
                tail = point if isinstance(point, str) else params_label(point)
                iid = f"{lab}/spp{n}/{tail}"
                p = {"scene": s, "label": lab, **size, "spp": n, "seed": seed, "max_depth": max_depth,
                     "method": point if isinstance(point, str) else method, "runs": runs,
                     "reference": f"references/{lab}"}
                if not isinstance(point, str):
                    p["params"] = point
                items.append(Item(iid, kind, p, [iid], deps=[f"references/{lab}"]))
    return items


def _write_results(man: Manifest, extra: Any) -> None:
    """OUT/results.json (the rows of atrous.eval's results.json, one per finished item, plus the
    references) and OUT/results.md (a table)."""
    rows, refs, failed = [], {}, []
    for e in man.entries.values():
        if e["status"] != "done":
            failed.append({"id": e["id"], "error": e.get("error")})
        elif e["kind"] == "reference":
            refs[e["id"].split("/", 1)[1]] = e["result"]
        elif e.get("result"):
            rows.append(e["result"])
    data = {"job": man.data["job"], "config": man.data["spec"], "references": refs, "results": rows,
            "failed": failed}
    data.update(extra(rows) if callable(extra) else extra)
    tmp = man.out / ".results.json.tmp"
    tmp.write_text(json.dumps(data, indent=1, default=lambda x: None))
    os.replace(tmp, man.out / "results.json")
    cols = ["scene", "spp", "method"] + (["params"] if any("params" in r for r in rows) else []) + \
           ["relmse", "psnr", "ssim", "flip", "ms"]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in sorted(rows, key=lambda r: (r["scene"], r["spp"], r.get("relmse") or 0)):
        vals = []
        for c in cols:
            v = r.get(c)
            vals.append(params_label(v) if c == "params" else f"{v:.5g}" if isinstance(v, float) else str(v))
        lines.append("| " + " | ".join(vals) + " |")
    tmp = man.out / ".results.md.tmp"
    tmp.write_text("\n".join(lines) + "\n")
    os.replace(tmp, man.out / "results.md")


def _common_eval(scenes, spp, width, height, ref_spp, seed, max_depth):
    scenes = check_scenes(scenes)
    spp = int_list(spp, "spp", 1, 1 << 20)
    size = _size(width, height)
    ref_spp = positive_int(ref_spp, "ref_spp", 1, 1 << 20)
    seed = positive_int(seed, "seed", 0, _SEED_MAX)
    max_depth = positive_int(max_depth, "max_depth", 1, 1000)
    return scenes, spp, size, ref_spp, seed, max_depth


def evaluate(out: PathLike, scenes: Any = ("cornell", "cornell-spheres"), spp: Any = (4, 16),
             methods: Any = EVAL_METHODS, *, width: int = 64, height: int = 64, ref_spp: int = 256,
             seed: int = 1, ref_seed: int = 1000003, runs: int = 3, max_depth: int = 8, **run: Any) -> JobResult:
    """The quality benchmark (atrous.eval's measurements) as methods x scenes x spp items after one
    reference item per scene: OUT/references/<scene>/, OUT/<scene>/spp<N>/<method>/ (denoised.exr,
    .png, metrics.json), OUT/results.json and results.md. Denoise times are medians of `runs` runs,
    measured while other items share the machine (atrous.eval's timings are the clean ones)."""
    scenes, spp, size, ref_spp, seed, max_depth = _common_eval(scenes, spp, width, height, ref_spp, seed, max_depth)
    ref_seed = positive_int(ref_seed, "ref_seed", 0, _SEED_MAX)
    if ref_seed == seed:
        raise FarmInputError("ref_seed: must differ from seed (the reference would share the input's noise)")
    methods = name_list(methods, "methods")
    for m in methods:
        if m not in eval_choices():
            raise FarmInputError(f"methods: unknown '{m}' (expected {', '.join(eval_choices())})")
    runs = positive_int(runs, "runs", 1, 1000)
    items = _references(scenes, size, ref_spp, ref_seed, max_depth)
    items += _scored("evaluate", scenes, spp, size, seed, max_depth, None, methods, runs)
    spec = {"scenes": scenes, "spp": spp, "methods": methods, **size, "ref_spp": ref_spp, "seed": seed,
            "ref_seed": ref_seed, "runs": runs, "max_depth": max_depth}
    return run_job("evaluate", spec, items, Path(out), finalize=lambda m: _write_results(m, {}), **run)


def _best(rows: List[Dict[str, Any]]) -> Dict[str, Any]:
    """The lowest relMSE per scene x spp, and the point with the lowest mean relMSE over all of them."""
    per: Dict[str, Any] = {}
    by_point: Dict[str, List[float]] = {}
    point_of: Dict[str, Any] = {}
    for r in rows:
        key = f"{r['scene']}/spp{r['spp']}"
        if key not in per or r["relmse"] < per[key]["relmse"]:
            per[key] = {"params": r.get("params"), "relmse": r["relmse"], "psnr": r.get("psnr")}
        lab = params_label(r.get("params") or {})
        by_point.setdefault(lab, []).append(r["relmse"])
        point_of[lab] = r.get("params")
    cells = len({(r["scene"], r["spp"]) for r in rows})
    full = {k: sum(v) / len(v) for k, v in by_point.items() if len(v) == cells}
    overall = min(full, key=full.get) if full else None
    return {"best": per, "best_overall": None if overall is None else {"params": point_of[overall],
                                                                       "mean_relmse": full[overall]}}


def sweep(out: PathLike, method: str, grid: Dict[str, Sequence[Any]], scenes: Any = ("cornell",),
          spp: Any = (4,), *, width: int = 64, height: int = 64, ref_spp: int = 256, seed: int = 1,
          ref_seed: int = 1000003, max_depth: int = 8, **run: Any) -> JobResult:
    """A parameter grid of eaw or sure scored against references: one item per scene x spp x grid
    point, OUT/<scene>/spp<N>/<name=value,...>/, and OUT/results.json with the best point per
    scene x spp and overall (lowest mean relMSE)."""
    if method not in atrous.METHODS:
        raise FarmInputError(f"method: unknown '{method}' (expected {', '.join(atrous.METHODS)})")
    if not isinstance(grid, dict) or not grid:
        raise FarmInputError("grid: give at least one parameter with its values (NAME=V1,V2,...)")
    grid = {k.replace("-", "_"): list(v) if isinstance(v, (list, tuple)) else [v] for k, v in grid.items()}
    points = grid_points(grid)
    if len(points) > 100000:
        raise FarmInputError(f"grid: {len(points)} points is more than 100000")
    for pt in points:
        check_denoise_params(method, pt, "grid")
    scenes, spp, size, ref_spp, seed, max_depth = _common_eval(scenes, spp, width, height, ref_spp, seed, max_depth)
    ref_seed = positive_int(ref_seed, "ref_seed", 0, _SEED_MAX)
    if ref_seed == seed:
        raise FarmInputError("ref_seed: must differ from seed (the reference would share the input's noise)")
    items = _references(scenes, size, ref_spp, ref_seed, max_depth)
    items += _scored("sweep", scenes, spp, size, seed, max_depth, method, points, 1)
    spec = {"method": method, "grid": grid, "scenes": scenes, "spp": spp, **size, "ref_spp": ref_spp,
            "seed": seed, "ref_seed": ref_seed, "max_depth": max_depth}
    return run_job("sweep", spec, items, Path(out), finalize=lambda m: _write_results(m, _best), **run)
