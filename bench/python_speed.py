#!/usr/bin/env python3
"""A still filter through Python against the same filter in `atrous bench` and against OIDN high,
in one run (issue 31's bars: from Python at most 1.1x the CLI bench's time, and at least 8x faster
than OIDN high, at 512x512 on this machine).

    .venv/bin/python bench/python_speed.py --atrous build/atrous            # EAW at 512x512
    .venv/bin/python bench/python_speed.py --methods eaw,sure --rounds 7 --out python_speed.json

Each round runs, one after the other: `atrous bench --json --what M --sizes S --runs R` (a process:
the filter alone on the scene's 2-spp buffers with every buffer, seed 7, inputs in place: its
median), then R calls of ``atrous.denoise(color, method=M, device="cpu", **every buffer)`` on the
same buffers rendered through Python (atrous.render, the same scene, spp and seed), then R calls of
OIDN high (pyoidn's Filter, committed once, ``execute()`` timed). Each figure is the median over
the rounds of the round's median. One JSON document on stdout (and in --out): the medians, the
ratios, the machine, the date and the commit. Run it on an idle machine.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import statistics
import subprocess
import time
from pathlib import Path


from atrous.eval.machine import cpu_model, emit, git_commit
from atrous.eval.speed import _oidn_filter  # an OIDN RT filter bound and committed once

ROOT = Path(__file__).resolve().parents[1]
BUFFERS = ("albedo", "normal", "position", "depth", "ids", "variance", "emission")


def timed(f, runs: int, warmup: int) -> float:
    for _ in range(warmup):
        f()
    ts = []
    for _ in range(runs):
        t = time.perf_counter()
        f()
        ts.append((time.perf_counter() - t) * 1e3)
    return statistics.median(ts)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--atrous", default=str(ROOT / "build" / "atrous"), help="the atrous CLI (default build/atrous)")
    p.add_argument("--methods", default="eaw", help="comma list of still methods (default eaw)")
    p.add_argument("--size", default="512x512", help="WxH (default 512x512)")
    p.add_argument("--rounds", type=int, default=5, help="alternating rounds (default 5)")
    p.add_argument("--runs", type=int, default=20, help="timed calls per figure and round (default 20)")
    p.add_argument("--warmup", type=int, default=3, help="untimed calls first, each figure and round (default 3)")
    p.add_argument("--scene", default="cornell")
    p.add_argument("--no-oidn", action="store_true", help="leave OIDN out")
    p.add_argument("--out", help="also write the JSON here")
    a = p.parse_args(argv)
    if a.rounds < 1 or a.runs < 1 or a.warmup < 0:
        p.error("--rounds and --runs must be >= 1, --warmup >= 0")
    w, h = (int(v) for v in a.size.lower().split("x"))
    import atrous

    b = atrous.render(a.scene, width=w, height=h, spp=2, seed=7)
    feats = {k: b[k] for k in BUFFERS if b.get(k) is not None}
    methods = [m for m in a.methods.split(",") if m]
    oidn = None
    if not a.no_oidn:
        import pyoidn
        from atrous.eval import oidn_inputs

        color, albedo, normal = oidn_inputs(b)
        dev = pyoidn.Device()
        dev.commit()
        oidn, result = _oidn_filter(pyoidn, dev, color, albedo, normal, pyoidn.OIDN_QUALITY_HIGH)  # result: kept alive
    per = {m: {"cli": [], "python": []} for m in methods}
    oidn_ms, device_name = [], ""
    for _ in range(a.rounds):
        for m in methods:
            r = subprocess.run([a.atrous, "bench", "--json", "--device", "cpu", "--what", m, "--sizes", a.size,
                                "--scene", a.scene, "--runs", str(a.runs), "--warmup", str(a.warmup)],
                               capture_output=True, text=True, check=True)
            doc = json.loads(r.stdout)
            device_name = doc.get("device_name", "")
            per[m]["cli"].append(doc["results"][0]["median_ms"])
            per[m]["python"].append(timed(lambda: atrous.denoise(b["color"], method=m, device="cpu", **feats),
                                          a.runs, a.warmup))
        if oidn is not None:
            oidn_ms.append(timed(oidn.execute, a.runs, a.warmup))
    out = {"benchmark": "python_speed", "device": "cpu", "device_name": device_name, "cpu": cpu_model(),
           "size": a.size, "scene": a.scene, "spp": 2, "seed": 7, "rounds": a.rounds, "runs": a.runs,
           "warmup": a.warmup, "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
           "commit": git_commit(), "methods": {}}
    oidn_med = statistics.median(oidn_ms) if oidn_ms else None
    if oidn_med is not None:
        out["oidn_high_ms"] = oidn_med
    for m in methods:
        cli, py = statistics.median(per[m]["cli"]), statistics.median(per[m]["python"])
        row = {"cli_bench_ms": cli, "python_ms": py, "python_over_cli": py / cli,
               "cli_rounds_ms": per[m]["cli"], "python_rounds_ms": per[m]["python"]}
        if oidn_med is not None:
            row["oidn_high_over_python"] = oidn_med / py
        out["methods"][m] = row
    emit(out, a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
