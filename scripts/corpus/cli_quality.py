#!/usr/bin/env python3
"""relMSE of the atrous CLI's filters on the third-party corpus, each file read the way a user
hands it over (`atrous denoise --in FILE.exr` or `--in DIR`), against the corpus's reference.

  scripts/corpus/cli_quality.py [--corpus out/corpus/quick] [--atrous build/atrous] [--json OUT]
      [--methods eaw,sure] [--max-ratio R] [--bounds FILE] [--write-bounds FILE --margin M]

--methods takes any `atrous denoise --method` (e.g. eaw,sure,learned: the learned filter with the
built-in weights, or a weight file with --extra '--learned-weights FILE'). Needs only the CLI and the rendered corpus (scripts/corpus/render.py), not Mitsuba or Blender.
With --max-ratio R it exits 1 when any filter's relMSE is above R times the noisy input's; with
--bounds FILE when any relMSE is above its bound there ("scene/spp/method": relMSE); the CI check
(scripts/corpus_check.sh) uses the bounds. --write-bounds writes today's figures times M.
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile


def compare(atrous, ref, images):
    out = subprocess.run([atrous, "compare", "--json", "--ref", ref] + images, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(out.stdout + out.stderr)
    return [im["relmse"] for im in json.loads(out.stdout)["images"]]


def stills(corpus):
    """(scene, spp, input path, reference path) of every still in the corpus."""
    for manifest in sorted(glob.glob(os.path.join(corpus, "*", "*", "manifest.json"))):
        scene_dir = os.path.dirname(manifest)
        m = json.load(open(manifest))
        if "sequence" in m.get("layout", "") or m.get("frames"):
            continue
        refs = sorted(glob.glob(os.path.join(scene_dir, "ref*")))
        if not refs:
            continue
        ref = refs[-1]
        ref = ref if ref.endswith(".exr") else os.path.join(ref, "color.exr")
        for inp in sorted(glob.glob(os.path.join(scene_dir, "spp*"))):
            spp = int(os.path.basename(inp)[3:].split(".")[0])
            if os.path.isdir(inp) and not os.path.exists(os.path.join(inp, "color.exr")):
                continue
            yield m.get("scene", os.path.basename(scene_dir)), m.get("renderer", "?"), spp, inp, ref


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--corpus", default="out/corpus/quick")
    ap.add_argument("--atrous", default="build/atrous")
    ap.add_argument("--methods", default="eaw,sure")
    ap.add_argument("--json")
    ap.add_argument("--max-ratio", type=float)
    ap.add_argument("--extra", default="", help="extra denoise flags, e.g. '--no-firefly'")
    ap.add_argument("--bounds", help="JSON of bounds: {\"scene/spp/method\": relMSE}")
    ap.add_argument("--write-bounds", help="write today's relMSE x --margin as a bounds file")
    ap.add_argument("--margin", type=float, default=1.25)
    a = ap.parse_args()
    methods = a.methods.split(",")
    rows, worst = [], 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for scene, renderer, spp, inp, ref in stills(a.corpus):
            outs = []
            for m in methods:
                o = os.path.join(tmp, m + ".exr")
                r = subprocess.run([a.atrous, "denoise", "--in", inp, "--method", m, "--out", o] + a.extra.split(),
                                   capture_output=True, text=True)
                if r.returncode != 0:
                    print(f"{scene} {spp}: {m} failed: {r.stdout}{r.stderr}", file=sys.stderr)
                    return 2
                outs.append(o)
            noisy_in = inp if inp.endswith(".exr") else os.path.join(inp, "color.exr")
            vals = compare(a.atrous, ref, [noisy_in] + outs)
            row = {"scene": scene, "renderer": renderer, "spp": spp, "noisy": vals[0]}
            row.update({m: v for m, v in zip(methods, vals[1:])})
            rows.append(row)
            worst = max([worst] + [row[m] / max(row["noisy"], 1e-12) for m in methods])
    print("| scene | renderer | spp | noisy | " + " | ".join(methods) + " |")
    print("|---|---|---|---|" + "---|" * len(methods))
    for r in rows:
        print(f"| {r['scene']} | {r['renderer']} | {r['spp']} | {r['noisy']:.4g} | " +
              " | ".join(f"{r[m]:.4g} ({r['noisy'] / max(r[m], 1e-12):.1f}x)" for m in methods) + " |")
    print(f"worst filter/noisy ratio: {worst:.3f}")
    if a.json:
        json.dump({"corpus": a.corpus, "rows": rows, "worst_ratio": worst}, open(a.json, "w"), indent=1)
    worse = [f"{r['scene']}/{r['spp']}/{m}" for r in rows for m in methods if r[m] >= r["noisy"]]
    if worse:
        print("worse than the noisy input: " + ", ".join(worse))
    if a.write_bounds:
        b = {f"{r['scene']}/{r['spp']}/{m}": float(f"{r[m] * a.margin:.4g}") for r in rows for m in methods}
        json.dump(b, open(a.write_bounds, "w"), indent=1, sort_keys=True)
    failed = False
    if a.bounds:
        bounds = json.load(open(a.bounds))
        seen = set()
        for r in rows:
            for m in methods:
                key = f"{r['scene']}/{r['spp']}/{m}"
                if key not in bounds:
                    continue
                seen.add(key)
                if r[m] > bounds[key]:
                    print(f"FAIL: {key}: relMSE {r[m]:.4g} above its bound {bounds[key]}", file=sys.stderr)
                    failed = True
        missing = sorted(set(bounds) - seen)
        if missing:
            print("FAIL: not measured: " + ", ".join(missing), file=sys.stderr)
            failed = True
        print(f"{len(seen)} bounds checked, {'some failed' if failed else 'all held'}")
    if a.max_ratio is not None and worst > a.max_ratio:
        print(f"FAIL: a filter's relMSE is {worst:.3f}x the noisy input's (bound {a.max_ratio})", file=sys.stderr)
        failed = True
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
