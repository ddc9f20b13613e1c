#!/usr/bin/env python3
"""Quality per second (docs/quality.md, "Quality per second"): relMSE on the third-party corpus
(scripts/corpus/method_quality.py's JSON: geometric mean per renderer of relMSE / OIDN fast's)
against time per frame at 512² and 1080p (atrous.eval speed (python/atrous/eval/speed.py)'s JSON: `atrous bench` medians for
EAW, SURE, learned and blend, OIDN fast/balanced/high alternating in one process), for every atrous
method and OIDN's three quality modes. Writes a PNG and prints the points.

    .venv/bin/python scripts/corpus/quality_per_second.py --quality out/corpus/full/methods.json \\
        --speed out/bench/default_speed.json --out docs/images/quality_per_second.png
"""
import argparse
import json
import math

import numpy as np


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quality", required=True)
    ap.add_argument("--speed", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    q = json.load(open(a.quality))
    sp = json.load(open(a.speed))
    # The corpus's variant names -> the speed JSON's keys ("default" is blend with these buffers).
    names = {"eaw": "eaw_total_ms", "sure": "sure_total_ms", "learned": "learned_total_ms",
             "default": "blend_total_ms", "oidn_fast": "alt_oidn_fast_ms", "oidn_balanced": "alt_oidn_balanced_ms",
             "oidn_high": "alt_oidn_high_ms"}
    labels = {"default": "blend (default)", "oidn_fast": "OIDN fast", "oidn_balanced": "OIDN balanced",
              "oidn_high": "OIDN high", "eaw": "EAW", "sure": "SURE", "learned": "learned"}
    rows = q["rows"]
    renderers = sorted({r["renderer"] for r in rows})
    # Per renderer: Mitsuba's Gaussian-filtered renders are where OIDN does little, so one mean over
    # both renderers would flatter atrous.
    gm = {}
    for ren in renderers:
        rs = [r for r in rows if r["renderer"] == ren]
        gm[ren] = {n: math.exp(np.mean([math.log(r["relmse"][n] / r["relmse"]["oidn_fast"]) for r in rs]))
                   for n in names if all(n in r["relmse"] for r in rs)}
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    colors = {ren: c for ren, c in zip(renderers, ("tab:blue", "tab:orange", "tab:green"))}
    fig, axes = plt.subplots(1, len(sp["results"]), figsize=(5.6 * len(sp["results"]), 4.6))
    for ax, res in zip(np.atleast_1d(axes), sp["results"]):
        size = f"{res['width']}x{res['height']}"
        for ren in renderers:
            seen = {}
            for n, g in gm[ren].items():
                t = res.get(names[n])
                if t is None:
                    continue
                oidn = n.startswith("oidn")
                ax.scatter([t], [g], marker="s" if oidn else "o", color=colors[ren], s=36,
                           label=ren if n == "default" else None)
                k = (oidn, round(g, 3))
                dy = -10 * seen.get(k, 0)  # OIDN balanced and high coincide in quality: stack their labels
                seen[k] = seen.get(k, 0) + 1
                ax.annotate(labels[n], (t, g), textcoords="offset points", xytext=(5, 3 + dy), fontsize=7)
                print(f"{size} {ren} {labels[n]}: {t:.1f} ms, relMSE / OIDN fast {g:.3f} ({len([r for r in rows if r['renderer'] == ren])} stills)")
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(f"ms per {size} frame (CPU, {sp['machine']['cpu_count']} threads; circles atrous, squares OIDN)")
        ax.set_ylabel("relMSE / OIDN fast's (geometric mean over the stills)")
        ax.set_title(f"{size}: lower left is better", fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8, loc="upper center")
    fig.suptitle(f"Quality per second: third-party corpus stills (4 and 16 spp), {sp['date_utc'][:10]}", fontsize=10)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
