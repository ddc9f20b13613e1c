#!/usr/bin/env python3
"""Renders the third-party corpus (Mitsuba 3 + Blender Cycles; LuxCore in the training split) into
out/corpus/<mode>/.

    scripts/corpus/render.py --quick            # CI subset: 64x64, 2 stills + 4-frame sequence per renderer
    scripts/corpus/render.py --full             # the corpus: 256x256 stills, 2048-spp references, 20-frame sequences
    scripts/corpus/render.py --full --only mitsuba --scenes mi_glass,mi_orbit
    scripts/corpus/render.py --train            # the TRAINING split (tr_mi_NN, tr_cy_NN, tr_lx_NN) -> out/corpus/train/

Runs with any python3: it calls scripts/corpus/setup.sh (creates .venv-corpus once) and then runs
mitsuba_render.py and cycles_render.py (with --train: mitsuba_train.py, cycles_train.py and, where
pyluxcore installed, luxcore_train.py) inside .venv-corpus, one process per renderer. The LuxCore
test stills have their own script (luxcore_stills.py, docs/corpus.md). What already
exists is skipped, so a second run is quick and an interrupted run resumes.
"""
import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
VPY = ROOT / ".venv-corpus" / "bin" / "python"


def llvm_path():
    for p in ("/usr/lib/x86_64-linux-gnu/libLLVM-19.so", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
              "/usr/lib/llvm-19/lib/libLLVM.so"):
        if os.path.exists(p):
            return p
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="CI-sized subset (default)")
    g.add_argument("--full", action="store_true", help="the full corpus")
    g.add_argument("--train", action="store_true",
                   help="the training split (mitsuba_train.py, cycles_train.py): never the test scenes")
    ap.add_argument("--out", default=None, help="output root (default out/corpus/quick or out/corpus/full)")
    ap.add_argument("--only", choices=["mitsuba", "cycles", "luxcore"], help="one renderer")
    ap.add_argument("--scenes", default="", help="comma-separated scene names (default: all of the mode)")
    a = ap.parse_args()
    mode = "train" if a.train else "full" if a.full else "quick"
    out = Path(a.out) if a.out else ROOT / "out" / "corpus" / mode
    out.mkdir(parents=True, exist_ok=True)
    subprocess.run([str(HERE / "setup.sh")], check=True)
    env = dict(os.environ)
    if "DRJIT_LIBLLVM_PATH" not in env and llvm_path():
        env["DRJIT_LIBLLVM_PATH"] = llvm_path()
    t0 = time.time()
    for r in ("mitsuba", "cycles", "luxcore"):
        if a.only and a.only != r:
            continue
        if r == "luxcore":
            if mode != "train":
                continue
            if subprocess.run([str(VPY), "-c", "import pyluxcore"], capture_output=True).returncode:
                print("[corpus] luxcore: pyluxcore is not in .venv-corpus; no LuxCore training scenes", flush=True)
                continue
        script = f"{r}_train.py" if mode == "train" else f"{r}_render.py"
        cmd = ["nice", "-n", "10", str(VPY), str(HERE / script), "--out", str(out)]
        if mode != "train":
            cmd += ["--mode", mode]
        if a.scenes:
            cmd += ["--scenes", a.scenes]
        t = time.time()
        print(f"[corpus] {r}: {' '.join(cmd)}", flush=True)
        tail = []
        with subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True) as p:
            for line in p.stdout:  # Blender prints a line per sample: keep ours and errors
                tail = (tail + [line])[-60:]
                # ours: "HH:MM:SS mitsuba|cycles ..." (common.log), shown even before 10:00
                ours = re.match(r"\d\d:\d\d:\d\d (mitsuba|cycles|luxcore) ", line)
                if ours or not line.startswith(("Fra:", "0", " ")) or "rror" in line:
                    print(line, end="", flush=True)
        if p.returncode != 0:
            print("".join(tail), file=sys.stderr)
            sys.exit(f"[corpus] {r} failed (exit {p.returncode})")
        print(f"[corpus] {r} done in {time.time() - t:.1f}s", flush=True)
    print(f"[corpus] {mode} corpus in {out} ({time.time() - t0:.1f}s)", flush=True)


if __name__ == "__main__":
    main()
