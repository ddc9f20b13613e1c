"""The learned filter's speed against EAW, SURE and Intel Open Image Denoise, in one run.

    .venv/bin/python -m atrous.eval speed --atrous build/atrous            # 512x512 and 1920x1080
    .venv/bin/python -m atrous.eval speed --atrous build/atrous --runs 20 --out learned_speed.json

It calls `atrous bench --json --what eaw,sure,learned` (the filter alone, inputs in place: the
median of --runs runs after --warmup; docs/benchmarks.md) and, in the same run, times OIDN on the
same inputs (the scene at 2 spp, seed 7, as `atrous bench` renders them, through atrous.render):

* ``oidn_denoise``: ``pyoidn.denoise(color, albedo, normal, hdr=True, quality="high")``, the call
  python/atrous/eval makes (pyoidn keeps its device and filter between calls, but binds the images
  and commits the filter in every call);
* ``oidn_filter``: pyoidn's object API, a ``pyoidn.Filter`` ("RT", hdr, quality high) created,
  bound and committed once, then only ``execute()`` timed: OIDN's own cost.
* ``alt_*``: the default method (``atrous.denoise`` with no ``method``: auto), ``blend``, ``refine``
  (SURE and the refine stage), through Python, and OIDN fast, balanced and high
  (``Filter.execute``), one call of each in turn per round, in this process: the speed bar of
  issues 27 and 47 (default at most OIDN fast).

Both are --warmup untimed calls (at least one), then the median of --runs calls (atrous.eval's
time_call), the same counts as the atrous rows. The result
is one JSON document on stdout (and in --out): every median, the ratios learned / OIDN (against
both OIDN timings), the machine, the date and the commit. Run it on an idle machine: the other
processes' load is in every figure.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from atrous.eval.machine import cpu_model, emit, git_commit
from atrous.names import LEARNED

import numpy as np

import atrous

# The still methods timed: every row of the registry with a cascade of its own (auto is one of them).
_FILTERS = tuple(str(r["name"]) for r in atrous.denoise_methods() if not r["resolves"] and not r["registered"])

ROOT = Path.cwd()  # the repository root: run from it (its out/ and build/ are the defaults)


def _oidn_filter(pyoidn, dev, color, albedo, normal, quality):
    """An RT filter (hdr) of `quality` bound to the images and committed: execute() is OIDN's own cost.
    Returns (filter, output array): OIDN writes into that array, so the caller keeps it alive as long
    as the filter."""
    flt = pyoidn.Filter(dev, pyoidn.OIDN_FILTER_TYPE_RT)
    result = np.zeros_like(color)
    for name, img in ((pyoidn.OIDN_IMAGE_COLOR, color), (pyoidn.OIDN_IMAGE_ALBEDO, albedo),
                      (pyoidn.OIDN_IMAGE_NORMAL, normal), (pyoidn.OIDN_IMAGE_OUTPUT, result)):
        flt.set_image(name, img, pyoidn.OIDN_FORMAT_FLOAT3)
    flt.set_bool("hdr", True)
    flt.set_quality(quality)
    flt.commit()
    err = dev.get_error()
    if err:
        raise RuntimeError(f"OIDN filter set-up failed: {err}")
    return flt, result


def time_oidn(b, runs: int, warmup: int) -> dict:
    import pyoidn
    from atrous.eval import oidn_inputs, time_call  # what atrous.eval's OIDN column passes and how it times

    color, albedo, normal = oidn_inputs(b)
    out = {"oidn_denoise_ms": time_call(
        lambda: pyoidn.denoise(color, albedo, normal, hdr=True, quality="high"), runs, warmup)[1]}
    dev = pyoidn.Device()
    dev.commit()
    flt, result = _oidn_filter(pyoidn, dev, color, albedo, normal, pyoidn.OIDN_QUALITY_HIGH)  # result: kept alive
    out["oidn_filter_ms"] = time_call(flt.execute, runs, warmup)[1]
    err = dev.get_error()
    if err:
        raise RuntimeError(f"OIDN execute failed: {err}")
    flt.release()
    dev.release()
    try:
        from importlib.metadata import version as _dist_version

        out["pyoidn"] = _dist_version("pyoidn")
    except Exception:
        out["pyoidn"] = "unknown"
    out["oidn"] = getattr(getattr(pyoidn, "version", None), "oidn_version", "unknown")
    return out


def time_default_alternating(b, runs: int, warmup: int) -> dict:
    """The default method (atrous.denoise with no method: auto, blend with these buffers) and OIDN
    fast, balanced and high (Filter.execute, committed once), in one process, one call of each in turn per
    round: the same load on every figure. Medians of `runs` rounds after `warmup` rounds."""
    import atrous
    import pyoidn
    from atrous import names
    from atrous.eval import oidn_inputs

    color, albedo, normal = oidn_inputs(b)
    feats = {k: b.get(k) for k in ("albedo", "normal", "position", "depth", "ids", "variance", "emission")
             if b.get(k) is not None}
    dev = pyoidn.Device()
    dev.commit()
    # (Each filter writes into its own output array: both are kept alive while the filters live.)
    fast, fast_out = _oidn_filter(pyoidn, dev, color, albedo, normal, pyoidn.OIDN_QUALITY_FAST)
    bal, bal_out = _oidn_filter(pyoidn, dev, color, albedo, normal, pyoidn.OIDN_QUALITY_BALANCED)
    high, high_out = _oidn_filter(pyoidn, dev, color, albedo, normal, pyoidn.OIDN_QUALITY_HIGH)
    calls = {"default": lambda: atrous.denoise(b["color"], **feats),
             names.BLEND: lambda: atrous.denoise(b["color"], method=names.BLEND, **feats),
             names.REFINE: lambda: atrous.denoise(b["color"], method=names.REFINE, **feats),
             "oidn_fast": fast.execute, "oidn_balanced": bal.execute, "oidn_high": high.execute}
    times = {k: [] for k in calls}
    for r in range(warmup + runs):
        for k, f in calls.items():
            t = time.perf_counter()
            f()
            if r >= warmup:
                times[k].append((time.perf_counter() - t) * 1e3)
    err = dev.get_error()
    if err:
        raise RuntimeError(f"OIDN execute failed: {err}")
    fast.release()
    bal.release()
    high.release()
    dev.release()
    del fast_out, bal_out, high_out
    out = {f"alt_{k}_ms": float(np.median(v)) for k, v in times.items()}
    out["alt_default_over_oidn_fast"] = out["alt_default_ms"] / out["alt_oidn_fast_ms"]
    out[f"alt_{names.REFINE}_over_oidn_fast"] = out[f"alt_{names.REFINE}_ms"] / out["alt_oidn_fast_ms"]
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m atrous.eval speed", description=__doc__.split("\n\n")[0])
    p.add_argument("--atrous", default=str(ROOT / "build" / "atrous"), help="the atrous CLI (default build/atrous)")
    p.add_argument("--sizes", default="512x512,1920x1080", help="comma list of WxH (default 512x512,1920x1080)")
    p.add_argument("--runs", type=int, default=10, help="timed runs per figure (default 10)")
    p.add_argument("--warmup", type=int, default=3, help="untimed runs first (default 3)")
    p.add_argument("--scene", default="cornell", help="scene whose 2-spp buffers are denoised (default cornell)")
    p.add_argument("--device", default="cpu", help="atrous bench's --device (default cpu; OIDN runs on the CPU)")
    p.add_argument("--learned-weights", help="weight file for the learned filter (default: the built-in weights)")
    p.add_argument("--out", help="also write the JSON here")
    a = p.parse_args(argv)
    if a.runs < 1 or a.warmup < 0:
        p.error("--runs must be >= 1 and --warmup >= 0")
    if not os.access(a.atrous, os.X_OK):
        p.error(f"--atrous: '{a.atrous}' is not an executable (build it: cmake --build build --target atrous)")
    sizes = []
    for s in a.sizes.split(","):
        try:
            w, h = (int(v) for v in s.lower().split("x"))
        except ValueError:
            p.error(f"--sizes: '{s}' is not WxH")
        sizes.append((w, h))

    cmd = [a.atrous, "bench", "--json", "--what", ",".join(_FILTERS), "--sizes", a.sizes, "--runs", str(a.runs),
           "--warmup", str(a.warmup), "--scene", a.scene, "--device", a.device]
    if a.learned_weights:
        cmd += ["--learned-weights", a.learned_weights]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.stderr.write(f"learned_speed: {' '.join(cmd)} failed ({proc.returncode}): {proc.stderr.strip()}\n")
        return 2
    bench = json.loads(proc.stdout)

    rows = []
    for w, h in sizes:
        row = {"width": w, "height": h}
        for r in bench["results"]:
            if r["width"] == w and r["height"] == h and r["what"] in _FILTERS:
                row[f"{r['what']}_ms"] = r["median_ms"]
                row[f"{r['what']}_total_ms"] = r["total_ms"]
        b = atrous.render(a.scene, width=w, height=h, spp=2, seed=7)
        row.update(time_oidn(b, a.runs, a.warmup))
        row.update(time_default_alternating(b, a.runs, a.warmup))
        for k in ("oidn_denoise_ms", "oidn_filter_ms"):
            if row.get(f"{LEARNED}_ms") and row.get(k):
                row[f"{LEARNED}_over_" + k[:-3]] = row[f"{LEARNED}_ms"] / row[k]
        rows.append(row)

    doc = {
        "what": "learned filter speed vs EAW, SURE and OIDN (python -m atrous.eval speed)",
        "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"),
        "commit": git_commit(),
        "machine": {"host": platform.node(), "cpu": cpu_model(), "cpu_count": os.cpu_count(),
                    "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None},
        "atrous_device": bench.get("device"), "atrous_device_name": bench.get("device_name"),
        "scene": a.scene, "input_spp": 2, "runs": a.runs, "warmup": a.warmup,
        "learned_weights": a.learned_weights or "built-in",
        "oidn_api": {"oidn_denoise": "pyoidn.denoise(color, albedo, normal, hdr=True, quality='high') per call",
                     "oidn_filter": "pyoidn.Filter RT (hdr, quality high) committed once, execute() timed"},
        "atrous_timing": "atrous bench median_ms (the filter alone, inputs in place); *_total_ms = the whole denoise()",
        "alternating": "alt_*: atrous.denoise with no method (the default: auto) and OIDN fast/balanced/high Filter.execute, "
                       "one call of each per round in this process; medians of --runs rounds after --warmup",
        "command": " ".join(cmd),
        "results": rows,
    }
    emit(doc, a.out)
    return 0

