#!/usr/bin/env python3
"""Turns the raw training scenes (out/train/data/<split>/*.npz: color/variance/albedo/normal/depth/
emission at each spp + reference, from scripts/train/dataset.py or scripts/corpus) into the learned
filter's prepared planes, made by the library itself (atrous.prepared_planes: the still driver's
sanitise, emission split, firefly clamp, noise estimate, demodulation), so that the network trains
on exactly what it sees in atrous::denoise (docs/learned.md, "Training").

Each scene is prepared twice where it has a variance buffer: `given` (the rendered variance) and
`est` (variance withheld: the driver's per-pixel estimate, what other renderers' output gets), and
`noem` (variance and emission withheld: what a renderer that writes neither gives, e.g. Mitsuba's
aov integrator; a visible light then stays in d and its edge must be kept by the network itself).
Scenes without one (the corpus training split) get `est` only. Output: out/train/prep/<split>/
<name>.npz with keys "<variant>_<spp>_<plane>" (plane: color, variance, albedo, normal, depth,
modulation, emission: the C++ PreparedPlanes' names; absent planes have no key) and "reference";
written under a temporary name and renamed, so a rerun skips what is done (and redoes a file of
the older plane names d, var, mod). Needs the atrous module (.venv):

  .venv/bin/python scripts/train/prepare.py --splits train test corpus_train
"""
from __future__ import annotations

import argparse
import glob
import sys
import time
from pathlib import Path

import numpy as np

PLANES = ("color", "variance", "albedo", "normal", "depth", "modulation", "emission")


def _current(target: Path) -> bool:
    """Whether a prepared file has this version's plane names (an older one's "_d" keys are redone)."""
    try:
        return any(k.endswith("_color") for k in np.load(target).files)
    except (OSError, ValueError):
        return False


def spps_of(z) -> list:
    return sorted(int(k.split("_")[1]) for k in z.files if k.startswith("color_"))


def prepare_scene(z, planes_fn, variants=("given", "est")) -> dict:
    """The prepared planes of one raw scene (an npz mapping) as a flat dict of float32 arrays."""
    out = {"reference": np.nan_to_num(np.asarray(z["reference"], np.float32), nan=0.0, posinf=0.0, neginf=0.0)}
    for spp in spps_of(z):
        bufs = {b: (np.asarray(z[f"{b}_{spp}"], np.float32) if f"{b}_{spp}" in z.files else None)
                for b in ("color", "variance", "albedo", "normal", "depth", "emission")}
        if bufs["depth"] is not None and bufs["depth"].ndim == 3:
            bufs["depth"] = np.ascontiguousarray(bufs["depth"][..., :1])
        for v in variants:
            if v == "given" and bufs["variance"] is None:
                continue
            kw = dict(bufs)
            if v in ("est", "noem"):
                kw["variance"] = None
            if v == "noem":
                if bufs["emission"] is None:  # the `est` variant is the same image already
                    continue
                kw["emission"] = None
            color = kw.pop("color")
            planes = planes_fn(color, **kw)
            for p in PLANES:
                if p in planes:
                    out[f"{v}_{spp}_{p}"] = np.asarray(planes[p], np.float32)
    return out


def main(argv=None, planes_fn=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", default="out/train/data", help="raw scenes: <data>/<split>/*.npz")
    p.add_argument("--out", default="out/train/prep")
    p.add_argument("--splits", nargs="+", default=["train", "test", "corpus_train"])
    p.add_argument("--variants", nargs="+", default=["given", "est", "noem"], choices=["given", "est", "noem"])
    a = p.parse_args(argv)
    if planes_fn is None:
        import atrous

        planes_fn = atrous.prepared_planes
    t0, n = time.time(), 0
    for split in a.splits:
        dest = Path(a.out) / split
        dest.mkdir(parents=True, exist_ok=True)
        for f in sorted(glob.glob(f"{a.data}/{split}/*.npz")):
            if f.endswith(".tmp.npz"):  # a scene being written (dataset.py renames it when done)
                continue
            target = dest / Path(f).name
            if target.exists() and target.stat().st_mtime >= Path(f).stat().st_mtime and _current(target):
                continue  # prepared from this version of the scene (dataset.py redraws a changed one)
            try:
                planes = prepare_scene(np.load(f), planes_fn, a.variants)
            except (ValueError, KeyError) as e:
                raise SystemExit(f"prepare: {f}: {e}")
            tmp = target.with_suffix(".tmp.npz")
            np.savez(tmp, **planes)
            tmp.replace(target)
            n += 1
    print(f"prepare: {n} scenes prepared in {time.time() - t0:.0f} s ({a.out})", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
