"""How far a dataset's OIDN targets are from the truth (issue 47, docs/farm.md "Training targets"):
for every scene of a `render --dataset` output that has both target.exr and reference.exr (the
spec's reference_every), relMSE, MSE and mean of the target against the reference, beside each
input spp's noisy colour; geometric means over the scenes. The data card of docs/learned.md quotes
it.

    python -m atrous.farm.target_error OUT [--json OUT/target_error.json]
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np

import atrous


def _score(img: np.ndarray, ref: np.ndarray) -> Dict[str, float]:
    img = np.asarray(img, np.float32)[..., :3]
    d = img.astype(np.float64) - ref
    return {"relmse": float(atrous.relmse(img, ref)), "mse": float(np.mean(d * d)),
            "mean": float(img.mean() / ref.mean()) if ref.mean() > 0 else float("nan")}


def target_error(root: Path) -> Dict[str, Any]:
    """Per scene and geometric means; raises ValueError when no scene has both images."""
    scenes: List[Dict[str, Any]] = []
    for d in sorted(Path(root).glob("scene_*")):
        if not ((d / "target.exr").is_file() and (d / "reference.exr").is_file()):
            continue
        ref = atrous.read_image(d / "reference.exr")[..., :3]
        row: Dict[str, Any] = {"scene": d.name, "target": _score(atrous.read_image(d / "target.exr"), ref)}
        meta = d / "target.json"
        if meta.is_file():
            row["target_spp"] = json.loads(meta.read_text()).get("spp")
        for sd in sorted(d.glob("spp_*"), key=lambda p: int(p.name[4:])):
            row[sd.name] = _score(atrous.read_image(sd / "color.exr"), ref)
        scenes.append(row)
    if not scenes:
        raise ValueError(f"{root}: no scene has both target.exr and reference.exr (a spec with "
                         f"\"target\": \"oidn\" and \"reference_every\" > 0 makes them)")
    cols = [k for k in scenes[0] if isinstance(scenes[0][k], dict)]
    geo = {c: math.exp(float(np.mean([math.log(max(r[c]["relmse"], 1e-12)) for r in scenes if c in r])))
           for c in cols}
    return {"root": str(root), "scenes": scenes, "geomean_relmse": geo}


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m atrous.farm.target_error", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("root", help="a `render --dataset` output folder")
    ap.add_argument("--json", default="")
    a = ap.parse_args(argv)
    try:
        res = target_error(Path(a.root))
    except (ValueError, OSError) as e:
        print(f"target_error: {e}", file=sys.stderr)
        return 2
    cols = list(res["geomean_relmse"])
    print("| scene | " + " | ".join(f"{c} relMSE / mean" for c in cols) + " |")
    print("|---|" + "---:|" * len(cols))
    for r in res["scenes"]:
        print(f"| {r['scene']} | " + " | ".join(f"{r[c]['relmse']:.4g} / {r[c]['mean']:.3f}" if c in r else ""
                                              for c in cols) + " |")
    print("| geometric mean | " + " | ".join(f"{res['geomean_relmse'][c]:.4g}" for c in cols) + " |")
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
