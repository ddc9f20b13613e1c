#!/usr/bin/env python3
"""From file to file: `atrous denoise --in DIR` against the in-memory filter and OIDN, in one run.

    .venv/bin/python bench/file_to_file.py --atrous build/atrous                 # 512x512, 1920x1080, 3840x2160
    .venv/bin/python bench/file_to_file.py --sizes 1920x1080 --runs 7 --out f2f.json

For each size it renders the cornell scene at 4 spp with every buffer (`atrous render`, cached in
out/bench/f2f/WxH), then alternates, --runs times after one untimed round:

* ``atrous denoise --in DIR --method M --out OUT.exr`` for each method (eaw, sure, and the default:
  no --method), timed from the outside (wall clock of the process) with its peak resident memory
  (wait4), and its own log: read / filter / write milliseconds and the filter's stages;
* OIDN (pyoidn, colour + albedo + normal, HDR) at quality fast and high, in a child interpreter
  that reads the same three EXR files (atrous.read_image), denoises and writes the EXR: its
  read+denoise+write milliseconds (measured inside the child) and the child's wall clock and
  peak memory (interpreter start and imports included).

With --sequence it also renders a --frames-frame 1080p sequence and times `atrous denoise
--sequence` (per-frame wall against the filter's time per frame). It ends with `atrous bench
--json` at the same sizes (the filter alone, inputs in memory) so the ratio file-to-file /
in-memory is of one run. One JSON document on stdout (and in --out), with the machine, the date
and the commit. Run it on an idle machine: other processes' load is in every figure.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from atrous.eval.machine import cpu_model, emit, git_commit

ROOT = Path(__file__).resolve().parents[1]

# The OIDN child: reads the three files, denoises, writes; prints its own milliseconds.
OIDN_CHILD = r"""
import sys, time, json
t0 = time.perf_counter()
import numpy as np, pyoidn, atrous
t1 = time.perf_counter()
d, quality, out = sys.argv[1], sys.argv[2], sys.argv[3]
c = atrous.read_image(d + "/color.exr"); a = atrous.read_image(d + "/albedo.exr"); n = atrous.read_image(d + "/normal.exr")
t2 = time.perf_counter()
c = np.ascontiguousarray(np.maximum(np.nan_to_num(c, nan=0.0, posinf=0.0), 0.0), np.float32)
a = np.ascontiguousarray(np.clip(a, 0.0, 1.0), np.float32); n = np.ascontiguousarray(np.clip(n, -1.0, 1.0), np.float32)
r = pyoidn.denoise(c, a, n, hdr=True, quality=quality)
t3 = time.perf_counter()
atrous.write_image(out, r)
t4 = time.perf_counter()
print(json.dumps({"import_ms": (t1 - t0) * 1e3, "read_ms": (t2 - t1) * 1e3, "denoise_ms": (t3 - t2) * 1e3,
                  "write_ms": (t4 - t3) * 1e3, "total_ms": (t4 - t1) * 1e3}))
"""


def run_with_rss(cmd: list) -> dict:
    """Runs cmd with its peak resident memory measured by wait4 on that child alone."""
    r_fd, w_fd = os.pipe()
    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # the child: output into the pipe, then exec
        os.close(r_fd)
        os.dup2(w_fd, 1)
        os.dup2(w_fd, 2)
        try:
            os.execv(cmd[0], cmd)
        finally:
            os._exit(127)
    os.close(w_fd)
    chunks = []
    with os.fdopen(r_fd, "r") as f:
        for line in f:
            chunks.append(line)
    _, status, usage = os.wait4(pid, 0)
    wall = (time.perf_counter() - t0) * 1e3
    return {"rc": os.waitstatus_to_exitcode(status), "out": "".join(chunks), "wall_ms": wall,
            "peak_mb": usage.ru_maxrss / 1024.0}


def parse_denoise_log(out: str) -> dict:
    r = {}
    m = re.search(r"read ([\d.]+) ms, filter ([\d.]+) ms, total ([\d.]+) ms, write ([\d.]+) ms", out)
    if m:
        r.update(read_ms=float(m.group(1)), filter_ms=float(m.group(2)), call_ms=float(m.group(3)), write_ms=float(m.group(4)))
    m = re.search(r"stages ms: (.*)", out)
    if m:
        r["stages"] = {k.strip(): float(v) for k, v in (s.rsplit(" ", 1) for s in m.group(1).split(","))}
    m = re.search(r"method (?:auto -> )?(\S+)", out)  # without --method: "method auto -> blend (...)"
    if m:
        r["method_used"] = m.group(1)
    return r


def median_of(rows: list, key: str):
    vals = [r[key] for r in rows if key in r]
    return statistics.median(vals) if vals else None


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--atrous", default=str(ROOT / "build" / "atrous"))
    p.add_argument("--python", default=str(ROOT / ".venv" / "bin" / "python"), help="interpreter with pyoidn and atrous")
    p.add_argument("--sizes", default="512x512,1920x1080,3840x2160")
    p.add_argument("--methods", default="eaw,sure,default", help="comma list; 'default' runs without --method")
    p.add_argument("--runs", type=int, default=7)
    p.add_argument("--no-oidn", action="store_true")
    p.add_argument("--sequence", action="store_true", help="also time a 1080p sequence (--frames frames)")
    p.add_argument("--frames", type=int, default=8)
    p.add_argument("--work", default=str(ROOT / "out" / "bench" / "f2f"))
    p.add_argument("--out", help="also write the JSON here")
    a = p.parse_args(argv)
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    sizes = [tuple(int(v) for v in s.lower().split("x")) for s in a.sizes.split(",")]
    methods = a.methods.split(",")
    rows = []
    for w, h in sizes:
        d = work / f"{w}x{h}"
        if not (d / "color.exr").exists():
            subprocess.run([a.atrous, "render", "--scene", "cornell", "--width", str(w), "--height", str(h), "--spp", "4",
                            "--out", str(d)], check=True, capture_output=True)
        runs = {m: [] for m in methods}
        oidn = {q: [] for q in ("fast", "high")}
        for it in range(a.runs + 1):  # round 0 is the warm-up (page cache, first loads)
            for m in methods:
                cmd = [a.atrous, "denoise", "-v", "--in", str(d), "--out", str(work / f"out_{w}x{h}_{m}.exr")]  # -v: the stage times
                if m != "default":
                    cmd += ["--method", m]
                r = run_with_rss(cmd)
                if r["rc"] != 0:
                    sys.stderr.write(f"file_to_file: {' '.join(cmd)} failed: {r['out']}\n")
                    return 2
                row = {"wall_ms": r["wall_ms"], "peak_mb": r["peak_mb"], **parse_denoise_log(r["out"])}
                if it > 0:
                    runs[m].append(row)
            if a.no_oidn:
                continue
            for q in ("fast", "high"):
                r = run_with_rss([a.python, "-c", OIDN_CHILD, str(d), q, str(work / f"oidn_{w}x{h}_{q}.exr")])
                if r["rc"] != 0:
                    sys.stderr.write(f"file_to_file: OIDN {q} failed: {r['out']}\n")
                    return 2
                inner = json.loads(r["out"].strip().splitlines()[-1])
                if it > 0:
                    oidn[q].append({"wall_ms": r["wall_ms"], "peak_mb": r["peak_mb"], **inner})
        size_row = {"width": w, "height": h, "runs": a.runs, "atrous": {}, "oidn": {}}
        for m, rs in runs.items():
            entry = {k: median_of(rs, k) for k in ("wall_ms", "peak_mb", "read_ms", "filter_ms", "call_ms", "write_ms")}
            entry["method_used"] = rs[-1].get("method_used") if rs else None
            stages = [r["stages"] for r in rs if "stages" in r]
            if stages:
                entry["stages_ms"] = {k: statistics.median(s[k] for s in stages if k in s) for k in stages[0]}
            size_row["atrous"][m] = entry
        for q, rs in oidn.items():
            if rs:
                size_row["oidn"][q] = {k: median_of(rs, k) for k in ("wall_ms", "peak_mb", "read_ms", "denoise_ms", "write_ms",
                                                                     "total_ms", "import_ms")}
        rows.append(size_row)
    # The filter alone, inputs in memory (the same scene and sizes; cornell, 2 spp, seed 7).
    used = {e.get("method_used") or "sure" for row in rows for m, e in row["atrous"].items() if m == "default"}
    want = sorted(({m for m in methods if m != "default"} | used) & {"eaw", "sure", "learned", "blend"})
    bench = json.loads(subprocess.run([a.atrous, "bench", "--json", "--device", "cpu", "--what", ",".join(want), "--sizes",
                                       a.sizes], check=True, capture_output=True, text=True).stdout)
    for row in rows:
        for r in bench["results"]:
            if (r["width"], r["height"]) != (row["width"], row["height"]):
                continue
            for m, e in row["atrous"].items():
                if r["what"] == (m if m != "default" else (e.get("method_used") or "sure")):
                    e["in_memory_ms"] = r["total_ms"]
                    if e.get("wall_ms"):
                        e["wall_over_in_memory"] = e["wall_ms"] / r["total_ms"]
    doc = {"what": "file to file: atrous denoise --in DIR vs the in-memory filter vs OIDN (bench/file_to_file.py)",
           "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"), "cpu": cpu_model(),
           "device": bench.get("device_name"), "commit": git_commit(), "sizes": rows}
    if a.sequence:
        seq = work / "seq1080"
        if not (seq / f"frame_{a.frames - 1:04d}").exists():
            subprocess.run([a.atrous, "render", "--scene", "cornell-moving", "--width", "1920", "--height", "1080", "--spp", "4",
                            "--frames", str(a.frames), "--out", str(seq)], check=True, capture_output=True)
        r = run_with_rss([a.atrous, "denoise", "--method", "eaw", "--sequence", str(seq), "--out", str(work / "seq_out")])
        m = re.search(r"filter ([\d.]+) ms per frame, ([\d.]+) ms per frame in all", r["out"])
        if r["rc"] == 0 and m:
            doc["sequence_1080p_eaw"] = {"frames": a.frames, "filter_ms_per_frame": float(m.group(1)),
                                         "wall_ms_per_frame": float(m.group(2)), "peak_mb": r["peak_mb"],
                                         "ratio": float(m.group(2)) / float(m.group(1))}
    emit(doc, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
