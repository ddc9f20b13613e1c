"""SVGF quality benchmark: SVGF vs per-frame EAW and SURE on animated scenes (docs/quality.md).

For each scene (NAME:CAMERA_PATH) it renders a 1-spp sequence with per-frame references
(`atrous render --frames F --spp 1 --reference-spp N`), denoises it with svgf, eaw and sure
(`atrous denoise --sequence`, or bench/svgf_sequence_tool where the CLI lacks --sequence), and
measures per frame
  relMSE    mean((x - r)^2 / (r^2 + 0.01))                       (atrous compare --json)
  temporal  relMSE of x_f - x_{f-1} against r_f - r_{f-1}        (docs/eval.md, "What is measured"; tool metrics)
  temporal_no_emitters  the same without the pixels that see a light (emission.exr > 0 in either
            frame, dilated by 1 px): at 1 spp their jittered edges flicker and dominate `temporal`
            unless the emission is accumulated (SVGF); this column is the rest of the image
Prints JSON (and writes it with --json), a Markdown section with --markdown, SVG plots with --plots.
Python's standard library, the CLI, and the atrous package for SVGF's name in the registry.
"""
import argparse
import json
import os
import subprocess
import sys
import time

from atrous.names import EAW, SURE, SVGF

METHODS = [SVGF, EAW, SURE]


def run(cmd, quiet=True):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.exit("command failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stdout))
    return r.stdout


def nice(cmd):
    return ["nice", "-n", "19"] + cmd


def has_sequence_flag(atrous):
    try:
        out = subprocess.run([atrous, "denoise", "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True).stdout
    except OSError:
        return False
    return "--sequence" in out


def mean(v):
    v = [x for x in v if x is not None]
    return sum(v) / len(v) if v else float("nan")


def svg_plot(path, title, series, key):
    """A small line plot (per frame, log-free, y from 0) written as plain SVG."""
    w, h, ml, mb, mt, mr = 520, 240, 60, 30, 24, 90
    colors = {"noisy": "#999999", SVGF: "#d62728", EAW: "#1f77b4", SURE: "#2ca02c"}
    ys = [y for s in series.values() for y in s[key] if y is not None]
    n = max(len(s[key]) for s in series.values())
    ymax = max(ys) * 1.05 if ys else 1.0
    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="11">' % (w, h),
           '<rect width="100%" height="100%" fill="white"/>',
           '<text x="%d" y="15">%s</text>' % (ml, title)]
    x0, y0, x1, y1 = ml, h - mb, w - mr, mt
    out.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' % (x0, y0, x1, y0))
    out.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' % (x0, y0, x0, y1))
    out.append('<text x="%d" y="%d">%.3g</text>' % (4, y1 + 4, ymax))
    out.append('<text x="%d" y="%d">0</text>' % (ml - 12, y0))
    out.append('<text x="%d" y="%d">frame</text>' % ((x0 + x1) // 2, h - 6))
    out.append('<text x="%d" y="%d">%d</text>' % (x1 - 8, y0 + 14, n - 1))
    for i, (name, s) in enumerate(series.items()):
        pts = ["%.1f,%.1f" % (x0 + (x1 - x0) * f / max(n - 1, 1), y0 - (y0 - y1) * min(v, ymax) / ymax)
               for f, v in enumerate(s[key]) if v is not None]
        c = colors.get(name, "black")
        out.append('<polyline fill="none" stroke="%s" stroke-width="1.5" points="%s"/>' % (c, " ".join(pts)))
        out.append('<text x="%d" y="%d" fill="%s">%s</text>' % (x1 + 8, y1 + 14 * (i + 1), c, name))
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def markdown(result, plots_rel):
    """The results as Markdown tables (summary, then every 4th frame per scene)."""
    sk = result["skip_frames"]
    out = ["| scene (camera) | method | mean relMSE, frames %d+ | mean temporal, frames %d+ | mean temporal without emitter pixels, frames %d+ |" % (sk, sk, sk),
           "|---|---|---|---|---|"]
    for sc in result["scenes"]:
        for k in ["noisy"] + METHODS:
            m = sc["methods"][k]
            out.append("| %s (%s) | %s | %.4f | %.3f | %.4f |" % (sc["scene"], sc["camera_path"], k, m["mean_relmse_after_skip"],
                                                                 m["mean_temporal_after_skip"], m["mean_temporal_no_emitters_after_skip"]))
    out.append("")
    for sc in result["scenes"]:
        out.append("SVGF below EAW in relMSE on %s of frames %d+ of %s (%s); temporal error without emitter pixels: "
                   "EAW / SVGF = %.1f (with them: %.2f)." % (sc["svgf_beats_eaw_frames"], sk, sc["scene"], sc["camera_path"],
                                                             sc["temporal_no_emitters_eaw_over_svgf"], sc["temporal_eaw_over_svgf"]))
        out.append("")
    for sc in result["scenes"]:
        n = len(sc["methods"][SVGF]["relmse"])
        out.append("Per frame, %s (%s camera): relMSE / temporal error without emitter pixels" % (sc["scene"], sc["camera_path"]))
        out.append("")
        out.append("| frame | " + " | ".join("%s relMSE" % k for k in ["noisy"] + METHODS) + " | " +
                   " | ".join("%s temporal" % k for k in METHODS) + " |")
        out.append("|---" * (1 + 4 + len(METHODS)) + "|")
        for f in list(range(0, n, 4)) + ([n - 1] if (n - 1) % 4 else []):
            cells = ["%.4f" % sc["methods"][k]["relmse"][f] for k in ["noisy"] + METHODS]
            t = [sc["methods"][k]["temporal_no_emitters"][f] for k in METHODS]
            cells += ["–" if v is None else "%.4f" % v for v in t]
            out.append("| %d | %s |" % (f, " | ".join(cells)))
        out.append("")
        if plots_rel:
            for key in ["relmse", "temporal_no_emitters"]:
                out.append("![%s %s](%s/svgf_%s_%s_%s.svg)" % (sc["scene"], key, plots_rel, sc["scene"], sc["camera_path"], key))
            out.append("")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m atrous.eval sequences", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--atrous", default="build/atrous", help="atrous CLI (default build/atrous)")
    ap.add_argument("--tool", default="build/bench/svgf_sequence_tool", help="bench/svgf_sequence_tool binary")
    ap.add_argument("--scenes", default="cornell:orbit,cornell-moving:static", help="NAME:CAMERA_PATH,...")
    ap.add_argument("--frames", type=int, default=32)
    ap.add_argument("--size", type=int, default=512, help="width = height")
    ap.add_argument("--reference-spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--work", default="out/svgf_quality", help="sequences and denoised frames go here")
    ap.add_argument("--reuse", action="store_true", help="keep already rendered sequences of the same settings")
    ap.add_argument("--reuse-baselines", action="store_true",
                    help="with --reuse: keep eaw/sure outputs already denoised from the same sequence (SVGF always re-runs)")
    ap.add_argument("--use-tool", action="store_true", help="denoise with --tool even when the CLI has --sequence")
    ap.add_argument("--svgf-args", default="", help="extra flags for the SVGF denoise, e.g. '--svgf-emission-alpha 1'")
    ap.add_argument("--svgf-tag", default="", help="suffix of the SVGF output directory (to keep variants apart)")
    ap.add_argument("--skip-frames", type=int, default=8, help="frames left out of the summary means (history warm-up)")
    ap.add_argument("--json", help="also write the JSON here")
    ap.add_argument("--plots", help="write svgf_<scene>_<path>_{relmse,temporal_no_emitters}.svg into this directory")
    ap.add_argument("--markdown", help="write the tables (Markdown) to this file")
    a = ap.parse_args(argv)

    use_cli = not a.use_tool and has_sequence_flag(a.atrous)
    result = {"benchmark": "svgf_quality", "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
              "machine": os.uname().nodename + " (" + str(os.cpu_count()) + " CPUs, CPU denoisers)",
              "frames": a.frames, "size": a.size, "spp": 1, "reference_spp": a.reference_spp,
              "denoise_via": "atrous denoise --sequence" if use_cli else "bench/svgf_sequence_tool denoise",
              "skip_frames": a.skip_frames, "svgf_args": a.svgf_args, "scenes": []}
    for spec in a.scenes.split(","):
        name, path = (spec.split(":") + ["auto"])[:2]  # the camera path: auto unless given
        seq = os.path.join(a.work, "%s_%s_%d" % (name, path, a.size))
        stamp = os.path.join(seq, "settings.json")
        settings = {"scene": name, "path": path, "frames": a.frames, "size": a.size, "ref": a.reference_spp, "seed": a.seed}
        t0 = time.time()
        fresh = not (a.reuse and os.path.exists(stamp) and json.load(open(stamp)) == settings)
        if fresh:
            run(nice([a.atrous, "render", "--scene", name, "--camera-path", path, "--frames", str(a.frames), "--spp", "1",
                      "--reference-spp", str(a.reference_spp), "--width", str(a.size), "--height", str(a.size),
                      "--seed", str(a.seed), "--out", seq]))
            json.dump(settings, open(stamp, "w"))
        render_s = time.time() - t0
        scene = {"scene": name, "camera_path": path, "render_seconds": round(render_s, 1), "methods": {}}
        outs = {}
        for m in METHODS:
            out = os.path.join(a.work, "%s_%s_%d_%s" % (name, path, a.size, m + (a.svgf_tag if m == SVGF else "")))
            outs[m] = out
            frames_in = sorted(d for d in os.listdir(seq) if d.startswith("frame_"))
            if m != SVGF and a.reuse_baselines and not fresh and \
                    all(os.path.exists(os.path.join(out, f + ".exr")) for f in frames_in):
                continue
            extra = a.svgf_args.split() if m == SVGF else []
            if use_cli:
                run(nice([a.atrous, "denoise", "--method", m, "--sequence", seq, "--out", out] + extra))
            else:
                run(nice([a.tool, "denoise", "--method", m, "--sequence", seq, "--out", out, "--quiet"] + extra))
        frames = sorted(d for d in os.listdir(seq) if d.startswith("frame_"))
        series = {k: {"relmse": [], "temporal": [], "temporal_no_emitters": []} for k in ["noisy"] + METHODS}
        for f in frames:
            imgs = [os.path.join(seq, f, "color.exr")] + [os.path.join(outs[m], f + ".exr") for m in METHODS]
            j = json.loads(run([a.atrous, "compare", "--json", "--ref", os.path.join(seq, f, "reference.exr")] + imgs))
            for k, im in zip(["noisy"] + METHODS, j["images"]):
                series[k]["relmse"].append(im["relmse"])
        # Temporal error: the tool reads OUTDIR/frame_NNNN.exr; give the noisy input the same layout.
        noisy = os.path.join(a.work, "%s_%s_%d_noisy" % (name, path, a.size))
        os.makedirs(noisy, exist_ok=True)
        for f in frames:
            link = os.path.join(noisy, f + ".exr")
            if not os.path.lexists(link):
                os.symlink(os.path.abspath(os.path.join(seq, f, "color.exr")), link)
        outs_all = dict(outs, noisy=noisy)
        for k in ["noisy"] + METHODS:
            t = json.loads(run([a.tool, "metrics", seq, outs_all[k]]))
            series[k]["temporal"] = [x["temporal"] for x in t]
            series[k]["temporal_no_emitters"] = [x["temporal_no_emitters"] for x in t]
        s = a.skip_frames
        for k in ["noisy"] + METHODS:
            scene["methods"][k] = {
                "relmse": series[k]["relmse"], "temporal": series[k]["temporal"],
                "temporal_no_emitters": series[k]["temporal_no_emitters"],
                "mean_relmse_after_skip": mean(series[k]["relmse"][s:]),
                "mean_temporal_after_skip": mean(series[k]["temporal"][s:]),
                "mean_temporal_no_emitters_after_skip": mean(series[k]["temporal_no_emitters"][s:])}
        sv, ea = series[SVGF]["relmse"][s:], series[EAW]["relmse"][s:]
        scene["svgf_beats_eaw_frames"] = "%d/%d" % (sum(1 for x, y in zip(sv, ea) if x < y), len(sv))
        scene["temporal_eaw_over_svgf"] = scene["methods"][EAW]["mean_temporal_after_skip"] / \
            scene["methods"][SVGF]["mean_temporal_after_skip"]
        scene["temporal_no_emitters_eaw_over_svgf"] = scene["methods"][EAW]["mean_temporal_no_emitters_after_skip"] / \
            scene["methods"][SVGF]["mean_temporal_no_emitters_after_skip"]
        if a.plots:
            os.makedirs(a.plots, exist_ok=True)
            for key in ["relmse", "temporal_no_emitters"]:
                svg_plot(os.path.join(a.plots, "svgf_%s_%s_%s.svg" % (name, path, key)),
                         "%s (%s camera): %s per frame" % (name, path, key), series, key)
        result["scenes"].append(scene)
        print("%s:%s done (render %.0f s)" % (name, path, render_s), file=sys.stderr)
    text = json.dumps(result, indent=1)
    if a.markdown:
        rel = os.path.relpath(a.plots, os.path.dirname(os.path.abspath(a.markdown))) if a.plots else None
        with open(a.markdown, "w") as f:
            f.write(markdown(result, rel) + "\n")
    if a.json:
        with open(a.json, "w") as f:
            f.write(text + "\n")
    print(text)

