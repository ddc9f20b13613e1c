#!/usr/bin/env python3
"""Benchmark of atrous.farm: items per minute with 1 and 2 local Ray workers, the scaling, and the
overhead per item against the bare CLI (`atrous render`, one process per item). Prints JSON.

    .venv/bin/python bench/farm_bench.py [--cli build/atrous] [--runs 3] [--items 16]

For each item size (tiny: 32x32 at 2 spp, where the overhead dominates; medium: 128x128 at
64 spp) a render job of --items items (cornell, seeds 1..N) runs through the farm on a local Ray
instance of 1 and of 2 CPUs (ray.init(num_cpus=W): W worker processes run items at once), each
item reserving one CPU and rendering with one thread. Ray is started once per worker count and
a warm-up job runs first (worker processes start and import atrous); each timed job writes into
a fresh directory (a rerun into the same one would skip every item). Figures are medians of
--runs runs. The CLI baseline runs the same items one after the other as `atrous render
--threads 1 ...` processes; overhead per item = farm seconds per item (1 worker) - CLI seconds per
item. Ray's own start (ray.init) is reported apart: a job pays it once.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from atrous.eval.machine import cpu_model

REPO = Path(__file__).resolve().parents[1]
SIZES = {"tiny": {"width": 32, "height": 32, "spp": 2}, "medium": {"width": 128, "height": 128, "spp": 64}}


def _mem_gib() -> float:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                return round(int(line.split()[1]) / 2 ** 20, 1)
    except OSError:
        pass
    return 0.0


def farm_job(tmp: Path, size: dict, items: int) -> float:
    import atrous.farm

    out = Path(tempfile.mkdtemp(dir=tmp))
    t0 = time.perf_counter()
    res = atrous.farm.render(out, ["cornell"], [size["spp"]], width=size["width"], height=size["height"],
                             seeds=list(range(1, items + 1)), progress=False)
    dt = time.perf_counter() - t0
    if not res.ok or len(res.done) != items:
        raise SystemExit(f"farm_bench: the job failed: {res.failed[:1]}")
    shutil.rmtree(out)
    return dt


def cli_items(cli: str, tmp: Path, size: dict, items: int) -> float:
    out = Path(tempfile.mkdtemp(dir=tmp))
    t0 = time.perf_counter()
    for seed in range(1, items + 1):
        r = subprocess.run([cli, "render", "--scene", "cornell", "--width", str(size["width"]), "--height",
                            str(size["height"]), "--spp", str(size["spp"]), "--seed", str(seed), "--threads", "1",
                            "--device", "cpu", "--quiet", "--out", str(out / f"cornell_spp{size['spp']}_seed{seed}")],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit(f"farm_bench: {cli} render failed: {r.stderr.strip()}")
    dt = time.perf_counter() - t0
    shutil.rmtree(out)
    return dt


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cli", default=os.environ.get("ATROUS_CLI") or str(REPO / "build" / "atrous"))
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--items", type=int, default=16)
    p.add_argument("--sizes", default="tiny,medium")
    a = p.parse_args()
    if not os.access(a.cli, os.X_OK):
        print(f"farm_bench: {a.cli}: no atrous CLI there (build it, or give --cli)", file=sys.stderr)
        return 2
    sizes = [s for s in a.sizes.split(",") if s]
    bad = [s for s in sizes if s not in SIZES]
    if bad or a.runs < 1 or a.items < 2:
        print(f"farm_bench: bad --sizes/--runs/--items ({bad or (a.runs, a.items)})", file=sys.stderr)
        return 2
    import ray

    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    tmp = Path(tempfile.mkdtemp(prefix="farm-bench-"))
    result = {
        "benchmark": "atrous.farm render job vs the bare CLI",
        "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "command": "python bench/farm_bench.py " + " ".join(sys.argv[1:]),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(), "memory_gib": _mem_gib(),
                    "python": platform.python_version(), "ray": ray.__version__},
        "load_average_before": [round(x, 2) for x in os.getloadavg()],
        "items_per_job": a.items, "runs": a.runs, "sizes": {}, "ray_init_s": {},
    }
    try:
        per_workers = {}
        for workers in (1, 2):
            t0 = time.perf_counter()
            ray.init(num_cpus=workers, include_dashboard=False, logging_level="ERROR", log_to_driver=False)
            result["ray_init_s"][str(workers)] = round(time.perf_counter() - t0, 3)
            per_workers[workers] = {}
            for s in sizes:
                farm_job(tmp, SIZES[s], workers * 2)  # warm-up: the worker processes start and import atrous
                per_workers[workers][s] = [farm_job(tmp, SIZES[s], a.items) for _ in range(a.runs)]
            ray.shutdown()
        for s in sizes:
            cli_items(a.cli, tmp, SIZES[s], 2)  # warm-up (page cache)
            cli = [cli_items(a.cli, tmp, SIZES[s], a.items) for _ in range(a.runs)]
            one, two = (statistics.median(per_workers[w][s]) for w in (1, 2))
            cli_m = statistics.median(cli)
            result["sizes"][s] = {
                **SIZES[s],
                "farm_1_worker_s": [round(x, 3) for x in per_workers[1][s]],
                "farm_2_workers_s": [round(x, 3) for x in per_workers[2][s]],
                "cli_sequential_s": [round(x, 3) for x in cli],
                "items_per_min_1_worker": round(a.items / one * 60, 1),
                "items_per_min_2_workers": round(a.items / two * 60, 1),
                "scaling_2_vs_1": round(one / two, 3),
                "cli_items_per_min": round(a.items / cli_m * 60, 1),
                "farm_s_per_item_1_worker": round(one / a.items, 4),
                "cli_s_per_item": round(cli_m / a.items, 4),
                "overhead_per_item_s": round((one - cli_m) / a.items, 4),
            }
    finally:
        if ray.is_initialized():
            ray.shutdown()
        shutil.rmtree(tmp, ignore_errors=True)
    result["load_average_after"] = [round(x, 2) for x in os.getloadavg()]
    print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
