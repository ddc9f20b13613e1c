"""Quality benchmark of the denoisers (run by hand; results go to docs/quality.md).

For each built-in scene, renders a high-spp reference (cached under OUT/refs/), noisy images at
the given spp, denoises them with EAW and SURE, and compares all against the reference with
`atrous compare --json`. Prints a markdown table (MSE, relMSE, MSE reduction over noisy, SURE vs
EAW) and writes it to OUT/quality.md. Python 3 standard library only.

  .venv/bin/python -m atrous.eval cli-scenes                      # 512x512, 4 and 16 spp, 4096-spp references
  nice -n 19 .venv/bin/python -m atrous.eval cli-scenes --size 256 --ref-spp 1024   # quicker, for development
"""
import argparse
import datetime
import json
import os
import subprocess
import sys
import time

from atrous.eval.machine import cpu_model
from atrous.names import EAW, SURE  # the two filters compared, by their names in the registry

SCENES = ["cornell", "cornell-point", "cornell-spheres", "sphere-env"]


def run(cmd):
    t = time.time()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stdout))
    return r.stdout, time.time() - t


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m atrous.eval cli-scenes", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--atrous", default="build/atrous", help="path of the atrous CLI")
    ap.add_argument("--out", default="out/quality", help="work directory (references cached in OUT/refs)")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--spp", default="4,16")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--denoise-args", default="", help="extra flags for atrous denoise")
    args = ap.parse_args(argv)
    spps = [int(s) for s in args.spp.split(",")]
    scenes = args.scenes.split(",")
    os.makedirs(os.path.join(args.out, "refs"), exist_ok=True)
    rows = []
    for scene in scenes:
        ref_dir = os.path.join(args.out, "refs", "%s-%d-%d" % (scene, args.size, args.ref_spp))
        if not os.path.exists(os.path.join(ref_dir, "color.exr")):
            print("rendering reference %s at %d spp ..." % (scene, args.ref_spp), flush=True)
            _, dt = run([args.atrous, "render", "--scene", scene, "--width", str(args.size), "--height", str(args.size),
                         "--spp", str(args.ref_spp), "--seed", "4099", "--out", ref_dir])
            print("  %.0f s" % dt, flush=True)
        for spp in spps:
            noisy_dir = os.path.join(args.out, "%s-%d-%d" % (scene, args.size, spp))
            run([args.atrous, "render", "--scene", scene, "--width", str(args.size), "--height", str(args.size),
                 "--spp", str(spp), "--seed", "1", "--out", noisy_dir])
            outs, times = {}, {}
            for m in (EAW, SURE):
                o = os.path.join(noisy_dir, "denoised-%s.exr" % m)
                text, _ = run([args.atrous, "denoise", "--in", noisy_dir, "--method", m, "--out", o]
                              + args.denoise_args.split())
                outs[m] = o
                for line in text.splitlines():
                    if "filter" in line and " ms" in line:
                        times[m] = float(line.split("filter")[1].split("ms")[0])
                    if "fireflies clamped" in line:
                        times["firefly"] = line.split("denoise: ")[1]
            text, _ = run([args.atrous, "compare", "--json", "--ref", os.path.join(ref_dir, "color.exr"),
                           os.path.join(noisy_dir, "color.exr"), outs[EAW], outs[SURE]])
            imgs = json.loads(text)["images"]
            row = {"scene": scene, "spp": spp, "noisy": imgs[0], EAW: imgs[1], SURE: imgs[2],
                   EAW + "_ms": times.get(EAW), SURE + "_ms": times.get(SURE), "firefly": times.get("firefly", "")}
            rows.append(row)
            print("%-16s %3d spp  MSE noisy %.4g  EAW %.4g (%.1fx)  SURE %.4g (%.1fx)  SURE/EAW %.2f" % (
                scene, spp, imgs[0]["mse"], imgs[1]["mse"], imgs[0]["mse"] / imgs[1]["mse"], imgs[2]["mse"],
                imgs[0]["mse"] / imgs[2]["mse"], imgs[1]["mse"] / imgs[2]["mse"]), flush=True)
    lines = []
    lines.append("Generated %s UTC on %s; `%s`; %dx%d, references %d spp (seed 4099), noisy seed 1." % (
        datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M"), cpu_model("unknown CPU"),
        " ".join(["python3"] + sys.argv), args.size, args.size, args.ref_spp))
    lines.append("")
    lines.append("| scene | spp | MSE noisy | MSE EAW | MSE SURE | noisy/EAW | EAW/SURE | relMSE noisy | relMSE EAW | relMSE SURE | SSIM EAW | SSIM SURE |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        n, e, s = r["noisy"], r[EAW], r[SURE]
        lines.append("| %s | %d | %.4g | %.4g | %.4g | %.1f× | %.2f× | %.4g | %.4g | %.4g | %.3f | %.3f |" % (
            r["scene"], r["spp"], n["mse"], e["mse"], s["mse"], n["mse"] / e["mse"], e["mse"] / s["mse"],
            n["relmse"], e["relmse"], s["relmse"], e["ssim"], s["ssim"]))
    lines.append("")
    for r in rows:
        if r["firefly"]:
            lines.append("- %s %d spp: %s" % (r["scene"], r["spp"], r["firefly"]))
    table = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "quality.md"), "w") as f:
        f.write(table)
    print()
    print(table)

