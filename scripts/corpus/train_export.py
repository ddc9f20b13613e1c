#!/usr/bin/env python3
"""The corpus's training split as the learned filter's raw training files (docs/corpus.md,
"Training split"): each scene of out/corpus/train/ (render.py --train) becomes one
out/train/data/corpus_train/scene_<name>.npz in scripts/train/dataset.py's format.

    .venv-corpus/bin/python scripts/corpus/train_export.py --atrous build-h4/atrous

Every buffer is what atrous itself takes from the renderer's file: `atrous inspect FILE --export
DIR` (the same reader and conventions as `atrous denoise --in FILE`), read back with OpenEXR.
Keys per spp in (1, 4, 16): color_{spp}, albedo_{spp}, normal_{spp}, depth_{spp} (3 channels,
background 1e30), emission_{spp} (zeros where the renderer gives none); no variance_{spp} (the
renderers give none: the driver estimates it); reference (the >= 1024-spp render's colour);
kind ("mitsuba" / "cycles" / "luxcore"); scene_json (the scene's manifest). All arrays H x W x 3 float32.
Written under a temporary name and renamed; a scene whose npz is newer than its manifest is skipped.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
from common import TRAIN  # noqa: E402

KEYS = ("color", "albedo", "normal", "depth", "emission")


def read_rgb(path):
    import OpenEXR
    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        return np.ascontiguousarray(np.asarray(ch["RGB"].pixels, np.float32))


def export(atrous, src, tmp):
    """The buffers atrous takes from `src` (a layered EXR or a render directory), by name."""
    out = Path(tempfile.mkdtemp(dir=tmp))
    r = subprocess.run([atrous, "inspect", str(src), "--export", str(out)], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"train_export: atrous inspect {src} failed: {r.stdout}{r.stderr}")
    return {p.stem: read_rgb(p) for p in out.glob("*.exr")}


def scene_arrays(atrous, d, man, tmp, spps=TRAIN["spp"]):
    arrays = {}
    for stem, f in man["files"].items():
        src = d / (f["file"] if "file" in f else f["folder"])
        b = export(atrous, src, tmp)
        if stem == man["reference"]:
            arrays["reference"] = b["color"]
            continue
        spp = f["spp"]
        for k in KEYS:
            arrays[f"{k}_{spp}"] = b[k] if k in b else np.zeros_like(b["color"])
    for spp in spps:
        for k in KEYS:
            assert f"{k}_{spp}" in arrays, (d, k, spp)
    for k, v in arrays.items():
        if not np.isfinite(v).all() and not k.startswith("depth"):
            bad = int((~np.isfinite(v)).any(-1).sum())
            print(f"train_export: {d.name} {k}: {bad} non-finite pixels (left: the driver sanitises)", flush=True)
    arrays["kind"] = np.array(man["renderer"])
    arrays["scene_json"] = np.array(json.dumps(man))
    return arrays


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--atrous", default=str(ROOT / "build" / "atrous"))
    ap.add_argument("--corpus", default=str(ROOT / "out" / "corpus" / "train"))
    ap.add_argument("--out", default=str(ROOT / "out" / "train" / "data" / "corpus_train"))
    ap.add_argument("--test", action="store_true",
                    help="export the corpus's test stills instead (--corpus out/corpus/full, default --out "
                         "out/train/data/corpus_test): for evaluating a network in JAX only; no training split "
                         "reads them")
    a = ap.parse_args()
    if a.test and a.out == ap.get_default("out"):
        a.out = str(ROOT / "out" / "train" / "data" / "corpus_test")
    if a.test and a.corpus == ap.get_default("corpus"):  # the test stills are in the full corpus
        a.corpus = str(ROOT / "out" / "corpus" / "full")
    pattern, spps = ("*/[cml][yix]_*/manifest.json", (4, 16)) if a.test else ("*/tr_*/manifest.json", TRAIN["spp"])
    dest = Path(a.out)
    dest.mkdir(parents=True, exist_ok=True)
    n = 0
    for man_path in sorted(Path(a.corpus).glob(pattern)):
        d = man_path.parent
        if "files" not in json.loads(man_path.read_text()):  # a sequence (frames, not stills)
            continue
        target = dest / f"scene_{d.name}.npz"
        if target.exists() and target.stat().st_mtime >= man_path.stat().st_mtime:
            n += 1
            continue
        man = json.loads(man_path.read_text())
        t = time.time()
        with tempfile.TemporaryDirectory(dir=dest) as tmp:
            arrays = scene_arrays(a.atrous, d, man, tmp, spps)
            part = Path(tmp) / "scene.npz"
            np.savez_compressed(part, **arrays)
            os.replace(part, target)
        n += 1
        print(f"train_export: {target} ({time.time() - t:.1f}s; render {sum(man['render_seconds'].values()):.0f}s)",
              flush=True)
    print(f"train_export: {n} scenes in {dest}", flush=True)


if __name__ == "__main__":
    main()
