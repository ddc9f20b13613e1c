"""The fuzz harness's Python-binding cases (fuzz.py, tests/python/test_fuzz.py): seeded calls of the
atrous module, run in child interpreters so that a crash marks its case instead of ending the run."""
import json
import math
import os
import subprocess

from fuzz_mutate import FLOAT_SPECIALS

# ------------------------------------------------------------------------- Python-binding cases

PY_CASES_SRC = r'''
import json, sys, math
import numpy as np
import atrous
cases = json.loads(sys.stdin.read())
for c in cases:
    kind, args = c["kind"], c["args"]
    print(json.dumps({"id": c["id"], "status": "start"}), flush=True)
    try:
        if kind == "render":
            out = atrous.render(args.pop("scene"), **args)
            vals = list(out.values())
        elif kind == "sequence":
            vals = []
            for b in atrous.render_sequence(args.pop("scene"), args.pop("frames"), **args):
                vals += [v for v in b.values() if isinstance(v, np.ndarray)]
        elif kind == "denoise":
            img = np.full((12, 16, 3), 0.5, np.float32)
            feats = {k: np.full((12, 16, 3), 0.5, np.float32) for k in ("albedo", "normal", "position", "depth")}
            for k, v in args.pop("specials", {}).items():
                arr = img if k == "color" else feats.setdefault(k, np.full((12, 16, 3), 0.5, np.float32))
                arr.flat[v[0] % arr.size] = float(v[1])
            vals = [atrous.denoise(img, **feats, **args)]
        elif kind == "write_image":
            atrous.write_image(args["path"], np.zeros((2, 2, 3), np.float32))
            vals = []
        elif kind == "read_image":
            vals = [atrous.read_image(args["path"])]
        finite = all(np.isfinite(np.asarray(v, dtype=np.float64)).all() for v in vals if isinstance(v, np.ndarray))
        res = "ok" if finite else "nan-inf"
    except (ValueError, TypeError, OverflowError) as e:
        res = "clean"
    except Exception as e:
        res = "wrong-code:" + type(e).__name__ + ": " + str(e)[:200]
    print(json.dumps({"id": c["id"], "status": res}), flush=True)
'''


def python_cases(rng, n, work):
    cases = []
    kwn = ["sigma_color", "sigma_normal", "sigma_position", "sigma_depth", "albedo_epsilon", "color_scale",
           "position_scale", "emission_scale", "firefly_k", "albedo_floor", "color_level_factor"]
    vals = [1e-20, 1e-7, 1e-6, 0.0, -1.0, 0.5, 1e30, 3e38, float("nan"), float("inf"), 2, 10]
    for i in range(n):
        k = rng.choice(["render", "render", "sequence", "denoise", "denoise", "denoise", "write_image", "read_image"])
        must_fail = None
        if k in ("render", "sequence"):
            key = rng.choice(["threads", "width", "height", "spp", "max_depth"])
            v = rng.choice([0, 1, 2, -1, 65537, 100000, 4096, 2 ** 31, 16385, 5000])
            args = {"scene": "cornell" if k == "render" else "cornell-moving", "width": 8, "height": 6, "spp": 1}
            if v in (16385, 5000) and key in ("width", "height", "spp"):
                v = 3
            args[key] = v
            if k == "sequence":
                args["frames"] = 2
            lim = {"threads": (0, 4096), "width": (1, 16384), "height": (1, 16384), "spp": (1, 1 << 31),
                   "max_depth": (0, 1024)}[key]
            must_fail = not (lim[0] <= v <= lim[1])
            if key == "spp" and v > 8:
                args[key] = 2
                must_fail = False
        elif k == "denoise":
            args = {"method": rng.choice(["eaw", "sure"])}
            if rng.random() < 0.6:
                key, v = rng.choice(kwn), rng.choice(vals)
                args[key] = v
                zero_ok = key in ("sigma_color", "sigma_normal", "sigma_position", "sigma_depth", "albedo_floor")
                hi = 1.0 if key in ("albedo_floor", "color_level_factor") else 3e38
                lo = 1e-38 if key == "color_level_factor" else 1e-6
                if key in ("color_scale", "position_scale", "emission_scale"):
                    hi = 1e6
                must_fail = not (math.isfinite(v) and ((zero_ok and v == 0) or (lo <= v <= hi)))
                if key == "color_level_factor" and v == 0:
                    must_fail = True
                if key == "albedo_floor" and 0 <= v <= 1:
                    must_fail = False
            else:
                args["specials"] = {rng.choice(["color", "albedo", "normal", "position", "depth"]):
                                    [rng.randrange(10 ** 6), repr(rng.choice(FLOAT_SPECIALS[:4]))]}
        elif k == "write_image":
            args = {"path": os.path.join(work, rng.choice(["a\x00b.exr", "x.exr", "x.bogus", "nodir/x.exr",
                                                           "x.pfm\x00.png"]))}
            must_fail = "\x00" in args["path"] or "bogus" in args["path"] or "nodir" in args["path"]
        else:
            args = {"path": os.path.join(work, rng.choice(["missing.exr", "a\x00b.exr", "seeds/env.pfm",
                                                           "seeds/tex.png", "seeds"]))}
            must_fail = "seeds/" not in args["path"]
        cases.append({"id": i, "kind": k, "args": args, "must_fail": must_fail})
    return cases


def run_python_cases(python, cases, timeout):
    """Runs the cases in child interpreters; a child that dies marks its current case a crash."""
    results, todo = {}, list(cases)
    while todo:
        payload = json.dumps([{k: c[k] for k in ("id", "kind", "args")} for c in todo])
        try:
            r = subprocess.run([python, "-c", PY_CASES_SRC], input=payload, capture_output=True, text=True,
                               timeout=timeout * max(1, len(todo)) / 4 + 60)
            out, rc = r.stdout, r.returncode
        except subprocess.TimeoutExpired as e:
            out, rc = (e.stdout or b"").decode() if isinstance(e.stdout, bytes) else (e.stdout or ""), "timeout"
        current = None
        for line in out.splitlines():
            m = json.loads(line)
            if m["status"] == "start":
                current = m["id"]
            else:
                results[m["id"]] = m["status"]
                current = None
        done = set(results)
        if current is not None and current not in done:
            results[current] = "hang" if rc == "timeout" else "crash"
        todo = [c for c in todo if c["id"] not in results]
        if rc == 0 and todo:  # should not happen: the child finished without them
            for c in todo:
                results[c["id"]] = "wrong-code:missing"
            todo = []
    final = {}
    for c in cases:
        s = results[c["id"]]
        if s == "ok" and c["must_fail"]:
            s = "accepted-bad"
        if s.startswith("wrong-code"):
            s = "wrong-code"
        final[c["id"]] = s
    return final
