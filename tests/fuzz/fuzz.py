#!/usr/bin/env python3
"""atrous fuzz harness (docs/reliability.md): seeded, reproducible mutations of every input format
(EXR, PFM, PNG, HDR, scene JSON, OBJ/MTL, sequences, buffer sizes) and every numeric flag of
`atrous render` and `atrous denoise`; other renderers' layered EXRs (class layered), --pass/--layer/
--add-pass on every path (pass-flag), sequences in every layout (seq-layout), oidnDenoise's flags
(oidn) and learned-weight files (weights); plus Python-binding cases. Each case runs with its
peak memory measured and its input files hashed before and after, and is classified as

  ok              exit 0, every output present and finite
  clean           exit 2, one stderr line naming the file (or flag) at fault, nothing written
  crash           a signal, exit >= 128, or a sanitizer report
  hang            past the time limit
  wrong-code      any other exit code (or, in Python, an exception other than ValueError/TypeError)
  bad-message     exit 2, but the message is not one line or does not name the file or flag
  partial-output  exit 2 with files left in the output location
  nan-inf         exit 0 with a NaN or Inf in an output image
  accepted-bad    exit 0 on an input the rules say is bad (out-of-range value, truncated file, ...),
                  or a flag that cannot apply to the input, ignored
  memory          a peak resident set above 300 MB while the case's input files total under 1 MB
                  (the child's own ru_maxrss from os.wait4), or killed at --mem-cap
  input-modified  an input file changed or removed (an output written over an input)
  wrong-output    exit 0 but an output is wrong where the harness can tell: a layered file's
                  colour exported elsewhere than its data window says, an --add-pass copy that
                  lost or changed a channel, an --ldr output outside [0, 1]
  refused-good    exit 2 on an input the harness built valid (a plain Blender/Mitsuba file, ...)

Only the standard library is needed (EXRs are written and decoded here, fuzz_exr.py). Usage:

  tests/fuzz/fuzz.py --cli build/atrous --cases 3000 --seed 1      # full campaign
  tests/fuzz/fuzz.py --cli build/atrous --ci                        # the CI subset (make test)

Exit status 0 when no case is in a failure class. --keep keeps the work directory; a failing case
prints its command line, and `--only ID` (with the same --seed, --classes and, for a Python case
pyN, --python-cases) reruns one case.
The summary gives each class's largest peak memory and the case it came from.
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
# fuzz_exr (EXR writer/reader), fuzz_proc (the watched run: peak memory, limits, input hashes),
# fuzz_layered, fuzz_seqs, fuzz_flags (the new input paths' classes),
# fuzz_cases (classes, building, running and classifying CLI cases), fuzz_python (Python-binding
# cases). The names tests/python/test_fuzz.py uses are imported here too.
from fuzz_cases import CLASSES, FAILURES, KLASSES, KNOWN, Case, build_case, run_case
from fuzz_files import make_seeds, write_pfm, write_png  # noqa: F401
import fuzz_proc
from fuzz_proc import close_spawners
from fuzz_python import python_cases, run_python_cases

# ------------------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default="build/atrous")
    ap.add_argument("--cases", type=int, default=2000, help="CLI cases (spread over the input classes)")
    ap.add_argument("--python-cases", type=int, default=None, help="Python-binding cases (default: cases / 6)")
    ap.add_argument("--python", default=None, help="interpreter with atrous and numpy (default: .venv/bin/python)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--ci", action="store_true", help="the CI subset: 40 CLI cases per class, 60 Python cases, seed 14")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per case before it counts as a hang")
    ap.add_argument("--only", default=None, help="run this case only: a CLI case's id, or pyN for Python case N")
    ap.add_argument("--classes", default=",".join(KLASSES))
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--show", type=int, default=40, help="failures printed in full")
    ap.add_argument("--json", default=None, help="write the summary here")
    ap.add_argument("--mem-cap", type=float, default=1024, help="MB: a case past this is killed (class memory)")
    ap.add_argument("--mem-limit", type=float, default=None,
                    help="MB a case with under 1 MB of input may peak at (default 300; 900 for a sanitizer build)")
    a = ap.parse_args()
    if a.ci:
        a.cases, a.seed = 40 * len(a.classes.split(",")), 14
        if a.python_cases is None:
            a.python_cases = 60
    if a.python_cases is None:
        a.python_cases = a.cases // 6
    cli = os.path.abspath(a.cli)
    if a.mem_limit is None:  # ASan's shadow memory and quarantine roughly triple a process's resident set
        sanitized = os.path.isfile(cli) and b"__asan_init" in open(cli, "rb").read()
        a.mem_limit = 900 if sanitized else 300
        if sanitized:
            print("fuzz: %s is a sanitizer build: memory limit %d MB" % (cli, a.mem_limit))
    fuzz_proc.MEMORY_LIMIT_MB = a.mem_limit
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
        logs = os.path.join(work, "logs")
        os.makedirs(logs)
        for i in range(a.cases):
            k = klasses[i % len(klasses)]
            crng = random.Random("%d/%d" % (a.seed, i))  # each case reproducible on its own
            if a.only is not None and str(i) != a.only:
                continue
            # ordinal: the case's number inside its class (the new classes take their kind from it)
            cases.append(build_case(i, crng, seeds, work, cli, k, i // len(klasses), a.seed))
        counts = {c: 0 for c in CLASSES}
        per_class = {}
        peaks, peaks_ok = {}, {}  # per class: the largest peak, and the largest of cases not in a failure class
        failures = []
        with cf.ThreadPoolExecutor(max_workers=a.jobs) as ex:
            futs = {ex.submit(run_case, c, a.timeout, env, a.mem_cap, logs): c for c in cases}
            for f in cf.as_completed(futs):
                c = futs[f]
                cls, why, el, peak = f.result()
                counts[cls] += 1
                per_class.setdefault(c.klass, {}).setdefault(cls, 0)
                per_class[c.klass][cls] += 1
                if peak > peaks.get(c.klass, (0, None))[0]:
                    peaks[c.klass] = (peak, c.id)
                if cls not in FAILURES and peak > peaks_ok.get(c.klass, (0, None))[0]:
                    peaks_ok[c.klass] = (peak, c.id)
                if cls in FAILURES:
                    failures.append((c, cls, why))
        pcounts = {}
        if a.python_cases and (a.only is None or a.only.startswith("py")):
            if os.path.exists(py) and subprocess.run([py, "-c", "import atrous, numpy"], capture_output=True).returncode == 0:
                pc = python_cases(rng, a.python_cases, work, seeds)
                if a.only is not None:
                    pc = [c for c in pc if "py%d" % c["id"] == a.only]
                res = run_python_cases(py, pc, a.timeout, a.mem_cap)
                for c in pc:
                    s, why, peak = res[c["id"]]
                    pcounts[s] = pcounts.get(s, 0) + 1
                    counts[s] = counts.get(s, 0) + 1
                    key = "python:" + c["kind"]
                    if peak > peaks.get(key, (0, None))[0]:
                        peaks[key] = (peak, "py%d" % c["id"])
                    if s not in FAILURES and peak > peaks_ok.get(key, (0, None))[0]:
                        peaks_ok[key] = (peak, "py%d" % c["id"])
                    if s in FAILURES:
                        failures.append((Case("py%d" % c["id"], "python", [c["kind"], repr(c["args"])[:300]], [], [],
                                              note=c.get("note", "")), s, why))
            else:
                print("fuzz: %s has no atrous module: Python-binding cases skipped" % py)
        elapsed = time.time() - t0
        total = sum(counts.values())
        print("atrous fuzz: seed %d, %d cases (%d CLI over %d input classes, %d Python) in %.0f s" %
              (a.seed, total, len(cases), len(set(c.klass for c in cases)), sum(pcounts.values()), elapsed))
        print("  " + ", ".join("%s %d" % (k, counts.get(k, 0)) for k in CLASSES) +
              (", skipped %d (an optional module missing)" % counts["skip"] if counts.get("skip") else ""))
        for k in sorted(per_class):
            print("  %-13s %s" % (k, ", ".join("%s %d" % (c, n) for c, n in sorted(per_class[k].items()))))
        if pcounts:
            print("  %-13s %s" % ("python", ", ".join("%s %d" % (c, n) for c, n in sorted(pcounts.items()))))
        print("  peak memory (MB, case): " + ", ".join("%s %.0f (%s)" % (k, v[0], v[1]) for k, v in sorted(peaks.items())))
        if peaks_ok != peaks:
            print("  of cases not failing:   " + ", ".join("%s %.0f (%s)" % (k, v[0], v[1]) for k, v in
                                                          sorted(peaks_ok.items()) if peaks.get(k) != v))
        if counts.get("known"):
            print("  known (open, not failures): " + "; ".join(k[2] for k in KNOWN))
        failures.sort(key=lambda t: (t[1], t[0].klass, str(t[0].id)))
        for c, cls, why in failures[:a.show]:
            print("FAIL %s [%s %s] %s: %s\n     %s" % (cls, c.klass, c.id, c.note, why,
                                                     " ".join(repr(x) if " " in x or not x else x for x in c.argv)))
        if len(failures) > a.show:
            print("... and %d more failures (--show N, --json FILE)" % (len(failures) - a.show))
        if a.json:
            json.dump({"seed": a.seed, "cases": total, "counts": counts, "per_class": per_class, "python": pcounts,
                       "seconds": round(elapsed, 1), "peak_mb": {k: [round(v[0], 1), v[1]] for k, v in peaks.items()},
                       "peak_mb_not_failing": {k: [round(v[0], 1), v[1]] for k, v in peaks_ok.items()},
                       "failures": [{"id": c.id, "class": cls, "klass": c.klass, "note": c.note, "why": why,
                                     "argv": c.argv} for c, cls, why in failures]},
                      open(a.json, "w"), indent=1)
        return 1 if failures else 0
    finally:
        close_spawners()
        if a.keep:
            print("fuzz: work directory kept: " + work)
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
