"""relMSE of the learned filter on the held-out scenes (out/train/data/test) against the noisy input,
atrous's EAW and SURE and OIDN (pyoidn, when importable), at 4 and 16 spp, per scene and geometric
mean; prints a Markdown table and writes JSON (docs/learned.md, "Results"). Every atrous method runs
through the library as it ships (atrous.denoise with all buffers, the learned filter with
method="learned" and the given or built-in weights), so the table measures the C++ inference, not
the JAX model. Runs in the project venv (.venv: the atrous module, pyoidn):

  .venv/bin/python -m atrous.eval held-out --weights out/train/run/weights.bin --json out/train/eval.json
"""
import argparse
import glob
import json
import math
import sys
from pathlib import Path

import numpy as np

import atrous
from atrous.names import BLEND, LEARNED, SURE

ROOT = Path.cwd()  # the repository root: run from it (its out/ and build/ are the defaults)
BUFS = ("color", "variance", "albedo", "normal", "depth", "emission")
# The input, every still method of the registry with a cascade of its own (not auto, which is one of
# them per call; registered ones too), and OIDN.
METHODS = ("noisy", *(str(r["name"]) for r in atrous.denoise_methods() if not r["resolves"]), "oidn")


def buffers(z, spp: int) -> dict:
    b = {n: np.ascontiguousarray(z[f"{n}_{spp}"], np.float32) for n in BUFS if f"{n}_{spp}" in z.files}
    if "depth" in b and b["depth"].ndim == 3:
        b["depth"] = np.ascontiguousarray(b["depth"][..., :1])
    return b


def run_method(method: str, b: dict, weights):
    if method == "noisy":
        return b["color"]
    if method == "oidn":
        import pyoidn

        c = np.maximum(np.nan_to_num(b["color"], nan=0.0, posinf=0.0), 0.0).astype(np.float32)
        return pyoidn.denoise(c, np.clip(np.nan_to_num(b["albedo"]), 0, 1).astype(np.float32),
                              np.clip(np.nan_to_num(b["normal"]), -1, 1).astype(np.float32), hdr=True, quality="high")
    kw = {k: v for k, v in b.items() if k != "color"}
    extra = {"learned_weights": weights} if method in atrous.WEIGHTED_METHODS and weights else {}
    return atrous.denoise(b["color"], method=method, device="cpu", **kw, **extra)


def summary(res: dict, spps=(4, 16)) -> dict:
    out = {}
    for spp in spps:
        rows = {k: v for k, v in res.items() if k.endswith(f" {spp}spp")}
        ms = [m for m in METHODS if rows and all(m in v for v in rows.values())]
        s = {m: math.exp(np.mean([math.log(v[m]) for v in rows.values()])) for m in ms}
        # The figures docs/learned.md quotes (keys named after the methods, as the table's columns).
        for a, b in ((LEARNED, SURE), (BLEND, SURE)):
            if a in ms and b in ms:
                s[f"{a}_beats_{b}"] = sum(v[a] < v[b] for v in rows.values())
                s[f"{a}_over_{b}_max"] = max(v[a] / v[b] for v in rows.values())
        if LEARNED in ms and "oidn" in ms:
            s[f"{LEARNED}_over_oidn_max"] = max(v[LEARNED] / v["oidn"] for v in rows.values())
        s["scenes"] = len(rows)
        out[f"{spp}spp"] = s
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m atrous.eval held-out", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", default="out/train/data/test")
    p.add_argument("--weights", default=None, help="a weight file (version 4, or 3) (default: the built-in weights)")
    p.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    p.add_argument("--no-variance", action="store_true",
                   help="withhold the variance buffer (every atrous method then estimates it, as for other renderers)")
    p.add_argument("--json")
    a = p.parse_args(argv)
    res = {}
    files = sorted(f for f in glob.glob(f"{a.data}/*.npz") if not f.endswith(".tmp.npz"))
    if not files:
        raise SystemExit(f"evaluate: {a.data}: no scenes (run scripts/train/dataset.py)")
    for f in files:
        z = np.load(f)
        for spp in (4, 16):
            key = f"{Path(f).stem} {spp}spp"
            b = buffers(z, spp)
            if a.no_variance:
                b.pop("variance", None)
            r = res.setdefault(key, {})
            for m in a.methods:
                r[m] = atrous.relmse(run_method(m, b, a.weights), z["reference"])
            print(key, {k: round(v, 5) for k, v in r.items()}, flush=True)
    s = summary(res)
    if a.json:
        Path(a.json).write_text(json.dumps({"scenes": res, "summary": s}, indent=1))
    for spp, v in s.items():
        print(f"| {spp}, geometric mean over {v['scenes']} scenes | " +
              " | ".join(f"{m} {v[m]:.4f}" for m in METHODS if m in v) + " |")
        print({k: (round(x, 3) if isinstance(x, float) else x) for k, x in v.items() if k not in METHODS})
    return 0

