#!/usr/bin/env python3
"""Side-by-side images of the CLI's output on the third-party corpus: noisy | EAW | SURE | reference
(or noisy | the --methods given | reference),
tonemapped (the library's 8-bit preview, atrous.tonemap: x / (1 + x), gamma 1/2.2), one PNG per scene and spp.

  .venv/bin/python scripts/corpus/cli_crops.py --corpus out/corpus/full --out docs/images \\
      --scenes mi_glass,cy_glass_mirror --spp 16 [--atrous build/atrous] [--methods sure,learned]

Runs in the project venv (numpy, Pillow from matplotlib) with OpenEXR from .venv-corpus, as
quality.py does; each input is denoised as a user hands it over (`atrous denoise --in FILE`).
"""
import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
from cli_quality import stills  # noqa: E402
import OpenEXR  # noqa: E402


def rgb(path):
    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = {}
        for part in f.parts:
            for k, c in part.channels.items():
                ch[k] = np.asarray(c.pixels, np.float32)
    for pre in ("", "ViewLayer.Combined."):
        if pre + "R" in ch:
            return np.stack([ch[pre + "R"], ch[pre + "G"], ch[pre + "B"]], -1)
    raise SystemExit(f"{path}: no R,G,B")


def tonemap(x):
    import atrous

    return atrous.tonemap(x[..., :3], np.uint8)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--corpus", default="out/corpus/full")
    ap.add_argument("--out", default="docs/images")
    ap.add_argument("--atrous", default="build/atrous")
    ap.add_argument("--scenes", default="")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--methods", default="eaw,sure", help="comma list of atrous denoise methods (default eaw,sure)")
    a = ap.parse_args()
    want = set(a.scenes.split(",")) if a.scenes else None
    with tempfile.TemporaryDirectory() as tmp:
        for scene, _, spp, inp, ref in stills(a.corpus):
            if spp != a.spp or (want and scene not in want):
                continue
            outs = []
            methods = a.methods.split(",")
            for m in methods:
                o = os.path.join(tmp, m + ".exr")
                subprocess.run([a.atrous, "denoise", "--in", inp, "--method", m, "--out", o], check=True,
                               capture_output=True)
                outs.append(rgb(o))
            noisy = rgb(inp if inp.endswith(".exr") else os.path.join(inp, "color.exr"))
            strip = np.concatenate([tonemap(x) for x in [noisy] + outs + [rgb(ref)]], 1)
            tag = "" if methods == ["eaw", "sure"] else "_" + "_".join(methods)
            path = Path(a.out) / f"corpus_{scene}_{spp}spp{tag}.png"
            Image.fromarray(strip).save(path)
            print(path)


if __name__ == "__main__":
    main()
