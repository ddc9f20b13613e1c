#!/usr/bin/env python3
"""The sequence denoiser's time per frame against the per-frame still method's, in one run.

    .venv/bin/python bench/sequence_speed.py --atrous build/atrous                  # 1920x1080, 12 frames
    .venv/bin/python bench/sequence_speed.py --size 1280x720 --frames 16 --runs 5 --out seq.json

Renders cornell-moving at 1 spp with every buffer (`atrous render --frames`, cached in
out/bench/seq/WxH_F), then alternates, --runs times after one untimed round, `atrous denoise
--sequence DIR` with each variant (default: the temporal method, what `--sequence` runs without
--method; and `--method auto`, the still method frame by frame). Each run's own summary line gives
the filter's milliseconds per frame and the wall milliseconds per frame (reading and writing
overlapped with filtering). One JSON document on stdout (and in --out): the medians, their
ratios to the per-frame method, the machine, the date and the commit. Run it on an idle machine.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import re
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

from atrous.eval.machine import cpu_model, emit, git_commit

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = {"temporal": [], "per_frame_auto": ["--method", "auto"]}


def run_once(atrous: str, seq: Path, out: Path, flags: list) -> dict:
    shutil.rmtree(out, ignore_errors=True)
    r = subprocess.run([atrous, "denoise", "--sequence", str(seq), "--out", str(out)] + flags,
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"sequence_speed: atrous denoise failed: {r.stdout}{r.stderr}")
    m = re.search(r"filter ([\d.]+) ms per frame, ([\d.]+) ms per frame in all", r.stdout)
    if not m:
        sys.exit("sequence_speed: no summary line in atrous's output:\n" + r.stdout)
    return {"filter_ms": float(m.group(1)), "wall_ms": float(m.group(2))}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--atrous", default=str(ROOT / "build" / "atrous"))
    ap.add_argument("--size", default="1920x1080")
    ap.add_argument("--frames", type=int, default=12)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", help="write the JSON here too")
    ap.add_argument("--variant", action="append", default=[], metavar="NAME=FLAGS",
                    help="also time `denoise --sequence` with these flags (e.g. static0=\"--temporal-static-radius 0\")")
    a = ap.parse_args()
    variants = dict(VARIANTS)
    for v in a.variant:
        name, flags = v.split("=", 1)
        variants[name] = flags.split()
    w, h = (int(v) for v in a.size.lower().split("x"))
    work = ROOT / "out" / "bench" / "seq"
    seq = work / f"{w}x{h}_{a.frames}"
    if not (seq / f"frame_{a.frames - 1:04d}" / "color.exr").exists():
        subprocess.run([a.atrous, "render", "--scene", "cornell-moving", "--width", str(w), "--height", str(h),
                        "--spp", "1", "--frames", str(a.frames), "--quiet", "--out", str(seq)], check=True,
                       capture_output=True)
    samples = {k: [] for k in variants}
    for run in range(a.runs + 1):
        for name, flags in variants.items():
            r = run_once(a.atrous, seq, work / f"out_{name}", flags)
            if run > 0:  # the first round warms the page cache and the CPU up
                samples[name].append(r)
    med = {k: {m: statistics.median(s[m] for s in v) for m in ("filter_ms", "wall_ms")} for k, v in samples.items()}
    base = med["per_frame_auto"]
    doc = {"what": "atrous denoise --sequence: ms per frame, the temporal method against the still method per frame "
                   "(bench/sequence_speed.py)",
           "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"), "cpu": cpu_model(),
           "device": "cpu", "commit": git_commit(), "size": [w, h], "frames": a.frames, "runs": a.runs,
           "median_ms_per_frame": med,
           "temporal_over_per_frame": {m: med["temporal"][m] / base[m] for m in ("filter_ms", "wall_ms")},
           "over_per_frame": {k: {m: med[k][m] / base[m] for m in ("filter_ms", "wall_ms")} for k in med},
           "samples": samples}
    emit(doc, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
