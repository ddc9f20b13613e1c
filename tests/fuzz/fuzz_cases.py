"""The fuzz harness's CLI cases (fuzz.py): the classes a case can fall in, building one case of an
input class from a seeded RNG, running it and classifying the result."""
import json
import math
import os
import shutil
import struct
import zlib

from fuzz_files import outputs_finite, write_exr, write_pfm
import fuzz_proc
from fuzz_proc import SMALL_INPUT_BYTES, entries, input_roots, modified, run_watched, snapshot
from fuzz_mutate import (DENOISE_FLAGS, FLOAT_SPECIALS, NUM_VALUES, RENDER_FLAGS, SVGF_FLAGS, TEMPORAL_FLAGS, _isint, mutate_bytes,
                         mutate_json, mutate_mtl, mutate_obj, mutate_pfm)

FAILURES = ["crash", "hang", "wrong-code", "bad-message", "partial-output", "nan-inf", "accepted-bad", "memory",
            "input-modified", "wrong-output", "refused-good"]
# Findings whose fix is in another engineer's file, listed so that they stay visible in every run
# without failing it (docs/reliability.md, "Open"): (class, message prefix, what is needed).
KNOWN = [("bad-message", "atrous: error: color buffer has a value of magnitude",
          "apps/atrous/cmd_denoise.cpp names the file of every buffer's error but the colour's"),
         ("accepted-bad", "denoise-empty-number",
          "apps/atrous/cmd_denoise.cpp: CLI11 reads an empty number (--sigma-depth '') as 0 (render checks it)")]
CLASSES = ["ok", "clean"] + FAILURES + ["known"]

# ------------------------------------------------------------------------- cases


class Case:
    """One CLI case. must_fail: True (the input is bad: exit 2 expected), False or None (no oracle);
    good: the input is valid, so exit 2 is a failure (refused-good); check(case) -> None or (class,
    why): a further check of the outputs after exit 0; dir: the case's own directory; inputs: more
    paths it reads (every existing path in argv is watched anyway)."""

    def __init__(self, cid, klass, argv, outs, names, must_fail=None, files=None, note="", good=False, check=None,
                 inputs=()):
        self.id, self.klass, self.argv, self.outs, self.names = cid, klass, argv, outs, names
        self.must_fail, self.files, self.note = must_fail, files or {}, note
        self.good, self.check, self.inputs = good, check, list(inputs)
        self.dir = None
        self.unchecked = []  # outputs not checked for NaN/Inf (copies of inputs: case.check looks at them)


def build_case(cid, rng, seeds, work, cli, klass, ordinal=0, seed=0):
    d = os.path.join(work, "c%05d" % cid)
    os.makedirs(d)
    c = _build(cid, rng, seeds, work, cli, klass, d, ordinal, seed)
    c.dir = d
    return c


def _build(cid, rng, seeds, work, cli, klass, d, ordinal, seed):
    if klass in NEW_BUILDERS:
        return NEW_BUILDERS[klass](cid, rng, seeds, d, cli, klass, ordinal, seed)
    out = os.path.join(d, "out")
    R = os.path.join(seeds, "render")

    def copy_scene_dir():
        for f in ("scene.json", "keyed.json", "mesh.obj", "mesh.mtl", "tex.png", "env.pfm", "env.hdr"):
            shutil.copy(os.path.join(seeds, f), d)

    def render_argv(scene, extra=()):
        return [cli, "render", "--scene", scene, "--width", "12", "--height", "8", "--spp", "2", "--quiet",
                "--out", out] + list(extra)

    def render_outs():
        return [os.path.join(out, n + ".exr") for n in ("color", "variance", "albedo", "normal", "position",
                                                        "depth", "ids", "emission")]

    def denoise_argv(color, method, extra=(), feats=True):
        a = [cli, "denoise", "--color", color, "--method", method, "--out", out + ".pfm"]
        if feats:
            for n in ("variance", "albedo", "normal", "position", "depth", "ids", "emission"):
                a += ["--" + n, os.path.join(R, n + ".exr")]
        return a + list(extra)

    if klass in ("exr", "pfm", "png", "hdr"):
        # A mutated image as a denoise input (exr, pfm) or a texture / environment map (png, hdr).
        if klass == "exr":
            name = rng.choice(["color", "variance", "albedo", "normal", "position", "depth"])
            src = os.path.join(R, name + ".exr")
            data, kind, bad = mutate_bytes(rng, open(src, "rb").read(), 400)
            p = os.path.join(d, name + ".exr")
            open(p, "wb").write(data)
            argv = denoise_argv(os.path.join(R, "color.exr"), rng.choice(["eaw", "sure"]))
            argv[argv.index("--color" if name == "color" else "--" + name) + 1] = p
            if kind == "truncate" and len(data) > 200:
                bad = None  # a cut inside the last chunk's padding may still read
            return Case(cid, klass, argv, [out + ".pfm"], [p], bad, note="exr-" + kind)
        if klass == "pfm":
            name = rng.choice(["color", "variance", "albedo", "normal"])
            data, kind, bad = mutate_pfm(rng, open(os.path.join(seeds, name + ".pfm"), "rb").read())
            if kind == "pfm-values" and name == "variance":
                bad = None  # a negative variance is an error, NaN/Inf are missing data
            p = os.path.join(d, name + ".pfm")
            open(p, "wb").write(data)
            argv = [cli, "denoise", "--color", os.path.join(seeds, "color.pfm"), "--method",
                    rng.choice(["eaw", "sure"]), "--out", out + ".pfm"]
            argv += ["--albedo", os.path.join(seeds, "albedo.pfm"), "--normal", os.path.join(seeds, "normal.pfm")]
            if name == "color":
                argv[3] = p
            elif name == "variance":
                argv += ["--variance", p]
            else:
                argv[argv.index("--" + name) + 1] = p
            if kind == "pfm-values":
                bad = None if name != "variance" else None
            return Case(cid, klass, argv, [out + ".pfm"], [p], bad, note=kind)
        copy_scene_dir()
        if klass == "png":
            data, kind, bad = mutate_bytes(rng, open(os.path.join(seeds, "tex.png"), "rb").read(), 40)
            open(os.path.join(d, "tex.png"), "wb").write(data)
            # zlib/CRC damage may still decode to some image (stb skips CRCs): no oracle but truncation.
            bad = True if kind == "truncate" else None
            return Case(cid, klass, render_argv(os.path.join(d, "scene.json")), render_outs(),
                        ["tex.png", "scene.json", "mesh.mtl"], bad, note="png-" + kind)
        data, kind, bad = mutate_bytes(rng, open(os.path.join(seeds, "env.hdr"), "rb").read(), 50)
        open(os.path.join(d, "env.hdr"), "wb").write(data)
        sc = json.load(open(os.path.join(d, "scene.json")))
        sc["lights"][1]["file"] = "env.hdr"
        json.dump(sc, open(os.path.join(d, "scene.json"), "w"))
        bad = True if kind == "truncate" else None
        return Case(cid, klass, render_argv(os.path.join(d, "scene.json")), render_outs(), ["env.hdr"], bad,
                    note="hdr-" + kind)
    if klass == "json":
        copy_scene_dir()
        which = rng.choice(["scene.json", "keyed.json"])
        text, kind, bad = mutate_json(rng, open(os.path.join(d, which)).read())
        open(os.path.join(d, which), "w").write(text)
        extra = ["--frames", "2"] if which == "keyed.json" and rng.random() < 0.5 else []
        outs = render_outs() if not extra else [os.path.join(out, "frame_%04d" % f, "color.exr") for f in range(2)]
        return Case(cid, klass, render_argv(os.path.join(d, which), extra), outs, [which], bad, note=kind)
    if klass == "obj":
        copy_scene_dir()
        text, kind, bad = mutate_obj(rng, open(os.path.join(d, "mesh.obj")).read())
        open(os.path.join(d, "mesh.obj"), "w").write(text)
        return Case(cid, klass, render_argv(os.path.join(d, "scene.json")), render_outs(), ["mesh.obj"], bad,
                    note=kind)
    if klass == "mtl":
        copy_scene_dir()
        text, kind, bad = mutate_mtl(rng, open(os.path.join(d, "mesh.mtl")).read())
        if text is None:
            os.remove(os.path.join(d, "mesh.mtl"))
        else:
            open(os.path.join(d, "mesh.mtl"), "w").write(text)
        return Case(cid, klass, render_argv(os.path.join(d, "scene.json")), render_outs(),
                    ["mesh.mtl", "mesh.obj"], bad, note=kind)
    if klass == "render-flag":
        flag, ok = rng.choice(RENDER_FLAGS)
        v = rng.choice(NUM_VALUES)
        extra = [flag, v]
        if flag == "--reference-spp":
            extra += ["--frames", "2"]
        argv = render_argv("cornell", extra)
        if flag in ("--width", "--height", "--spp") and _isint(v) and 64 < int(v) <= 16384:
            argv[argv.index(flag) + 1] = "3"  # valid, and fast
            v = "3"
        if flag == "--frames" and _isint(v) and 3 < int(v):
            v = "3"
            argv[argv.index(flag) + 1] = v
        if flag == "--reference-spp" and _isint(v) and 4 < int(v):
            v = "4"
            argv[argv.index(flag) + 1] = v
        # The default --width 12 is replaced by a later duplicate: CLI11 takes the last one.
        outs = render_outs()
        if "--frames" in extra:
            outs = [os.path.join(out, "frame_0000", "color.exr")]
        return Case(cid, klass, argv, outs, [flag], not ok(v), note=flag + "=" + v)
    if klass == "denoise-flag":
        flag, ok = rng.choice(DENOISE_FLAGS)
        v = rng.choice(NUM_VALUES)
        method = rng.choice(["eaw", "sure"])
        return Case(cid, klass, denoise_argv(os.path.join(R, "color.exr"), method, [flag, v]), [out + ".pfm"],
                    [flag], not ok(v), note=method + " " + flag + "=" + v)
    if klass == "sizes":
        # A feature buffer of another size than the colour.
        w, h = rng.choice([(12, 12), (16, 11), (1, 1), (17, 12)])
        p = os.path.join(d, "feat.pfm")
        write_pfm(p, w, h, [0.5] * (w * h * 3))
        name = rng.choice(["variance", "albedo", "normal", "position", "depth", "ids", "emission"])
        argv = denoise_argv(os.path.join(R, "color.exr"), rng.choice(["eaw", "sure"]))
        argv[argv.index("--" + name) + 1] = p
        return Case(cid, klass, argv, [out + ".pfm"], [p], True, note="%s %dx%d" % (name, w, h))
    if klass == "sequence":
        seq = os.path.join(d, "seq")
        shutil.copytree(os.path.join(seeds, "seq"), seq)
        f = rng.randrange(3)
        name = rng.choice(["color", "albedo", "normal", "depth", "motion", "ids"])
        p = os.path.join(seq, "frame_%04d" % f, name + ".exr")
        method = rng.choice(["svgf", "svgf", "sure", "eaw", "temporal", "temporal"])
        kind = rng.choice(["bytes", "values", "delete", "flag"])
        bad = None
        extra = []
        if kind == "bytes" and os.path.exists(p):
            data, k, bad = mutate_bytes(rng, open(p, "rb").read(), 400)
            if k == "truncate" and len(data) > 200:
                bad = None
            open(p, "wb").write(data)
        elif kind == "values":
            # Special values in a frame buffer (PFM in place of the EXR is not a sequence file: an
            # EXR rewritten through the CLI would need OpenEXR here; use a PFM colour override).
            vals = [0.5] * (16 * 12 * 3)
            for _ in range(rng.choice([1, 5, 50])):
                vals[rng.randrange(len(vals))] = rng.choice(FLOAT_SPECIALS)
            if name == "normal":
                vals = [0.577 if math.isfinite(v) and v == 0.5 else v for v in vals]
            write_exr(p, 16, 12, vals)
            bad = None
        elif kind == "delete" and os.path.exists(p):
            os.remove(p)
            bad = True if name in ("color",) else None
        else:
            flag, ok = rng.choice({"svgf": SVGF_FLAGS, "temporal": TEMPORAL_FLAGS + DENOISE_FLAGS}.get(method, DENOISE_FLAGS))
            v = rng.choice(NUM_VALUES)
            extra = [flag, v]
            bad = not ok(v)
        argv = [cli, "denoise", "--sequence", seq, "--method", method, "--out", out] + extra
        outs = [os.path.join(out, "frame_%04d.exr" % k) for k in range(3)]
        return Case(cid, klass, argv, outs, [name, "frame_", seq] + extra[:1], bad,
                    note="%s %s frame %d %s %s" % (method, kind, f, name, " ".join(extra)))
    raise ValueError(klass)


KLASSES = ["exr", "pfm", "png", "hdr", "json", "obj", "mtl", "render-flag", "denoise-flag", "sizes", "sequence"]
OLD_KLASSES = list(KLASSES)  # KNOWN applies to these only: the new paths' findings are never marked known
# The classes of the layered-file, pass-flag, sequence-layout, oidnDenoise and weight-file paths
# (fuzz_layered.py, fuzz_seqs.py): each module registers its builders here.
NEW_BUILDERS = {}


def register(klass, builder):
    NEW_BUILDERS[klass] = builder
    if klass not in KLASSES:
        KLASSES.append(klass)


def _message_ok(case, lines):
    return len(lines) == 1 and any(n and n in lines[0] for n in case.names)


def classify(case, r, before, new_entries, input_bytes):
    """The class of a finished case: r is run_watched's result, before the input snapshot,
    new_entries the paths that appeared under the case's directories, input_bytes their size."""
    rc, stderr = r["rc"], r["stderr"]
    san = "ERROR: AddressSanitizer" in stderr or "runtime error:" in stderr or "LeakSanitizer" in stderr
    changed = modified(before)
    if r["mem_killed"]:
        return "memory", "killed at %.0f MB (the cap)" % r["peak_mb"]
    if r["timed_out"]:
        return "hang", "timed out after %.0f s" % r["seconds"]
    if san or rc < 0 or rc >= 128:
        return "crash", (stderr.strip().splitlines() or ["signal %d" % -rc])[-1][:300]
    if changed:
        return "input-modified", changed + " (exit %d)" % rc
    if r["peak_mb"] > fuzz_proc.MEMORY_LIMIT_MB and input_bytes < SMALL_INPUT_BYTES:
        return "memory", "peak %.0f MB with %d bytes of input" % (r["peak_mb"], input_bytes)
    if rc not in (0, 2):
        return "wrong-code", "exit %d: %s" % (rc, stderr.strip()[:300])
    if rc == 2:
        lines = [l for l in stderr.strip().splitlines() if l.strip()]
        # The log before the error (notes, a sequence's k/N counter: docs/cli.md) is not the message:
        # the message is what follows "atrous: error:", and it must be one line.
        starts = [i for i, l in enumerate(lines) if l.startswith("atrous: error:")]
        if starts:
            lines = lines[starts[0]:]
        if new_entries:
            return "partial-output", "left " + sorted(new_entries)[0]
        if not _message_ok(case, lines):
            for cls, prefix, _ in KNOWN if case.klass in OLD_KLASSES else []:
                if cls == "bad-message" and len(lines) == 1 and lines[0].startswith(prefix):
                    return "known", lines[0][:300]
            return "bad-message", " | ".join(lines)[:300]
        if case.good:
            return "refused-good", lines[0][:300]
        return "clean", lines[0][:300]
    missing = [p for p in case.outs if not os.path.exists(p)]
    if missing:
        return "partial-output", "exit 0 without " + missing[0]
    try:
        ok, bad = outputs_finite([p for p in case.outs if p not in case.unchecked])
    except (ValueError, OSError, IndexError, KeyError, struct.error, zlib.error) as e:
        return "wrong-output", "cannot decode an output: %s" % e
    if not ok:
        return "nan-inf", bad
    if case.must_fail:
        if case.argv[1] == "denoise" and "" in case.argv and case.klass in OLD_KLASSES:
            return "known", "denoise-empty-number"
        return "accepted-bad", "exit 0"
    if case.check:
        res = case.check(case)
        if res:
            return res
    return "ok", ""


def run_case(case, timeout, env, cap_mb=2048, logs=None):
    """Runs one case; returns (class, why, seconds, peak MB)."""
    roots = input_roots(case)
    before = snapshot(roots)
    input_bytes = sum(size for size, _ in before.values())
    dirs = [p for p in roots if os.path.isdir(p)]
    old = entries(dirs)
    prefix = os.path.join(logs or os.path.dirname(case.dir), "log%05d" % case.id if isinstance(case.id, int)
                          else "log" + str(case.id))
    r = run_watched(case.argv, timeout, env, cap_mb, prefix)
    new = entries(dirs) - old
    cls, why = classify(case, r, before, new, input_bytes)
    return cls, why, r["seconds"], r["peak_mb"]


from fuzz_layered import build_layered  # noqa: E402  (they import Case from here when they build)
from fuzz_seqs import build_seq  # noqa: E402

from fuzz_flags import build_oidn, build_pass_flag, build_weights  # noqa: E402

register("layered", build_layered)
register("pass-flag", build_pass_flag)
register("seq-layout", build_seq)
register("oidn", build_oidn)
register("weights", build_weights)
