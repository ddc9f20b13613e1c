#!/usr/bin/env python3
"""atrous fuzz harness (docs/reliability.md): seeded, reproducible mutations of every input format
(EXR, PFM, PNG, HDR, scene JSON, OBJ/MTL, sequences, buffer sizes) and every numeric flag of
`atrous render` and `atrous denoise`, plus Python-binding cases, each classified as

  ok              exit 0, every output present and finite
  clean           exit 2, one stderr line naming the file (or flag) at fault, nothing written
  crash           a signal, exit >= 128, or a sanitizer report
  hang            past the time limit
  wrong-code      any other exit code (or, in Python, an exception other than ValueError/TypeError)
  bad-message     exit 2, but the message is not one line or does not name the file or flag
  partial-output  exit 2 with files left in the output location
  nan-inf         exit 0 with a NaN or Inf in an output image
  accepted-bad    exit 0 on an input the rules say is bad (out-of-range value, truncated file, ...)

Only the standard library is needed (EXR outputs are decoded here: ZIP/none, as atrous writes
them). Usage:

  tests/fuzz/fuzz.py --cli build/atrous --cases 2000 --seed 1      # full campaign
  tests/fuzz/fuzz.py --cli build/atrous --ci                        # the CI subset (make test)

Exit status 0 when no case is in a failure class. --keep keeps the work directory; a failing case
prints its command line, and `--only ID` reruns one case.
"""
import argparse
import concurrent.futures as cf
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

# The parts: fuzz_files (output checks, seed files), fuzz_mutate (mutations, flag rules),
# fuzz_cases (classes, building, running and classifying CLI cases), fuzz_python (Python-binding
# cases). The names tests/python/test_fuzz.py uses are imported here too.
from fuzz_cases import CLASSES, FAILURES, KLASSES, KNOWN, Case, build_case, run_case
from fuzz_files import make_seeds, write_pfm, write_png  # noqa: F401
from fuzz_python import python_cases, run_python_cases

# ------------------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default="build/atrous")
    ap.add_argument("--cases", type=int, default=2000, help="CLI cases (spread over the input classes)")
    ap.add_argument("--python-cases", type=int, default=None, help="Python-binding cases (default: cases / 6)")
    ap.add_argument("--python", default=None, help="interpreter with atrous and numpy (default: .venv/bin/python)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--ci", action="store_true", help="the CI subset: 330 CLI cases, 60 Python cases, seed 14")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per case before it counts as a hang")
    ap.add_argument("--only", type=int, default=None, help="run this case id only")
    ap.add_argument("--classes", default=",".join(KLASSES))
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--json", default=None, help="write the summary here")
    a = ap.parse_args()
    if a.ci:
        a.cases, a.seed = 330, 14
        if a.python_cases is None:
            a.python_cases = 60
    if a.python_cases is None:
        a.python_cases = a.cases // 6
    cli = os.path.abspath(a.cli)
    here = os.path.dirname(os.path.abspath(__file__))
    py = a.python or os.path.join(here, "..", "..", ".venv", "bin", "python")
    work = tempfile.mkdtemp(prefix="atrous_fuzz_")
    env = dict(os.environ)
    env.setdefault("ASAN_OPTIONS", "detect_leaks=0:abort_on_error=0")
    t0 = time.time()
    try:
        seeds = make_seeds(cli, work)
        rng = random.Random(a.seed)
        klasses = a.classes.split(",")
        cases = []
        for i in range(a.cases):
            k = klasses[i % len(klasses)]
            crng = random.Random("%d/%d" % (a.seed, i))  # each case reproducible on its own
            if a.only is not None and i != a.only:
                continue
            cases.append(build_case(i, crng, seeds, work, cli, k))
        counts = {c: 0 for c in CLASSES}
        per_class = {}
        failures = []
        with cf.ThreadPoolExecutor(max_workers=a.jobs) as ex:
            futs = {ex.submit(run_case, c, a.timeout, env): c for c in cases}
            for f in cf.as_completed(futs):
                c = futs[f]
                cls, why, el = f.result()
                counts[cls] += 1
                per_class.setdefault(c.klass, {}).setdefault(cls, 0)
                per_class[c.klass][cls] += 1
                if cls in FAILURES:
                    failures.append((c, cls, why))
        pcounts = {}
        if a.python_cases and a.only is None:
            if os.path.exists(py) and subprocess.run([py, "-c", "import atrous, numpy"], capture_output=True).returncode == 0:
                pc = python_cases(rng, a.python_cases, work)
                res = run_python_cases(py, pc, a.timeout)
                for c in pc:
                    s = res[c["id"]]
                    pcounts[s] = pcounts.get(s, 0) + 1
                    counts[s] = counts.get(s, 0) + 1
                    if s in FAILURES:
                        failures.append((Case("py%d" % c["id"], "python", [c["kind"], repr(c["args"])], [], []), s, ""))
            else:
                print("fuzz: %s has no atrous module: Python-binding cases skipped" % py)
        elapsed = time.time() - t0
        total = sum(counts.values())
        print("atrous fuzz: seed %d, %d cases (%d CLI over %d input classes, %d Python) in %.0f s" %
              (a.seed, total, len(cases), len(set(c.klass for c in cases)), sum(pcounts.values()), elapsed))
        print("  " + ", ".join("%s %d" % (k, counts.get(k, 0)) for k in CLASSES))
        for k in sorted(per_class):
            print("  %-13s %s" % (k, ", ".join("%s %d" % (c, n) for c, n in sorted(per_class[k].items()))))
        if pcounts:
            print("  %-13s %s" % ("python", ", ".join("%s %d" % (c, n) for c, n in sorted(pcounts.items()))))
        if counts.get("known"):
            print("  known (open, not failures): " + "; ".join(k[2] for k in KNOWN))
        for c, cls, why in failures[:40]:
            print("FAIL %s [%s %s] %s: %s\n     %s" % (cls, c.klass, c.id, c.note, why,
                                                     " ".join(repr(x) if " " in x or not x else x for x in c.argv)))
        if a.json:
            json.dump({"seed": a.seed, "cases": total, "counts": counts, "per_class": per_class, "python": pcounts,
                       "seconds": round(elapsed, 1)}, open(a.json, "w"), indent=1)
        return 1 if failures else 0
    finally:
        if a.keep:
            print("fuzz: work directory kept: " + work)
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
