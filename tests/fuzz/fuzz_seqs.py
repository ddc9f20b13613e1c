"""The fuzz harness's sequence-layout cases (fuzz.py, class 'seq-layout'): `atrous denoise --sequence`
over every layout docs/inputs.md names: frame_NNNN/ folders (atrous render --frames) and numbered
layered EXR files (render0000.exr, frame_0000.exr, 0000.exr; Blender multipart or single-part,
Mitsuba) with <stem>_motion.exr companions; then a buffer in some frames only, a gap, a frame of
another size, a 1e20 colour in one frame (the message must name that frame's file), damaged bytes,
two prefixes, mixed layouts, special values, and `--out` equal to or inside the sequence directory
(no input may change: every case's inputs are hashed before and after)."""
import os
import shutil

import fuzz_exr as E
from fuzz_layered import BLENDER, MITSUBA, W, H, layered_file, make_part
from fuzz_mutate import mutate_bytes

_FRAMES = {}
NAMES = ["render%04d.exr", "frame_%04d.exr", "%04d.exr", "shot_v2_%03d.exr"]


def frame_buffers(seeds, k):
    """Frame k (0..2) of the seed sequence as {buffer: [R, G, B]}."""
    key = (seeds, k)
    if key not in _FRAMES:
        bufs = {}
        for n in ("color", "albedo", "normal", "position", "depth", "ids", "emission", "motion"):
            p = E.read(os.path.join(seeds, "seq", "frame_%04d" % k, n + ".exr"))[0]["pixels"]
            bufs[n] = [p["R"], p["G"], p["B"]]
        bufs["ids_g"] = [bufs["ids"][1]] * 3
        bufs["variance"] = bufs["albedo"]
        _FRAMES[key] = bufs
    return _FRAMES[key]


def plain_exr(path, bufs, name, w=W, h=H, scale=1.0, edit=None):
    """An atrous-style buffer file (root R,G,B float) of one buffer, optionally edited."""
    p = make_part(bufs, None, "RGB", name, "", "float", 0, w, h, scale)
    if edit:
        edit(p["pixels"])
    E.write(path, [p], False)


LAYOUTS = ["dirs", "blender5", "blender4", "mitsuba"]
KINDS = ["valid", "partial", "gap", "size", "colour1e20", "out-same", "out-inside", "companion", "damage",
         "prefixes", "mixed", "specials"]


def build_seq(cid, rng, seeds, d, cli, klass, ordinal, seed):
    from fuzz_cases import Case
    kind = KINDS[(ordinal + seed) % len(KINDS)]
    layout = LAYOUTS[(ordinal + ordinal // len(KINDS) + seed) % len(LAYOUTS)]
    seq = os.path.join(d, "seq")
    os.makedirs(seq)
    nframes = 3
    pattern = rng.choice(NAMES)
    method = rng.choice(["svgf", "svgf", "sure", "eaw", "temporal", "temporal"])
    j = rng.randrange(nframes)  # the frame the kind acts on
    must, good = None, False
    names = [seq]
    files = []  # each frame's file (layered) or directory
    passes, with_vector = None, False
    if layout != "dirs":
        style = layout
        base = [BLENDER[0], BLENDER[1], BLENDER[3], BLENDER[5]] if style != "mitsuba" else list(MITSUBA[:3])
        with_vector = style != "mitsuba" and rng.random() < 0.5
        passes = base + ([BLENDER[7]] if with_vector else [])
    companions = layout != "dirs" and (kind == "companion" or rng.random() < 0.3)
    typ = "float" if kind == "colour1e20" else None
    for k in range(nframes):
        bufs = frame_buffers(seeds, k)
        if layout == "dirs":
            fd = os.path.join(seq, "frame_%04d" % k)
            shutil.copytree(os.path.join(seeds, "seq", "frame_%04d" % k), fd)
            files.append(fd)
            continue
        pk = list(passes)
        if kind == "partial" and k == j:
            pk = [p for p in pk if p[0] not in ("Denoising Albedo", "albedo")]
        w, h = (8, 6) if kind == "size" and k == j else (W, H)
        parts, multi = layered_file(rng, bufs, style, passes=pk, typ=typ, comp=rng.choice([0, 2, 3]), w=w, h=h)
        if kind == "colour1e20" and k == j:
            p0 = parts[0]
            n = [c for c, _ in p0["channels"] if c.endswith("R")][0]
            p0["pixels"][n][rng.randrange(w * h)] = 1e20
        if kind == "specials" and k == j:
            p0 = parts[rng.randrange(len(parts))]
            n = rng.choice([c for c, _ in p0["channels"]])
            for _ in range(rng.choice([1, 5, 30])):
                p0["pixels"][n][rng.randrange(w * h)] = rng.choice([float("nan"), float("inf"), float("-inf")])
        f = os.path.join(seq, pattern % k)
        E.write(f, parts, multi)
        files.append(f)
        if companions and not (kind == "companion" and k == j and rng.random() < 0.4):
            stem = os.path.splitext(f)[0]
            cw, ch = (8, 6) if kind == "companion" and k == j and rng.random() < 0.3 else (w, h)
            plain_exr(stem + "_motion.exr", bufs, "motion", cw, ch)
    note = "%s %s %s %s frame %d" % (kind, layout, method, pattern if layout != "dirs" else "frame_NNNN/", j)
    target = files[j]
    tname = os.path.basename(target)
    if kind == "valid":
        good = True
    elif kind == "partial":
        if layout == "dirs":
            os.remove(os.path.join(target, rng.choice(["albedo.exr", "normal.exr", "depth.exr", "emission.exr"])))
        must = True
        names += [tname, os.path.basename(files[0])]
    elif kind == "gap":
        g = files[1]
        shutil.rmtree(g) if os.path.isdir(g) else os.remove(g)
        must = True
        names += [os.path.basename(files[0]), os.path.basename(files[2]), "1"]
    elif kind == "size":
        if layout == "dirs":
            for n in ("color", "albedo", "normal", "position", "depth", "ids", "emission", "motion"):
                plain_exr(os.path.join(target, n + ".exr"), frame_buffers(seeds, j), n, 8, 6)
        must = True
        names += [tname]
    elif kind == "colour1e20":
        if layout == "dirs":
            plain_exr(os.path.join(target, "color.exr"), frame_buffers(seeds, j), "color",
                      edit=lambda px: px["R"].__setitem__(rng.randrange(W * H), 1e20))
        must = True
        names = [tname]  # the frame's file, not only the directory
    elif kind == "companion":
        if layout == "dirs":
            os.remove(os.path.join(target, "motion.exr"))
            must = True
        else:
            comps = [os.path.splitext(f)[0] + "_motion.exr" for f in files]
            have = [os.path.exists(c) for c in comps]
            sizes = [E.read_headers(open(c, "rb").read())["headers"][0]["dataWindow"] for c in comps if
                     os.path.exists(c)]
            if len(set(sizes)) > 1 or (not all(have) and not with_vector):
                must = True  # motion in some frames only, or of another size than the frame
            elif not all(have):
                must = None  # every frame has its Vector pass; some also a companion (which wins there)
            elif rng.random() < 0.5:
                data, k2, _ = mutate_bytes(rng, open(comps[j], "rb").read(), 200)
                open(comps[j], "wb").write(data)
                must = True if k2 == "truncate" and method in ("svgf", "temporal") else None  # still methods need no motion
                note += " companion " + k2
            else:
                good = True
            names += [os.path.basename(c) for c in comps]
        names += [tname]
    elif kind == "damage":
        p = target if layout != "dirs" else os.path.join(target, rng.choice(["color.exr", "albedo.exr", "depth.exr"]))
        data, k2, _ = mutate_bytes(rng, open(p, "rb").read(), 300)
        open(p, "wb").write(data)
        must = True if k2 == "truncate" else None
        names += [tname, os.path.basename(p)]
        note += " " + k2
    elif kind == "prefixes":
        if layout == "dirs":
            os.rename(files[j], os.path.join(seq, "frame_%04d_x" % j))  # not a frame name
            must = True if j == 1 else None  # a gap; without the first or last, frames 1-2 or 0-1 remain
        else:
            other = os.path.join(seq, "other%04d.exr" % (j + 5))
            shutil.copy(target, other)
            must = True
            names += ["other", tname]
    elif kind == "specials" and layout == "dirs":
        n = rng.choice(["color", "albedo", "normal", "depth", "motion"])
        vals = [float("nan"), float("inf"), float("-inf")]
        plain_exr(os.path.join(target, n + ".exr"), frame_buffers(seeds, j), n,
                  edit=lambda px: [px[c].__setitem__(rng.randrange(W * H), rng.choice(vals)) for c in "RGB"])
        note += " " + n
    elif kind == "mixed":
        if layout == "dirs":
            plain_exr(os.path.join(seq, "render%04d.exr" % 3), frame_buffers(seeds, 0), "color")
        else:
            fd = os.path.join(seq, "frame_%04d" % 7)
            shutil.copytree(os.path.join(seeds, "seq", "frame_0000"), fd)
        must = True
        names += ["frame_", "render"]
    out = os.path.join(d, "out")
    if kind == "out-same":
        out = seq
    elif kind == "out-inside":
        out = os.path.join(seq, rng.choice(["out", "denoised", "frame_0003", "frame_9999"]))
        note += " --out " + os.path.basename(out)
    argv = [cli, "denoise", "--sequence", seq, "--method", method, "--out", out]
    outs = [os.path.join(out, "frame_%04d.exr" % k) for k in range(nframes)]
    if layout != "dirs":
        outs = [os.path.join(out, "frame_%04d.exr" % int(os.path.basename(f).split(".")[0][-4:].lstrip("_") or 0))
                for f in files]
        outs = [o for o in outs if os.path.basename(o) != "frame_.exr"]
    c = Case(cid, klass, argv, outs, names, must, note=note, good=good and must is not True)
    if kind in ("gap", "prefixes") or layout != "dirs":
        c.outs = []  # the frame numbers of numbered files decide the output names: existence is not checked
        c.check = lambda case, out=out: _outputs_present(out)
    return c


def _outputs_present(out):
    import fuzz_files
    # The outputs keep their input's names (render0001.exr, frame_0001.exr for a frame_0001/ folder).
    frames = sorted(f for f in os.listdir(out) if not f.startswith(".") and f.endswith(".exr")) if \
        os.path.isdir(out) else []
    if not frames:
        return "partial-output", "exit 0 but no output .exr in " + out
    ok, bad = fuzz_files.outputs_finite([os.path.join(out, f) for f in frames])
    return None if ok else ("nan-inf", bad)
