#!/usr/bin/env python3
"""The measurement behind `--method auto` (docs/learned.md, "Auto"): on TRAINING scenes only (our
own renders' train split and the third-party corpus's training split, never a test scene), SURE
and the learned filter through atrous.denoise, and the statistic auto decides by, so that the rule
is set on data the test tables never see. Run with the project venv (it needs atrous and numpy):

    .venv/bin/python scripts/train/auto_rule.py --json out/train/auto_rule.json

Per scene and spp (4 and 16; our renders with their variance and without it) it prints relMSE of
SURE and learned and rho = the median over pixels of sqrt(mean_c var_c) / (mean_c d_c + 0.01) on
the driver's prepared planes (color: the demodulated colour, variance: its rendered or estimated variance), then
the geometric mean of every candidate rule: always SURE, always learned, learned iff a variance
buffer was given, learned iff rho > t for each t."""
from __future__ import annotations

import argparse
import glob
import json
import math
import sys
from pathlib import Path

import numpy as np

import atrous

ROOT = Path(__file__).resolve().parents[2]


relmse = atrous.relmse  # docs/eval.md's relMSE, as the library computes it


def rho_of(planes) -> float:
    sd = np.sqrt(np.maximum(np.mean(planes["variance"], axis=2), 0.0))
    m = np.mean(np.maximum(planes["color"], 0.0), axis=2) + 0.01
    return float(np.median(sd / m))


def cases(data: Path, limit: int):
    for split, with_var in (("train", (True, False)), ("corpus_train", (False,))):
        for f in sorted(glob.glob(str(data / split / "*.npz")))[:limit]:
            z = np.load(f)
            ref = np.nan_to_num(z["reference"]).astype(np.float32)
            for spp in (4, 16):
                if f"color_{spp}" not in z.files:
                    continue
                bufs = {b: np.ascontiguousarray(z[f"{b}_{spp}"], np.float32) for b in ("color", "albedo", "normal", "emission")}
                bufs["depth"] = np.ascontiguousarray(z[f"depth_{spp}"], np.float32)
                for v in with_var:
                    var = z[f"variance_{spp}"].astype(np.float32) if v and f"variance_{spp}" in z.files else None
                    yield f"{split}/{Path(f).stem}", spp, var is not None, bufs, var, ref


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", default=str(ROOT / "out/train/data"))
    ap.add_argument("--limit", type=int, default=40, help="scenes per split")
    ap.add_argument("--json")
    a = ap.parse_args()
    rows = []
    for name, spp, given, b, var, ref in cases(Path(a.data), a.limit):
        kw = dict(albedo=b["albedo"], normal=b["normal"], depth=b["depth"], emission=b["emission"], variance=var)
        planes = atrous.prepared_planes(b["color"], **kw)
        r = {"scene": name, "spp": spp, "variance": given, "rho": rho_of(planes),
             "noisy": relmse(b["color"], ref),
             "sure": relmse(atrous.denoise(b["color"], method="sure", **kw), ref),
             "learned": relmse(atrous.denoise(b["color"], method="learned", **kw), ref)}
        rows.append(r)
        print(f"{name:34s} {spp:3d} var={int(given)} rho={r['rho']:.4f} sure={r['sure']:.5f} learned={r['learned']:.5f}",
              flush=True)
    if not rows:
        print(f"auto_rule: no scenes under {a.data}", file=sys.stderr)
        return 2

    def geo(pick):
        return math.exp(sum(math.log(r["learned"] if pick(r) else r["sure"]) for r in rows) / len(rows))

    rules = {"sure": geo(lambda r: False), "learned": geo(lambda r: True),
             "learned iff variance given": geo(lambda r: r["variance"])}
    for t in sorted({round(r["rho"], 3) for r in rows}):
        rules[f"learned iff rho > {t}"] = geo(lambda r, t=t: r["rho"] > t)
        rules[f"learned iff variance or rho > {t}"] = geo(lambda r, t=t: r["variance"] or r["rho"] > t)
    best = min(rules, key=rules.get)
    for k in ("sure", "learned", "learned iff variance given", best):
        print(f"geomean relMSE, {k}: {rules[k]:.5f}")
    if a.json:
        Path(a.json).write_text(json.dumps({"rows": rows, "rules": rules, "best": best}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
