#!/usr/bin/env python3
"""relMSE and temporal relMSE of `atrous denoise --sequence` runs (any flags) beside OIDN high per
frame, on the third-party corpus's animations and on atrous's own rendered sequences
(docs/temporal.md, docs/quality.md "Sequences").

    .venv/bin/python scripts/corpus/sequence_quality.py --corpus out/corpus/full --own out/heldout_seq \\
        temporal="" per_frame_auto="--method auto" svgf="--method svgf"

Each VARIANT=FLAGS runs `atrous denoise --sequence SEQ --out DIR FLAGS` on the sequence as the
renderer wrote it ("" is what a user gets without --method). Corpus sequences are the scenes of
<corpus>/{cycles,mitsuba}/ whose manifest lists frames (frames/ beside ref/); own sequences are
`atrous render --frames N --reference-spp S` folders (frame_NNNN/ with reference.exr), e.g.

    atrous render --scene cornell-moving --frames 20 --spp 1 --reference-spp 256 --width 128 --height 128 --out out/heldout_seq/cornell_moving
    atrous render --scene cornell-spheres --camera-path orbit --frames 20 --spp 1 --reference-spp 256 --width 128 --height 128 --out out/heldout_seq/spheres_orbit

OIDN (pyoidn, HDR, colour + albedo + normal) runs per frame on the buffers the corpus loaders read
(scripts/corpus/quality.py) or on the frame's color/albedo/normal.exr. The metrics are `atrous
compare --sequence`'s. Runs in the project venv (.venv: numpy, pyoidn, atrous).
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import quality as Q  # noqa: E402  (the corpus loaders)

ROOT = Path(__file__).resolve().parents[2]


def corpus_sequences(corpus: Path):
    for renderer in ("cycles", "mitsuba"):
        for d in sorted((corpus / renderer).glob("*")):
            man = d / "manifest.json"
            if man.exists() and "frames" in json.loads(man.read_text()) and (d / "frames").is_dir():
                yield d.name, d, d / "frames", d / "ref"


def own_sequences(own: Path):
    for d in sorted(own.glob("*")):
        if (d / "frame_0000" / "reference.exr").exists():
            yield d.name, d, d, d


def oidn_per_frame(name, scene, out: Path):
    import atrous
    import pyoidn

    out.mkdir(parents=True, exist_ok=True)
    man_path = scene / "manifest.json"
    if man_path.exists():
        man = json.loads(man_path.read_text())
        for fr in man["frames"]:
            b = Q.load_frame(scene, man, fr)
            alb = np.ascontiguousarray(np.clip(b["albedo"], 0.0, 1.0), np.float32)
            o = pyoidn.denoise(np.ascontiguousarray(b["color"], np.float32), alb,
                               np.ascontiguousarray(b["normal"], np.float32), hdr=True, quality="high")
            atrous.write_image(str(out / f"frame_{fr['frame']:04d}.exr"), np.asarray(o, np.float32))
        return
    for d in sorted(scene.glob("frame_*")):
        rd = lambda k: np.ascontiguousarray(np.asarray(atrous.read_image(str(d / f"{k}.exr")), np.float32))  # noqa: E731
        o = pyoidn.denoise(rd("color"), np.clip(rd("albedo"), 0.0, 1.0), rd("normal"), hdr=True, quality="high")
        atrous.write_image(str(out / f"{d.name}.exr"), np.asarray(o, np.float32))


def compare(cli, ref, outs):
    r = subprocess.run([cli, "compare", "--sequence", str(ref)] + [str(o) for o in outs] + ["--json"],
                       capture_output=True, text=True, check=True)
    return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", type=Path, help="the third-party corpus (scripts/corpus/render.py --full)")
    ap.add_argument("--own", type=Path, help="a folder of `atrous render --frames` sequences with references")
    ap.add_argument("--cli", default=str(ROOT / "build" / "atrous"))
    ap.add_argument("--json", type=Path, help="write the figures here too")
    ap.add_argument("variants", nargs="+", help="NAME=FLAGS")
    a = ap.parse_args()
    variants = [v.split("=", 1) for v in a.variants]
    seqs = []
    if a.corpus:
        seqs += list(corpus_sequences(a.corpus))
    if a.own:
        seqs += list(own_sequences(a.own))
    if not seqs:
        sys.exit("sequence_quality: no sequence found (give --corpus and/or --own)")
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene, seq, ref in seqs:
            outs = []
            for vname, flags in variants:
                o = Path(tmp) / name / vname
                subprocess.run([a.cli, "denoise", "--sequence", str(seq), "--out", str(o)] + shlex.split(flags),
                               check=True, stdout=subprocess.DEVNULL)
                outs.append(o)
            o = Path(tmp) / name / "oidn_high_per_frame"
            oidn_per_frame(name, scene, o)
            outs.append(o)
            rows = compare(a.cli, ref, outs)
            results[name] = {Path(r["path"]).name: {k: r[k] for k in ("relmse", "temporal_relmse", "psnr")}
                             for r in rows["sequences"]}
    names = [v[0] for v in variants] + ["oidn_high_per_frame"]
    print("| sequence | " + " | ".join(names) + " |")
    print("|---" * (len(names) + 1) + "|")
    for s, r in results.items():
        print(f"| {s} | " + " | ".join(f"{r[n]['relmse']:.4f} / {r[n]['temporal_relmse']:.4f}" for n in names) + " |")
    if a.json:
        a.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
