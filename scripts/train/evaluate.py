#!/usr/bin/env python3
"""relMSE of the learned filter on the held-out scenes (out/train/data/test) against the noisy input,
atrous's EAW and SURE (the CLI) and OIDN (pyoidn, when importable), at 4 and 16 spp; prints a
Markdown table and writes JSON (docs/learned.md, "First result"). Methods needing jax run only in
.venv-train; OIDN only where pyoidn imports (the lead's .venv): run it under both and --merge.

  .venv-train/bin/python scripts/train/evaluate.py --weights out/train/run/weights.bin --json out/train/eval.json
  .venv/bin/python scripts/train/evaluate.py --only oidn --json out/train/eval_oidn.json
  python3 scripts/train/evaluate.py --merge out/train/eval.json out/train/eval_oidn.json
"""
import argparse
import glob
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
BUFS = ("color", "variance", "albedo", "normal", "depth", "emission")


def relmse(x, r):
    x, r = np.nan_to_num(x.astype(np.float64)), np.nan_to_num(r.astype(np.float64))
    return float(np.mean((x - r) ** 2 / (r * r + 0.01)))


def cli(z, spp, atrous, method):
    import OpenEXR

    with tempfile.TemporaryDirectory() as t:
        for b in BUFS:
            OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                         {"RGB": np.ascontiguousarray(z[f"{b}_{spp}"], np.float32)}).write(f"{t}/{b}.exr")
        subprocess.run([atrous, "denoise", "--in", t, "--method", method, "--device", "cpu", "--out", f"{t}/o.exr"],
                       check=True, stdout=subprocess.DEVNULL)
        with OpenEXR.File(f"{t}/o.exr") as f:
            return np.array(f.channels()["RGB"].pixels, np.float32)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", default="out/train/data/test")
    p.add_argument("--weights", default="out/train/run/weights.bin")
    p.add_argument("--atrous", default="build-learn/atrous")
    p.add_argument("--only", choices=["oidn", "atrous"], default="atrous")
    p.add_argument("--json")
    p.add_argument("--merge", nargs="+")
    a = p.parse_args()
    if a.merge:
        res = {}
        for f in a.merge:
            for k, v in json.loads(Path(f).read_text()).items():
                res.setdefault(k, {}).update(v)
    else:
        res = {}
        files = sorted(glob.glob(f"{a.data}/*.npz"))
        if a.only == "oidn":
            sys.path.insert(0, str(ROOT / "python"))
            import pyoidn
        else:
            sys.path.insert(0, str(ROOT / "python" / "atrous"))
            import jax.numpy as jnp
            from learn import features, model, weights
            params = {k: jnp.asarray(v) for k, v in weights.from_bytes(Path(a.weights).read_bytes(), a.weights).items()}
        for f in files:
            z = np.load(f)
            ref = z["reference"]
            for spp in (4, 16):
                key = f"{Path(f).stem} {spp}spp"
                r = res.setdefault(key, {})
                if a.only == "oidn":
                    c = np.maximum(np.nan_to_num(z[f"color_{spp}"], nan=0.0, posinf=0.0), 0.0).astype(np.float32)
                    r["oidn"] = relmse(pyoidn.denoise(c, np.clip(np.nan_to_num(z[f"albedo_{spp}"]), 0, 1).astype(np.float32),
                                                      np.clip(np.nan_to_num(z[f"normal_{spp}"]), -1, 1).astype(np.float32),
                                                      hdr=True, quality="high"), ref)
                    continue
                r["noisy"] = relmse(z[f"color_{spp}"], ref)
                for m in ("eaw", "sure"):
                    r[m] = relmse(cli(z, spp, a.atrous, m), ref)
                x, d, al, e = features.prepare(*(z[f"{b}_{spp}"] for b in BUFS))
                out = model.forward(params, jnp.asarray(x[None]), jnp.asarray(d[None]), jnp.asarray(al[None]), jnp.asarray(e[None]))
                r["learned"] = relmse(np.asarray(out[0]), ref)
                print(key, {k: round(v, 4) for k, v in r.items()}, flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1))
    methods = sorted({m for v in res.values() for m in v})
    for spp in (4, 16):
        rows = {k: v for k, v in res.items() if k.endswith(f" {spp}spp")}
        gm = {m: math.exp(np.mean([math.log(v[m]) for v in rows.values() if m in v])) for m in methods
              if all(m in v for v in rows.values())}
        print(f"| {spp} spp, geometric mean over {len(rows)} scenes | " + " | ".join(f"{m} {gm[m]:.4f}" for m in gm) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
