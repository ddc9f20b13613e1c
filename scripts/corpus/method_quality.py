#!/usr/bin/env python3
"""relMSE of atrous CLI runs (any flags) beside OIDN fast and high on the third-party corpus's
stills (and plain MSE and the mean over the reference's), per case and as geometric means per renderer and
spp over OIDN fast and over SURE
(docs/quality.md, "The default method").

    .venv/bin/python scripts/corpus/method_quality.py --corpus out/corpus/full --json out/corpus/full/methods.json \\
        eaw="--method eaw" sure="--method sure" learned="--method learned" default=""

Each VARIANT=FLAGS runs `atrous denoise --in FILE --out X.exr FLAGS` on the file (or folder) as the
renderer wrote it, so `default=""` is what a user gets without --method. OIDN (pyoidn, colour +
albedo + normal as atrous.eval passes them, HDR; quality fast, balanced and high) runs on the
buffers atrous.eval corpus (python/atrous/eval/corpus.py)'s loaders read; its outputs are cached in <corpus>/oidn_cache/
(delete it after re-rendering). --crops DIR writes, for each --crop-cases scene/spp, a strip
noisy | --crop-variant | OIDN fast | OIDN high | reference (the window with the most reference
detail, 2x), DIR/<scene>_<spp>spp_oidn.png.
Runs in the project venv (.venv: numpy, pyoidn, atrous); needs no renderer.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

import numpy as np

from atrous.eval import corpus as Q  # the corpus loaders, relmse, read_exr


def oidn_output(cache: Path, key: str, b, quality: str):
    f = cache / f"{key}_{quality}.npy"
    if not f.exists():
        import pyoidn
        from atrous.eval import oidn_inputs

        cache.mkdir(parents=True, exist_ok=True)
        np.save(f, np.asarray(pyoidn.denoise(*oidn_inputs(b), hdr=True, quality=quality), np.float32))
    return np.load(f)


def parse_variants(ap, items):
    """NAME=FLAGS arguments -> [(name, [flags])]; a malformed one is the parser's error."""
    variants = []
    for v in items:
        if "=" not in v:
            ap.error(f"'{v}': expected NAME=FLAGS")
        name, flags = v.split("=", 1)
        variants.append((name, flags.split()))
    return variants


def run_variant(atrous, inp, out, flags, what):
    """`atrous denoise --in INP --out OUT FLAGS`, the output's RGB; None (after one line on stderr)
    where the CLI failed."""
    r = subprocess.run([atrous, "denoise", "--in", str(inp), "--out", out] + flags, capture_output=True, text=True)
    if r.returncode:
        print(f"{what} failed: {r.stdout}{r.stderr}", file=sys.stderr)
        return None
    return Q._stack(Q.read_exr(out), ["R", "G", "B"])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", default="out/corpus/full")
    ap.add_argument("--atrous", default="build/atrous")
    ap.add_argument("--scenes", default="", help="comma-separated scene names (default: every still)")
    ap.add_argument("--json")
    ap.add_argument("--crops", help="folder for side-by-side crops")
    ap.add_argument("--crop-cases", default="", help="comma list of scene/spp, e.g. cy_glass_mirror/4")
    ap.add_argument("--crop-variant", default="default")
    ap.add_argument("--crop-size", type=int, default=96)
    ap.add_argument("variants", nargs="+", metavar="NAME=FLAGS")
    a = ap.parse_args()
    variants = parse_variants(ap, a.variants)
    only = set(a.scenes.split(",")) if a.scenes else None
    crops = set(a.crop_cases.split(",")) if a.crop_cases else set()
    corpus = Path(a.corpus)
    rows = []
    for man_path in sorted(corpus.glob("*/*/manifest.json")):
        man = json.loads(man_path.read_text())
        sd = man_path.parent
        if "frames" in man or (only and man["scene"] not in only) or man["reference"] not in man["files"]:
            continue
        ref = Q.load_still(sd, man, man["reference"])["color"]
        for stem, e in sorted(man["files"].items()):
            if stem == man["reference"]:
                continue
            b = Q.load_still(sd, man, stem)
            row = {"scene": man["scene"], "renderer": man["renderer"], "spp": e["spp"],
                   "pixel_filter": man.get("pixel_filter", "?"), "relmse": {}, "mse": {}, "mean_over_ref": {}}

            def score(name, img):
                row["relmse"][name] = Q.relmse(img, ref)
                row["mse"][name] = float(np.mean((img.astype(np.float64) - ref) ** 2))
                row["mean_over_ref"][name] = float(img.mean(dtype=np.float64) / ref.mean(dtype=np.float64))

            score("noisy", b["color"])
            for q in ("fast", "balanced", "high"):
                score("oidn_" + q, oidn_output(corpus / "oidn_cache", f"{man['scene']}_{stem}", b, q))
            inp = sd / (e["file"] if "file" in e else e["folder"])
            with tempfile.TemporaryDirectory() as t:
                for name, flags in variants:
                    out = os.path.join(t, name + ".exr")
                    img = run_variant(a.atrous, inp, out, flags, f"{man['scene']} {stem}: {name}")
                    if img is None:
                        return 2
                    score(name, img)
                    if a.crops and name == a.crop_variant and f"{man['scene']}/{e['spp']}" in crops:
                        key = f"{man['scene']}_{stem}"
                        strip = Q.crop_strip([b["color"], img, oidn_output(corpus / "oidn_cache", key, b, "fast"),
                                              oidn_output(corpus / "oidn_cache", key, b, "high"), ref], ref, a.crop_size)
                        Path(a.crops).mkdir(parents=True, exist_ok=True)
                        Q.save_png(Path(a.crops) / f"{man['scene']}_{e['spp']}spp_oidn.png", strip)
            rows.append(row)
            print(row["scene"], row["spp"], " ".join(f"{k}={v:.4g}" for k, v in row["relmse"].items()), flush=True)
    groups = defaultdict(list)
    for r in rows:
        groups[(r["renderer"], r["spp"])].append(r)
    summary = {}
    names = list(rows[0]["relmse"]) if rows else []
    for (renderer, spp), rs in sorted(groups.items()):
        g = {n: math.exp(np.mean([math.log(r["relmse"][n] / r["relmse"]["oidn_fast"]) for r in rs])) for n in names}
        s = {"cases": len(rs), "geomean_over_oidn_fast": g}
        if "sure" in names:
            s["worst_over_sure"] = {n: max(r["relmse"][n] / r["relmse"]["sure"] for r in rs) for n in names}
        s["worst_over_oidn_high"] = {n: max(r["relmse"][n] / r["relmse"]["oidn_high"] for r in rs) for n in names}
        s["worst_over_noisy"] = {n: max(r["relmse"][n] / r["relmse"]["noisy"] for r in rs) for n in names}
        # the bright-pixel bar: plain MSE at most the larger of the input's and OIDN high's
        s["mse_above_noisy_and_oidn_high"] = {n: sum(r["mse"][n] > max(r["mse"]["noisy"], r["mse"]["oidn_high"])
                                                     for r in rs) for n in names}
        summary[f"{renderer} {spp}spp"] = s
        print(f"{renderer} {spp} spp ({len(rs)} cases), geomean / OIDN fast: " +
              " ".join(f"{n}={v:.3f}" for n, v in g.items()))
    if a.json:
        json.dump({"corpus": str(corpus), "variants": dict((n, " ".join(f)) for n, f in variants), "rows": rows,
                   "summary": summary}, open(a.json, "w"), indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
