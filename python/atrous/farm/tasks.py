"""What one Ray task runs: one item, in a worker process on any node of the cluster.

Every item writes into its own staging directory, OUT/.partial/<item>.<pid>.<random>/, and moves
its outputs into place with rename(2) only when all of them are written: a worker killed half-way
leaves a stray staging directory (removed when the job ends), never a half-written output. A
failure on bad input (the library's ValueError: a malformed scene file, a missing buffer) comes
back as a "failed" result with its message; Ray retries only a task whose worker process died.
"""
from __future__ import annotations

import json
import os
import shutil
import socket
import time
import uuid
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Dict, Iterator, List, Optional, Tuple

import numpy as np

import atrous

from ..plugins import load_plugins

BUFFERS = ("color", "variance", "albedo", "normal", "position", "depth", "ids", "emission")
PARTIAL = ".partial"
REFERENCE_SEED_OFFSET = 0x9E3779B9  # `atrous render --frames --reference-spp`: references use seed + this


def safe_name(item_id: str) -> str:
    return item_id.replace("/", "__")


@contextmanager
def staged(out_root: Path, item_id: str) -> Iterator[Path]:
    stage = out_root / PARTIAL / f"{safe_name(item_id)}.{os.getpid()}.{uuid.uuid4().hex[:8]}"
    stage.mkdir(parents=True)
    try:
        yield stage
    finally:
        shutil.rmtree(stage, ignore_errors=True)  # published (renamed away) or failed


def publish_dir(stage: Path, final: Path) -> None:
    """Moves the staged directory to `final`, replacing an earlier one whole."""
    final.parent.mkdir(parents=True, exist_ok=True)
    if final.exists():
        old = stage.with_name(stage.name + ".old")
        os.rename(final, old)
        os.rename(stage, final)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.rename(stage, final)


def publish_files(stage: Path, final_dir: Path, names: List[str]) -> None:
    """Moves staged files into `final_dir` one by one (each rename replaces its file atomically)."""
    final_dir.mkdir(parents=True, exist_ok=True)
    for n in names:
        os.replace(stage / n, final_dir / n)


def write_buffers(d: Path, bufs: Dict[str, np.ndarray], with_variance: bool = True) -> None:
    """The files of `atrous render --out DIR` (apps/atrous/cmd_render.cpp, writeBuffers)."""
    for name in BUFFERS:
        if name == "variance" and not with_variance:
            continue
        if name in bufs and bufs[name].size:
            atrous.write_image(d / f"{name}.exr", bufs[name])
    if "motion" in bufs:
        atrous.write_image(d / "motion.exr", bufs["motion"])
    atrous.write_image(d / "color.png", bufs["color"])


def read_buffers(d: Path) -> Dict[str, np.ndarray]:
    if not (d / "color.exr").is_file():
        raise ValueError(f"{d / 'color.exr'}: missing")
    bufs = {}
    for name in BUFFERS:
        p = d / f"{name}.exr"
        if p.is_file():
            bufs[name] = atrous.read_image(p)
            if bufs[name].shape != bufs["color"].shape:
                raise ValueError(f"{p}: is {bufs[name].shape[1]}x{bufs[name].shape[0]} but color.exr is "
                                 f"{bufs['color'].shape[1]}x{bufs['color'].shape[0]}")
    return bufs


def denoise_buffers(bufs: Dict[str, np.ndarray], method: str, params: Dict[str, Any], device: str) -> np.ndarray:
    if method == "oidn":
        from atrous.eval import load_oidn

        fn, note = load_oidn()
        if fn is None:
            raise RuntimeError(note)
        return fn(bufs)
    # At 1 spp the renderer cannot estimate a variance and writes zeros: a zero variance would
    # tell the filter the input is clean, so it estimates the noise itself (as atrous.eval does).
    var = bufs.get("variance")
    if var is not None and not np.any(var > 0):
        var = None
    return atrous.denoise(bufs["color"], albedo=bufs.get("albedo"), normal=bufs.get("normal"),
                          position=bufs.get("position"), depth=bufs.get("depth"), variance=var,
                          ids=bufs.get("ids"), emission=bufs.get("emission"), method=method,
                          device=device, **params)


def _render(p: Dict[str, Any], threads: int, spp: Optional[int] = None, seed: Optional[int] = None,
            scene: Optional[str] = None) -> Dict[str, np.ndarray]:
    return atrous.render(scene or p["scene"], width=p["width"], height=p["height"], spp=spp or p["spp"],
                         seed=p["seed"] if seed is None else seed, max_depth=p["max_depth"], threads=threads)


# ------------------------------------------------------------------------------------ kinds

def run_render(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """`atrous render --scene S --spp N --seed K [--denoise M,...] --out OUT/<id>`."""
    p = item["params"]
    bufs = _render(p, threads)
    with staged(out, item["id"]) as stage:
        write_buffers(stage, bufs)
        for m in p.get("denoise", []):
            img = denoise_buffers(bufs, m, {}, device)
            atrous.write_image(stage / f"denoised_{m}.exr", img)
            atrous.write_image(stage / f"denoised_{m}.png", img)
        publish_dir(stage, out / item["outputs"][0])
    return {}


def run_frame(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """Frame f of `atrous render --frames F [--reference-spp R] --out OUT/<sequence>`: the same
    time, seed (seed + f) and files as the CLI's frame_NNNN/."""
    from atrous import _core

    p = item["params"]
    f, frames, seed = p["frame"], p["frames"], p["seed"]
    args = (p["scene"], f, frames, p["camera_path"])

    def settings(spp: int, seed: int) -> Dict[str, Any]:  # the render table's keywords
        return {"width": p["width"], "height": p["height"], "spp": spp, "seed": seed,
                "max_depth": p["max_depth"], "threads": threads}

    bufs = dict(_core.render_frame(*args, settings(p["spp"], seed)))
    bufs.pop("time", None)
    with staged(out, item["id"]) as stage:
        write_buffers(stage, bufs, with_variance=p["spp"] > 1)
        if p.get("reference_spp"):
            # The CLI renders every frame's reference with one seed, seed + 0x9E3779B9;
            # render_frame adds the frame number to the seed it is given.
            ref_seed = (seed + REFERENCE_SEED_OFFSET - f) % 2 ** 32
            ref = _core.render_frame(*args, settings(p["reference_spp"], ref_seed))["color"]
            atrous.write_image(stage / "reference.exr", ref)
        publish_dir(stage, out / item["outputs"][0])
    return {}


def oidn_target(bufs: Dict[str, np.ndarray]) -> Tuple[np.ndarray, str]:
    """OIDN at quality high on a render, as atrous.eval runs it (load_oidn): a training target
    (docs/farm.md, "Training targets"), and which pyoidn made it."""
    from atrous.eval import load_oidn

    run, version = load_oidn()
    if run is None:
        raise RuntimeError(f"target 'oidn': {version}")
    return np.asarray(run(bufs), np.float32), version


def run_dataset(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """One scene of a training set: scene.json, spp_<N>/ per input spp (the `atrous render --out`
    layout) and reference.exr (reference_spp samples, another seed), or target.exr (OIDN high on a
    target_spp render, a third seed) with target.json and that render's colour (target_input.exr),
    and reference.exr where params["reference"]."""
    p = item["params"]
    with staged(out, item["id"]) as stage:
        scene = stage / "scene.json"
        scene.write_text(json.dumps(p["scene"], indent=1))
        for spp in p["spp"]:
            d = stage / f"spp_{spp}"
            d.mkdir()
            write_buffers(d, _render(p, threads, spp=spp, scene=str(scene)))
        if p.get("target") == "oidn":
            raw = _render(p, threads, spp=p["target_spp"], seed=p["target_seed"], scene=str(scene))
            img, version = oidn_target(raw)
            atrous.write_image(stage / "target.exr", img)
            # The render OIDN denoised: unbiased where OIDN's output may not be (an energy term's anchor).
            atrous.write_image(stage / "target_input.exr", raw["color"])
            (stage / "target.json").write_text(json.dumps({"kind": "oidn-high", "spp": p["target_spp"],
                                                           "seed": p["target_seed"], "pyoidn": version}))
        if p.get("reference", True):
            ref = _render(p, threads, spp=p["reference_spp"], seed=p["reference_seed"], scene=str(scene))
            atrous.write_image(stage / "reference.exr", ref["color"])
        # The scene file names no other file, so it is as valid in its final place.
        publish_dir(stage, out / item["outputs"][0])
    return {}


def run_denoise(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """A render directory -> OUT/<name>/denoised_<method>.exr/.png; a sequence frame ->
    OUT/<sequence>/frame_NNNN.exr/.png (the names `atrous denoise --sequence` writes)."""
    p = item["params"]
    bufs = read_buffers(Path(p["input"]))
    t0 = time.perf_counter()
    img = denoise_buffers(bufs, p["method"], p["params"], device)
    ms = (time.perf_counter() - t0) * 1e3
    return publish_denoised(item, out, img, Path(p["input"]) / "reference.exr", {"denoise_ms": ms})


def publish_denoised(item: Dict[str, Any], out: Path, img: np.ndarray, ref: Path,
                     result: Dict[str, Any]) -> Dict[str, Any]:
    """Writes `img` under each of the item's output names (.exr, .png) and publishes them; adds the
    MSE against `ref` to `result` when that reference exists."""
    names = [Path(o).name for o in item["outputs"]]
    with staged(out, item["id"]) as stage:
        for n in names:
            atrous.write_image(stage / n, img)
        publish_files(stage, out / Path(item["outputs"][0]).parent, names)
    if ref.is_file():
        result["mse_vs_reference"] = atrous.metrics(img, atrous.read_image(ref))["mse"]
    return result


def run_sequence(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """A whole sequence through a sequence method with history (svgf: each frame needs the ones
    before), one stream in order: OUT/<sequence>/frame_NNNN.exr/.png."""
    from atrous.eval.sequence import load_frame

    from .items import split_sequence_params

    p = item["params"]
    own, spatial, still = split_sequence_params(p["method"], p["params"])
    s = atrous.SequenceDenoiser(p["method"], device="cuda" if device == "cuda" else "cpu", spatial=spatial,
                                params=own, **still)
    pending = list(p["frames"])  # pushed, not yet out: the next to come out first
    with staged(out, item["id"]) as stage:
        def drain() -> None:
            while s.ready:
                img = s.next()
                name = pending.pop(0)
                atrous.write_image(stage / f"{name}.exr", img)
                atrous.write_image(stage / f"{name}.png", img)

        for name in p["frames"]:
            s.push({k: v for k, v in load_frame(Path(p["input"]) / name).items() if k != "reference"})
            drain()
        s.finish()
        drain()
        publish_dir(stage, out / item["outputs"][0])
    return {"frames": len(p["frames"])}


def run_window(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """One frame of a sequence through a sequence method without history (temporal), with the
    frames around it that it reads: OUT/<sequence>/frame_NNNN.exr/.png (what `atrous denoise
    --sequence` writes for it)."""
    from atrous.eval.sequence import load_frame, sequence_window

    from .items import split_sequence_params

    p = item["params"]
    method = p["method"]
    own, spatial, still = split_sequence_params(method, p["params"])
    i, names = int(p["index"]), p["frames"]
    # The static window needs the renderer's vectors (docs/temporal.md).
    motion = (Path(p["input"]) / names[i] / "motion.exr").exists()
    lo, hi = sequence_window(len(names), i, method, motion_given=motion, params=own, spatial=spatial, **still)
    frames = [{k: v for k, v in load_frame(Path(p["input"]) / n).items() if k != "reference"} for n in names[lo:hi + 1]]
    t0 = time.perf_counter()
    img = atrous.denoise_window(method, frames, i - lo, device=device, spatial=spatial, params=own, **still)
    ms = (time.perf_counter() - t0) * 1e3
    return publish_denoised(item, out, img, Path(p["input"]) / names[i] / "reference.exr",
                            {"denoise_ms": ms, "frames_read": hi - lo + 1})


def run_reference(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """A scene's reference for evaluate/sweep: reference.exr and its variance (the noise floor)."""
    from atrous.eval import reference_floor

    p = item["params"]
    t0 = time.perf_counter()
    bufs = _render(p, threads)
    ms = (time.perf_counter() - t0) * 1e3
    with staged(out, item["id"]) as stage:
        atrous.write_image(stage / "reference.exr", bufs["color"])
        atrous.write_image(stage / "variance.exr", bufs["variance"])
        publish_dir(stage, out / item["outputs"][0])
    return {"spp": p["spp"], "seed": p["seed"], "render_ms": ms, "ms_per_spp": ms / p["spp"],
            "floor_relmse": reference_floor(bufs)}


def run_score(item: Dict[str, Any], out: Path, threads: int, device: str) -> Dict[str, Any]:
    """evaluate (one method) and sweep (one parameter point): render the noisy input, denoise it
    (timed: median of `runs` runs after a warm-up), score it against the scene's reference."""
    from atrous.eval import score, time_call

    p = item["params"]
    ref_path = out / p["reference"] / "reference.exr"
    if not ref_path.is_file():
        raise RuntimeError(f"{ref_path}: the reference is missing")
    ref = atrous.read_image(ref_path)
    t0 = time.perf_counter()
    bufs = _render(p, threads)
    render_ms = (time.perf_counter() - t0) * 1e3
    if p["method"] == "noisy":
        img, ms, runs = bufs["color"], 0.0, []
    else:
        img, ms, runs = time_call(lambda: denoise_buffers(bufs, p["method"], p.get("params", {}), device),
                                  p.get("runs", 1))
    m = score(img, ref)
    row = {"scene": p["label"], "spp": p["spp"], "method": p["method"], **m, "ms": ms, "ms_runs": runs,
           "render_ms": render_ms}
    if "params" in p:
        row["params"] = p["params"]
    with staged(out, item["id"]) as stage:
        atrous.write_image(stage / "denoised.exr", img)
        atrous.write_image(stage / "denoised.png", img)
        (stage / "metrics.json").write_text(json.dumps(row, indent=1))
        publish_dir(stage, out / item["outputs"][0])
    return row


RUNNERS = {"render": run_render, "frame": run_frame, "dataset": run_dataset, "denoise": run_denoise,
           "sequence": run_sequence, "window": run_window, "reference": run_reference, "evaluate": run_score, "sweep": run_score}


def run_item(item: Dict[str, Any], out_root: str, threads: int, device: str, tracker: Any = None,
             *deps: Any) -> Dict[str, Any]:
    """The Ray task. `deps` are the results of the items this one needs (Ray runs it after them)."""
    node, node_id = socket.gethostname(), None
    try:
        import ray

        node = ray.util.get_node_ip_address()
        node_id = ray.get_runtime_context().get_node_id()
    except Exception:
        pass
    if tracker is not None:
        # Waited for (a round trip of a millisecond or two), so that a worker killed right after
        # still counts as an attempt in the manifest.
        try:
            ray.get(tracker.started.remote(item["id"], os.getpid(), node), timeout=10)
        except Exception:  # the progress display and the count are best effort; the item is not
            pass
    from .manifest import utc_now

    t0 = time.perf_counter()
    res: Dict[str, Any] = {"status": "done", "error": None, "error_kind": None, "result": None,
                           "node": node, "node_id": node_id, "pid": os.getpid(),
                           "started_utc": utc_now()}
    failed_dep = next((d for d in deps if isinstance(d, dict) and d.get("status") != "done"), None)
    try:
        if failed_dep is not None:  # failed as its dependency did (bad input there is bad input here)
            res.update(status="failed", error=f"needs {failed_dep.get('id')}, which failed: {failed_dep.get('error')}",
                       error_kind=failed_dep.get("error_kind") or "runtime")
        else:
            load_plugins(item["params"].get("plugins") or [])  # the methods a plugin registers
            res["result"] = RUNNERS[item["kind"]](item, Path(out_root), threads, device)
    except ValueError as e:  # bad input: the library's InputError, a missing buffer
        res.update(status="failed", error=str(e), error_kind="input")
    except (RuntimeError, OSError) as e:
        res.update(status="failed", error=f"{type(e).__name__}: {e}", error_kind="runtime")
    res["seconds"] = time.perf_counter() - t0
    res["id"] = item["id"]
    return res
