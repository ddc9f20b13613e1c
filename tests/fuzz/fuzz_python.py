"""The fuzz harness's Python-binding cases (fuzz.py, tests/python/test_fuzz.py): seeded calls of the
atrous module (render, render_sequence, denoise keywords, read_image/write_image paths), and of
everything in it that reads a file: read_image and read_buffers on layered, damaged, huge-window,
offset-window, deep and tiled EXRs, directories and weight files; denoise_sequence on a sequence
whose second frame's colour is one of those files (a failed run must leave nothing behind);
denoise(method='learned'|'auto',
learned_weights=F) and Svgf(learned_spatial=True, learned_weights=F) with every kind of bad
weight file; atrous.learn.weights.from_bytes. A driver interpreter imports atrous once and runs
each case in a forked child: a crash marks that case only, and the child's own peak resident set
(os.wait4) is the case's memory, the interpreter's included."""
import json
import math
import os
import shutil
import random
import subprocess

import fuzz_exr as E
from fuzz_mutate import FLOAT_SPECIALS

MEMORY_LIMIT_MB = 300

PY_CASES_SRC = r'''
import json, os, resource, select, signal, sys, time, math
import numpy as np
import atrous
cases = json.loads(sys.stdin.read())
timeout, cap = float(sys.argv[1]), float(sys.argv[2])
page = os.sysconf("SC_PAGE_SIZE")
print(json.dumps({"ready": True}), flush=True)


def run(c):
    kind, args = c["kind"], c["args"]
    if kind == "render":
        vals = list(atrous.render(args.pop("scene"), **args).values())
    elif kind == "sequence":
        vals = []
        for b in atrous.render_sequence(args.pop("scene"), args.pop("frames"), **args):
            vals += [v for v in b.values() if isinstance(v, np.ndarray)]
    elif kind in ("denoise", "learned"):
        img = np.full((12, 16, 3), 0.5, np.float32)
        img += np.linspace(0, 0.3, img.size, dtype=np.float32).reshape(img.shape)
        feats = {k: np.full((12, 16, 3), 0.5, np.float32) for k in ("albedo", "normal", "position", "depth")}
        for k, v in args.pop("specials", {}).items():
            arr = img if k == "color" else feats.setdefault(k, np.full((12, 16, 3), 0.5, np.float32))
            arr.flat[v[0] % arr.size] = float(v[1])
        vals = [atrous.denoise(img, **feats, **args)]
    elif kind == "svgf":
        s = atrous.Svgf(learned_spatial=True, learned_weights=args["path"])
        img = np.full((12, 16, 3), 0.5, np.float32)
        vals = [s.denoise_frame(img, albedo=img, normal=np.dstack([img[..., :2] * 0, img[..., :1] * 2]))]
    elif kind == "weights_py":
        from atrous.learn import weights
        weights.from_bytes(open(args["path"], "rb").read(), args["path"])
        vals = []
    elif kind == "write_image":
        atrous.write_image(args["path"], np.zeros((2, 2, 3), np.float32))
        vals = []
    elif kind == "read_buffers":
        vals = list(atrous.read_buffers(args["path"], motion=True).values())
    elif kind == "denoise_sequence":
        out = args["out"]
        try:
            atrous.denoise_sequence(args["seq"], out, method=args["method"], preview=False, pngs=False)
        except ValueError:
            if os.path.exists(out) or any(n.startswith("." + os.path.basename(out)) for n in os.listdir(os.path.dirname(out))):
                return ("wrong-code", "a failed run left files behind: " + out)
            raise
        vals = [atrous.read_image(os.path.join(out, n)) for n in sorted(os.listdir(out)) if n.endswith(".exr")]
    else:  # read_image
        vals = [atrous.read_image(args["path"])]
    finite = all(np.isfinite(np.asarray(v, dtype=np.float64)).all() for v in vals if isinstance(v, np.ndarray))
    return ("ok", "") if finite else ("nan-inf", "")


def child(c):
    try:
        res, why = run(c)
    except (ValueError, TypeError, OverflowError) as e:
        names = c.get("names") or []
        msg = str(e)
        if names and not any(n in msg for n in names) or "\n" in msg.strip():
            res, why = "bad-message", type(e).__name__ + ": " + msg[:300]
        else:
            res, why = "clean", msg[:300]
    except ModuleNotFoundError as e:  # an optional dependency of a subpackage (jax for atrous.learn)
        res, why = ("skip", str(e)) if e.name and not e.name.startswith("atrous") else ("wrong-code", str(e))
    except Exception as e:
        res, why = "wrong-code", type(e).__name__ + ": " + str(e)[:300]
    return res, why


for c in cases:
    r, w = os.pipe()
    t0 = time.time()
    pid = os.fork()
    if pid == 0:
        os.close(r)
        res = child(c)
        os.write(w, json.dumps(res).encode())
        os._exit(0)
    os.close(w)
    data, killed, seen, delay = b"", None, 0.0, 0.002
    while True:
        ready, _, _ = select.select([r], [], [], delay)
        if ready:
            chunk = os.read(r, 65536)
            data += chunk
            if not chunk:
                break
            continue
        try:
            seen = max(seen, int(open("/proc/%d/statm" % pid).read().split()[1]) * page / 2.0 ** 20)
        except (OSError, ValueError, IndexError):
            pass
        if killed is None and time.time() - t0 > timeout:
            killed = "hang"
        elif killed is None and seen > cap:
            killed = "memory"
        if killed:
            os.kill(pid, signal.SIGKILL)
            break
        delay = min(delay * 2, 0.05)
    os.close(r)
    _, status, ru = os.wait4(pid, 0)
    peak = max(ru.ru_maxrss / 1024.0, seen)
    if killed:
        res = [killed, "killed at %.0f MB / %.0f s" % (seen, time.time() - t0)]
    elif os.WIFSIGNALED(status) or not data:
        res = ["crash", "signal %d" % os.WTERMSIG(status) if os.WIFSIGNALED(status) else "exit without a result"]
    else:
        res = json.loads(data)
    print(json.dumps({"id": c["id"], "status": res[0], "why": res[1], "peak_mb": round(peak, 1)}), flush=True)
'''

# ------------------------------------------------------------------------- files


def _weight_files(d):
    """name -> (path, good?) for the weight-file cases: a valid copy and every kind of bad file."""
    from fuzz_flags import builtin_weights, with_checksum
    import struct
    w = builtin_weights()
    body = w[:-4]
    head = 36 if struct.unpack("<I", w[4:8])[0] == 4 else 28  # the first weight's offset (versions 4, 3)
    files = {"valid": w, "truncated": w[:len(w) // 2], "empty": b"", "version5": with_checksum(
        body[:4] + struct.pack("<I", 5) + body[8:]), "version1": with_checksum(body[:4] + struct.pack("<I", 1) + body[8:]),
        "flip": w[:100] + bytes([w[100] ^ 0x10]) + w[101:], "nonfinite": with_checksum(
        body[:head] + struct.pack("<f", float("nan")) + body[head + 4:]), "shape": with_checksum(
        body[:12] + struct.pack("<I", 25) + body[16:]), "overlong": with_checksum(body + b"\0" * 8),
        "notweights": b"\x89PNG\r\n\x1a\n" + b"\0" * 40}
    out = {}
    for k, data in files.items():
        p = os.path.join(d, "w_" + k + ".bin")
        open(p, "wb").write(data)
        out[k] = (p, k == "valid")
    os.makedirs(os.path.join(d, "w_dir.bin"), exist_ok=True)
    out["directory"] = (os.path.join(d, "w_dir.bin"), False)
    out["missing"] = (os.path.join(d, "w_missing.bin"), False)
    return out


def _image_files(d, seeds):
    """name -> (path, must_fail) of the EXRs read_image gets: layered, damaged, huge, offset, deep, tiled."""
    from fuzz_layered import huge_chunks, layered_file, make_part, seed_buffers
    rng = random.Random(7)
    bufs = seed_buffers(seeds)
    out = {}
    for style, typ in (("blender5", "float"), ("blender5", "half"), ("blender4", "float"), ("blender4", "half"),
                       ("mitsuba", "half")):
        parts, multi = layered_file(rng, bufs, style, typ=typ)
        p = os.path.join(d, "layered_%s_%s.exr" % (style, typ))
        data = E.write(p, parts, multi)
        out["layered-%s-%s" % (style, typ)] = (p, None)
        if typ == "float" and style != "mitsuba":
            continue
        t = os.path.join(d, "cut_%s.exr" % style)
        cut = len(data) * 2 // 3
        open(t, "wb").write(data[:cut])
        offs = E.read_headers(data)["offsets"]
        # read_image reads the first part: a cut after it may read (no oracle), one inside it may not
        out["truncated-" + style] = (t, True if len(offs) == 1 or cut < min(offs[1]) else None)
    rgb = make_part(bufs, None, "RGB", "color", "", "float", 3)
    for name, (bw, bh) in (("huge", (16384, 16384)), ("huge-tall", (1, 16384)), ("huge-wide", (16384, 4096))):
        q = dict(rgb)
        q["dw"] = (0, 0, bw - 1, bh - 1)
        q["display"] = (bw, bh)
        p = os.path.join(d, name + ".exr")
        E.write(p, [q], False, {0: huge_chunks(q, 0, False, bw, bh)})
        out[name] = (p, True)
    parts, multi = layered_file(rng, bufs, "blender5")
    big = {}
    for i, q in enumerate(parts):
        q["compression"] = 3
        q["dw"] = (0, 0, 16383, 16383)
        q["display"] = (16384, 16384)
        big[i] = huge_chunks(q, i, True, 16384, 16384)
    p = os.path.join(d, "huge_multipart.exr")
    E.write(p, parts, True, big)
    out["huge-multipart"] = (p, True)
    q = dict(make_part(bufs, None, "RGB", "color", "", "half", 2), dw=(5, 5, 20, 16), display=(16, 12))
    p = os.path.join(d, "offset.exr")
    E.write(p, [q], False)
    out["offset"] = (p, None)
    q = dict(make_part(bufs, "deep", "RGBZ", "color", "", "float", 0), kind="deep")
    p = os.path.join(d, "deep.exr")
    E.write(p, [q], True)
    out["deep"] = (p, True)
    q = dict(make_part(bufs, None, "RGB", "color", "", "half", 3), kind="tiled", tile=(5, 7))
    p = os.path.join(d, "tiled.exr")
    E.write(p, [q], False)
    out["tiled"] = (p, None)
    p = os.path.join(d, "empty.exr")
    open(p, "wb").write(b"")
    out["empty"] = (p, True)
    out["directory"] = (d, True)
    out["weights"] = (os.path.join(d, "w_valid.bin"), True)
    return out


def colour_part():
    """A float RGB part of the synthetic buffers' colour (the synthetic sequence's frames)."""
    from fuzz_layered import make_part, seed_buffers
    return make_part(seed_buffers(None), None, "RGB", "color", "", "float", 0)


def _sequence_seed(work, seeds):
    """A frame_NNNN sequence of the seeds (fuzz.py's rendered one), or None (synthetic frames)."""
    if seeds and os.path.isdir(os.path.join(seeds, "seq")):
        return os.path.join(seeds, "seq")
    return None


def python_cases(rng, n, work, seeds=None):
    """n cases; with seeds (the seed directory fuzz.py renders, or any directory holding
    render/*.exr and seq/frame_0001/motion.exr; None: synthetic buffers), a third read files."""
    files = os.path.join(work, "pyfiles")
    os.makedirs(files, exist_ok=True)
    weights = _weight_files(files)
    images = _image_files(files, seeds)
    cases = []
    kwn = ["sigma_color", "sigma_normal", "sigma_position", "sigma_depth", "albedo_epsilon", "color_scale",
           "position_scale", "emission_scale", "firefly_k", "albedo_floor", "color_level_factor"]
    vals = [1e-20, 1e-7, 1e-6, 0.0, -1.0, 0.5, 1e30, 3e38, float("nan"), float("inf"), 2, 10]
    file_kinds = ["read_file", "learned", "svgf", "weights_py", "read_buffers", "denoise_sequence"]
    seq = _sequence_seed(work, seeds)
    for i in range(n):
        names, note = [], ""
        if i % 3 == 2:  # the file readers, in turn
            k = file_kinds[(i // 3) % len(file_kinds)]
        else:
            k = rng.choice(["render", "render", "sequence", "denoise", "denoise", "denoise", "write_image",
                            "read_image"])
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
        elif k == "read_image":
            args = {"path": os.path.join(work, rng.choice(["missing.exr", "a\x00b.exr", "seeds/env.pfm",
                                                           "seeds/tex.png", "seeds"]))}
            must_fail = "seeds/" not in args["path"]
        elif k == "read_file":
            note = rng.choice(sorted(images))
            path, must_fail = images[note]
            args = {"path": path}
            names = [os.path.basename(path)]
        elif k == "read_buffers":  # the reader of `denoise --in`: no oracle beyond what read_image must refuse
            note = rng.choice(sorted(images))
            path, must_fail = images[note]
            must_fail = True if must_fail else None
            args = {"path": path}
            names = [os.path.basename(path)]
        elif k == "denoise_sequence":  # a sequence with one frame's colour replaced by one of the images
            note = rng.choice(sorted(images))
            path, must_fail = images[note]
            d = os.path.join(work, "pyseq_%d" % i)
            shutil.rmtree(d, ignore_errors=True)
            if seq:
                shutil.copytree(seq, d)
            else:  # synthetic: three frames of a flat colour
                for f in range(3):
                    os.makedirs(os.path.join(d, "frame_%04d" % f))
                    E.write(os.path.join(d, "frame_%04d" % f, "color.exr"), [colour_part()], False)
            frame = sorted(n for n in os.listdir(d) if n.startswith("frame_"))[1]
            if os.path.isfile(path):
                shutil.copyfile(path, os.path.join(d, frame, "color.exr"))
            must_fail = True if must_fail else None
            args = {"seq": d, "out": os.path.join(work, "pyseq_out_%d" % i),
                    "method": rng.choice(["eaw", "temporal", "svgf"])}
            names = [frame]
        else:
            note = rng.choice(sorted(weights))
            path, good = weights[note]
            if k == "weights_py" and note in ("directory", "missing"):  # open() is the harness's own
                note = "truncated"
                path, good = weights[note]
            args = {"path": path}
            if k == "learned":
                args = {"method": rng.choice(["learned", "auto"]), "learned_weights": path}
            must_fail = not good
            names = [os.path.basename(path)]
        cases.append({"id": i, "kind": k, "args": args, "must_fail": must_fail, "names": names,
                      "note": (k + " " + note).strip()})
    return cases


def run_python_cases(python, cases, timeout, cap_mb=1024):
    """Runs the cases in one driver interpreter, each in a forked child. Returns {id: (class, why,
    peak MB)}; a driver that dies marks its remaining cases (and it is restarted for the rest)."""
    results, todo = {}, list(cases)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    while todo:
        payload = json.dumps([{k: c[k] for k in ("id", "kind", "args", "names")} for c in todo])
        err = ""
        try:
            r = subprocess.run([python, "-c", PY_CASES_SRC, str(timeout), str(cap_mb)], input=payload,
                               capture_output=True, text=True, env=env, timeout=timeout * len(todo) + 120)
            out, err = r.stdout, r.stderr
        except subprocess.TimeoutExpired as e:
            out = (e.stdout or b"").decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
        lines = out.splitlines()
        if not any('"ready"' in l for l in lines):
            raise RuntimeError("the Python-case driver did not start under %s: %s" % (python, err.strip()[-500:]))
        for line in lines:
            try:
                m = json.loads(line)
            except ValueError:
                continue
            if isinstance(m, dict) and "id" in m:
                results[m["id"]] = (m["status"], m.get("why", ""), m.get("peak_mb", 0.0))
        rest = [c for c in todo if c["id"] not in results]
        if rest and len(rest) == len(todo):  # the driver itself failed on the first: mark it, go on
            results[rest[0]["id"]] = ("wrong-code", "driver: " + err[-300:], 0.0)
            rest = rest[1:]
        todo = rest
    final = {}
    for c in cases:
        s, why, peak = results[c["id"]]
        if s == "ok" and c["must_fail"]:
            s, why = "accepted-bad", "returned"
        if s in ("ok", "clean") and peak > MEMORY_LIMIT_MB:
            s, why = "memory", "peak %.0f MB" % peak
        final[c["id"]] = (s, why, peak)
    return final
