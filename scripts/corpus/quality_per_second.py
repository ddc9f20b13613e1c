#!/usr/bin/env python3
"""Quality per second (docs/quality.md, "Quality per second"): relMSE on the third-party corpus
(scripts/corpus/method_quality.py's JSON: geometric mean over every still of relMSE / OIDN fast's)
against time per frame at 512² and 1080p (bench/learned_speed.py's JSON: `atrous bench` medians for
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
    gm = {n: math.exp(np.mean([math.log(r["relmse"][n] / r["relmse"]["oidn_fast"]) for r in rows]))
          for n in names if all(n in r["relmse"] for r in rows)}
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(sp["results"]), figsize=(5.2 * len(sp["results"]), 4.2))
    for ax, res in zip(np.atleast_1d(axes), sp["results"]):
        size = f"{res['width']}x{res['height']}"
        for n, g in gm.items():
            t = res.get(names[n])
            if t is None:
                continue
            oidn = n.startswith("oidn")
            ax.scatter([t], [g], marker="s" if oidn else "o", color="tab:gray" if oidn else "tab:blue", s=40)
            ax.annotate(labels[n], (t, g), textcoords="offset points", xytext=(5, 4), fontsize=8)
            print(f"{size} {labels[n]}: {t:.1f} ms, relMSE / OIDN fast {g:.3f}")
        ax.set_xscale("log")
        ax.set_xlabel(f"ms per {size} frame (CPU, {sp['machine']['cpu_count']} threads)")
        ax.set_ylabel("relMSE / OIDN fast (geometric mean, %d stills)" % len(rows))
        ax.set_title(f"{size}: lower left is better")
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"Quality per second: third-party corpus (Cycles, Mitsuba), {sp['date_utc'][:10]}", fontsize=10)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
