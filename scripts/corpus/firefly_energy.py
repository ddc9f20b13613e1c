#!/usr/bin/env python3
"""How much light the denoisers keep at 1-16 spp (docs/quality.md, "Firefly energy loss"; issue 47).

For atrous's own scenes (built-ins and scenes/window-room.json, rendered here with the CLI at
128x128, seed 3, references 1024 spp seed 999, cached in --work) and for third-party stills
(corpus scene folders, e.g. out/corpus/lowspp/cycles/cy_interior), runs `atrous denoise` as a user
would with each variant's flags and prints, per image, the mean of the output over the reference's,
relMSE and plain MSE, beside OIDN fast (pyoidn, colour + albedo + normal, HDR) and the noisy input.

    .venv/bin/python scripts/corpus/firefly_energy.py --atrous build/atrous --json out/firefly_energy.json \\
        --builtin cornell,cornell-point,sphere-env,cornell-spheres,scenes/window-room.json \\
        --corpus out/corpus/lowspp/cycles/cy_interior,out/corpus/lowspp/mitsuba/mi_interior,out/corpus/lowspp/luxcore/lx_room \\
        default= no-restore=--no-firefly-restore no-firefly=--no-firefly

Runs in the project venv (.venv: numpy, pyoidn, atrous).
"""
import argparse
import json
import shlex
import subprocess
import tempfile
from pathlib import Path

import numpy as np

import atrous
from atrous.eval import load_oidn, oidn_inputs
from atrous.eval.corpus import load_still

ROOT = Path(__file__).resolve().parents[2]


def builtin_cases(cli, scenes, spps, work):
    """(name, input path, buffers, reference colour) of atrous's own renders, rendered once."""
    for scene in scenes:
        name = Path(scene).stem if scene.endswith(".json") else scene
        d = Path(work) / name

        def rendered(sub, spp, seed):
            out = d / sub
            if not (out / "color.exr").exists():
                subprocess.run([cli, "render", "--quiet", "--scene", scene, "--width", "128", "--height", "128",
                                "--spp", str(spp), "--seed", str(seed), "--out", str(out)], check=True)
            return out

        ref = atrous.read_buffers(str(rendered("ref", 1024, 999)))["color"]
        for spp in spps:
            path = rendered(f"s{spp}", spp, 3)
            yield f"{name} {spp}", path, atrous.read_buffers(str(path)), ref


def corpus_cases(folders):
    for sd in folders:
        sd = Path(sd)
        man = json.loads((sd / "manifest.json").read_text())
        ref = load_still(sd, man, man["reference"])["color"]
        for stem, e in man["files"].items():
            if stem == man["reference"]:
                continue
            path = sd / e.get("file", e.get("folder", ""))
            yield f"{sd.name} {e['spp']}", path, load_still(sd, man, stem), ref


def measure(img, ref):
    img = np.asarray(img, np.float64)[..., :3]
    return {"mean": float(img.mean() / ref.mean()), "relmse": float(atrous.relmse(img.astype(np.float32), ref)),
            "mse": float(np.mean((img - ref) ** 2))}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("variants", nargs="+", metavar="NAME=FLAGS")
    ap.add_argument("--atrous", default=str(ROOT / "build" / "atrous"))
    ap.add_argument("--builtin", default="", help="comma list of built-in scene names or JSON scene files")
    ap.add_argument("--spp", default="1,4,16")
    ap.add_argument("--corpus", default="", help="comma list of corpus scene folders (with manifest.json)")
    ap.add_argument("--work", default=str(ROOT / "out" / "firefly_energy"))
    ap.add_argument("--json", default="")
    a = ap.parse_args(argv)
    variants = [v.split("=", 1) for v in a.variants]
    oidn, why = load_oidn()
    spps = [int(s) for s in a.spp.split(",")]
    cases = list(builtin_cases(a.atrous, [s for s in a.builtin.split(",") if s], spps, a.work))
    cases += list(corpus_cases([c for c in a.corpus.split(",") if c]))
    rows = {}
    for name, path, bufs, ref in cases:
        row = {"noisy": measure(bufs["color"], ref)}
        if oidn is not None:
            import pyoidn
            row["oidn_fast"] = measure(pyoidn.denoise(*oidn_inputs(bufs), hdr=True, quality="fast"), ref)
        for vname, flags in variants:
            with tempfile.TemporaryDirectory() as t:
                subprocess.run([a.atrous, "denoise", "--quiet", "--in", str(path), "--out", f"{t}/out.exr"]
                               + shlex.split(flags), check=True)
                row[vname] = measure(atrous.read_image(f"{t}/out.exr"), ref)
        rows[name] = row
        print(f"{name:24s} " + "  ".join(f"{k} {v['mean']:.3f} / {v['relmse']:.4g} / {v['mse']:.3g}"
                                        for k, v in row.items()), flush=True)
    if oidn is None:
        print(f"(no OIDN column: {why})")
    if a.json:
        Path(a.json).parent.mkdir(parents=True, exist_ok=True)
        Path(a.json).write_text(json.dumps({"columns": "mean over the reference's / relMSE / MSE", "cases": rows},
                                           indent=1))


if __name__ == "__main__":
    main()
