"""The fuzz harness's layered-EXR cases (fuzz.py): Blender-style multipart files (one part per pass,
'ViewLayer.Combined', 'ViewLayer.Denoising Albedo', ...), Blender 4 single-part files
('ViewLayer.Combined.R' channels) and Mitsuba aov files (R,G,B + 'albedo.R', ..., half floats),
built from the seed render's buffers and then damaged: bytes, truncation, huge claimed data
windows, offset data windows, parts of other sizes, one-channel Normal/Vector passes, deep and
tiled parts, two view layers, special values; run through `denoise --in F.exr`, `inspect F.exr`,
`inspect F.exr --export DIR`, `denoise --color F.exr --albedo F.exr ...` and `--add-pass NAME`.

Class 'layered'. Each case's kind and command follow from its ordinal in the class, so the CI
subset covers every kind and every command; the details come from the case's own RNG."""
import math
import os
import struct
import zlib

import fuzz_exr as E
from fuzz_mutate import mutate_bytes

W, H = 16, 12
_BUFS = {}

# Blender pass name -> (components, source buffer). Shadow and AO are taken by no rule.
BLENDER = [("Combined", "RGBA", "color"), ("Denoising Albedo", "RGB", "albedo"), ("DiffCol", "RGB", "albedo"),
           ("Normal", "XYZ", "normal"), ("Denoising Normal", "XYZ", "normal"), ("Depth", "Z", "depth"),
           ("Position", "XYZ", "position"), ("Vector", "XYZW", "motion"), ("Object Index", "X", "ids"),
           ("Material Index", "X", "ids_g"), ("Emit", "RGB", "emission"), ("Shadow", "RGB", "albedo"),
           ("AO", "RGB", "albedo")]
# Mitsuba aov names -> (components, source buffer); the image itself is the root R,G,B.
MITSUBA = [("albedo", "RGB", "albedo"), ("nn", "XYZ", "normal"), ("dd", "T", "depth"), ("position", "XYZ", "position"),
           ("sh_normal", "XYZ", "normal")]
TAKEN = {"color", "albedo", "normal", "depth", "position", "motion", "ids", "ids_g", "emission"}


def synthetic_buffers():
    """16x12 buffers without a renderer (tests/python/test_fuzz.py): gradients, a sphere's normals."""
    n = W * H
    xs, ys = [i % W for i in range(n)], [i // W for i in range(n)]
    col = [[0.2 + 0.05 * (x % 5) + 0.02 * y for x, y in zip(xs, ys)], [0.3 + 0.01 * x for x in xs],
           [0.1 + 0.03 * y for y in ys]]
    alb = [[0.5] * n, [0.4 + 0.01 * x for x in xs], [0.3] * n]
    nrm = [[(x - 7.5) / 10 for x in xs], [(y - 5.5) / 10 for y in ys], [0.8] * n]
    pos = [[float(x) for x in xs], [float(y) for y in ys], [2.0] * n]
    dep = [[2.0 + 0.1 * x for x in xs]] * 3
    ids = [[float(x // 4) for x in xs], [float(y // 6) for y in ys], [0.0] * n]
    mot = [[0.5] * n, [-0.25] * n, [0.0] * n]
    return {"color": col, "variance": [[0.01] * n] * 3, "albedo": alb, "normal": nrm, "position": pos,
            "depth": dep, "ids": ids, "ids_g": [ids[1]] * 3, "emission": [[0.0] * n] * 3, "motion": mot}


def seed_buffers(seeds):
    """The seed render's buffers (16x12) as {name: [R, G, B] lists}, decoded once (synthetic ones
    when seeds is None or holds no render)."""
    if seeds in _BUFS:
        return _BUFS[seeds]
    if seeds is None or not os.path.exists(os.path.join(seeds, "render", "color.exr")):
        _BUFS[seeds] = synthetic_buffers()
        return _BUFS[seeds]
    bufs = {}
    for n in ("color", "variance", "albedo", "normal", "position", "depth", "ids", "emission"):
        p = E.read(os.path.join(seeds, "render", n + ".exr"))[0]["pixels"]
        bufs[n] = [p["R"], p["G"], p["B"]]
    m = E.read(os.path.join(seeds, "seq", "frame_0001", "motion.exr"))[0]["pixels"]
    bufs["motion"] = [m["R"], m["G"], m["B"]]
    bufs["ids_g"] = [bufs["ids"][1]] * 3
    _BUFS[seeds] = bufs
    return bufs


def _plane(bufs, src, k, comp, w, h, scale=1.0):
    """Component k of a pass from buffer src, at w x h (the seed cropped or tiled)."""
    if comp == "A":
        return [1.0] * (w * h)
    if comp == "W":
        return [0.0] * (w * h)
    s = bufs[src][k % 3]
    return [s[(y % H) * W + (x % W)] * scale for y in range(h) for x in range(w)]


def make_part(bufs, name, comps, src, prefix, typ="float", comp=0, w=W, h=H, scale=1.0):
    chans = [(prefix + c, typ) for c in comps]
    px = {n: _plane(bufs, src, k, c, w, h, scale) for k, (n, c) in enumerate(zip([c for c, _ in chans], comps))}
    return {"name": name, "channels": chans, "pixels": px, "w": w, "h": h, "compression": comp, "src": src,
            "pass": name}


def layered_file(rng, bufs, style, layers=("ViewLayer",), extra=0, typ=None, comp=None, colour_scale=1.0,
                 passes=None, w=W, h=H):
    """The parts of a layered file in one of the styles 'blender5' (multipart), 'blender4' (one part)
    or 'mitsuba' (one part, half). Returns (parts, multipart)."""
    typ = typ or ("half" if style == "mitsuba" else rng.choice(["float", "float", "half"]))
    comp = rng.choice([0, 1, 2, 3]) if comp is None else comp
    if style == "mitsuba":
        chosen = passes or [MITSUBA[0], MITSUBA[1], MITSUBA[2]] + rng.sample(MITSUBA[3:], rng.randrange(3))
        root = make_part(bufs, None, "RGB", "color", "", typ, comp, w, h, scale=colour_scale)
        for name, comps, src in chosen:
            p = make_part(bufs, None, comps, src, name + ".", typ, comp, w, h)
            root["channels"] += p["channels"]
            root["pixels"].update(p["pixels"])
        root["pass"] = "(root)"
        return [root], False
    chosen = passes or [BLENDER[0]] + rng.sample(BLENDER[1:], min(len(BLENDER) - 1, 3 + extra + rng.randrange(5)))
    parts = []
    for vl in layers:
        for name, comps, src in chosen:
            full = vl + "." + name
            parts.append(make_part(bufs, full, comps, src, full + ".", typ, comp, w, h,
                                   scale=colour_scale if src == "color" else 1.0))
    if style == "blender5":
        return parts, True
    one = {"name": None, "channels": [], "pixels": {}, "w": w, "h": h, "compression": comp, "src": "mixed",
           "pass": "all"}
    for p in parts:
        one["channels"] += p["channels"]
        one["pixels"].update(p["pixels"])
    return [one], False


def huge_chunks(part, pidx, multipart, w, h):
    """One real ZIP chunk of a w x h part and the chunk count such a part claims."""
    lines = E.LINES[part["compression"]]
    row = sum(E.SIZES[E.TYPES[t]] for _, t in part["channels"]) * w
    raw = b"\0" * (row * min(lines, h))
    data = E.compress(part["compression"], raw)
    pre = struct.pack("<i", pidx) if multipart else b""
    return ((h + lines - 1) // lines, [pre + struct.pack("<ii", 0, len(data)) + data])


def colour_of(parts):
    """(part index, [R, G, B] channel names) of the colour pass the rules pick (first view layer)."""
    for i, p in enumerate(parts):
        names = [n for n, _ in p["channels"]]
        for pre in ("", ):
            if all(pre + c in names for c in "RGB") and p["name"] is None and p["pass"] in ("(root)",):
                return i, ["R", "G", "B"]
        cand = [n[:-2] for n in names if n.endswith(".Combined.R")]
        if cand:
            return i, [cand[0] + "." + c for c in "RGB"]
    return None, None


def stored(typ, values):
    """The values as the file stores them (half-rounded)."""
    return E._unpack(typ, E._pack(typ, values))


def pass_channels(parts, buffer):
    """(part index, channel names) of the pass the rules take for a buffer (first tier that matches)."""
    if buffer == "color":
        return colour_of(parts)
    for tier in TIERS[buffer]:
        for name in tier:
            for i, p in enumerate(parts):
                chans = [n for n, _ in p["channels"] if n.split(".")[-2:-1] == [name]]
                if chans:
                    return i, chans
    return None, None


def _expected(buffer, v):
    if buffer == "albedo":
        return min(max(v, 0.0), 1.0)
    if buffer == "depth":
        return v if 0 < v < 1e9 else 1e30
    return v


def export_check(parts, outdir):
    """exit 0 of `inspect --export`: the exported colour, albedo, position and depth hold their
    passes as the file stores them (conventions applied), each at the place its data window says
    relative to the first part's window; every exported file is finite."""
    def check(case):
        try:
            for fn in sorted(os.listdir(outdir)):
                for v in E.read(os.path.join(outdir, fn))[0]["pixels"].values():
                    if not all(math.isfinite(x) for x in v):
                        return "nan-inf", "export " + fn
        except (OSError, ValueError, KeyError, IndexError, struct.error, zlib.error) as e:
            return "wrong-output", "an exported file is unreadable: %s" % e
        fx0, fy0, fx1, fy1 = parts[0]["dw"]
        dw_, dh_ = parts[0].get("display", (fx1 + 1, fy1 + 1))
        fx0, fy0, fx1, fy1 = max(fx0, 0), max(fy0, 0), min(fx1, dw_ - 1), min(fy1, dh_ - 1)  # the image
        for buffer in ("color", "albedo", "position", "depth"):
            pi, names = pass_channels(parts, buffer)
            path = os.path.join(outdir, buffer + ".exr")
            if pi is None or not os.path.exists(path):
                continue
            got = E.read(path)[0]
            p = parts[pi]
            x0, y0, x1, y1 = p["dw"]
            gx0, gy0, gx1, gy1 = got["dw"]
            gw, gh = gx1 - gx0 + 1, gy1 - gy0 + 1
            if (gw, gh) != (fx1 - fx0 + 1, fy1 - fy0 + 1):
                return "wrong-output", "export %s is %dx%d, the file %dx%d" % (buffer, gw, gh, fx1 - fx0 + 1,
                                                                              fy1 - fy0 + 1)
            names = sorted(names, key=lambda n: "RGBXYZ".find(n[-1]))[:3]
            pw = x1 - x0 + 1
            for k, c in enumerate("RGB"):
                n = names[k if len(names) == 3 else 0]
                src = stored(dict(p["channels"])[n], p["pixels"][n])
                for j in range(gh):
                    for i in range(gw):
                        ax, ay = fx0 + i, fy0 + j  # absolute pixel
                        if not (x0 <= ax <= x1 and y0 <= ay <= y1):
                            continue
                        want = src[(ay - y0) * pw + (ax - x0)]
                        have = got["pixels"][c][j * gw + i]
                        if math.isfinite(want) and abs(have - _expected(buffer, want)) > 1e-6 * max(1, abs(want)):
                            return "wrong-output", "export %s.exr %s(%d,%d) = %r; the file has %r at (%d,%d) in %s" % (
                                buffer, c, i, j, have, want, ax, ay, n)
        return None
    return check


def copy_check(parts, out, added):
    """exit 0 of `--add-pass NAME`: the copy holds every part and channel of the input with the
    same values (tiled parts as scanlines), plus the added pass, finite."""
    def check(case):
        try:
            got = E.read(out)
        except (OSError, ValueError, KeyError, IndexError, struct.error, zlib.error) as e:
            return "wrong-output", "the copy cannot be decoded: %s" % e
        have = {}
        for g in got:
            for n, _ in g["channels"]:
                have[(g["name"] if len(got) > 1 else None, n)] = (g, n)
        for p in parts:
            for n, t in p["channels"]:
                key = (p["name"] if len(parts) > 1 else None, n)
                if key not in have:
                    return "wrong-output", "the copy lacks channel %s of part %s" % (n, p["name"])
                g, gn = have[key]
                if g["dw"] != tuple(p["dw"]):
                    return "wrong-output", "part %s: data window %s in the copy, %s in the input" % (
                        p["name"], g["dw"], tuple(p["dw"]))
                src = stored(t, p["pixels"][n])
                for a, b in zip(src, g["pixels"][gn]):
                    if a != b and not (a != a and b != b):
                        return "wrong-output", "channel %s differs in the copy (%r, input %r)" % (n, b, a)
        new = [(g, n) for g in got for n, _ in g["channels"] if (g["name"] if len(got) > 1 else None, n) not in
               {(p["name"] if len(parts) > 1 else None, c) for p in parts for c, _ in p["channels"]}]
        if not any(added in (g["name"] or "") or added in n for g, n in new):
            return "wrong-output", "the copy has no pass named %s (new channels: %s)" % (added, [n for _, n in new][:6])
        for g, n in new:
            if not all(math.isfinite(v) for v in g["pixels"][n]):
                return "nan-inf", "added channel %s" % n
        return None
    return check


KINDS = ["valid", "damage", "huge", "offset", "othersize", "onechannel", "deep", "tiled", "twolayers", "specials",
         "outisinput", "aovs", "attrsize"]
COMMANDS = ["denoise-in", "inspect", "export", "color-albedo", "add-pass"]
ALBEDO_PASSES = {"Denoising Albedo", "DiffCol", "albedo"}
SURE_READS = ["albedo", "normal", "position", "emission", "object_id", "material_id"]
NORMAL_PASSES = {"Normal", "Denoising Normal", "nn", "sh_normal"}


# The rules' tiers (docs/inputs.md) for the passes these files hold: buffer -> [[names], [names]].
TIERS = {"color": [["Combined"]], "albedo": [["Denoising Albedo", "albedo"], ["DiffCol"]],
         "normal": [["Normal", "nn", "sh_normal"], ["Denoising Normal"]], "depth": [["Depth", "dd"]],
         "position": [["Position", "position"]], "object_id": [["Object Index"]], "material_id": [["Material Index"]],
         "emission": [["Emit"]], "motion": [["Vector"]]}


def taken(parts, buffers):
    """Indices of the parts holding a pass the rules take for one of these buffers (one view layer)."""
    passes = {}
    for i, p in enumerate(parts):
        for n, _ in p["channels"]:
            bits = n.split(".")
            if len(bits) >= 2:
                passes.setdefault(bits[-2], set()).add(i)
    out = set()
    for b in buffers:
        for tier in TIERS[b]:
            hit = [i for name in tier for i in passes.get(name, ())]
            if hit:
                out.update(hit)
                break
    return out


def has_pass(parts, wanted):
    """Whether the rules find a pass of one of these names (3 components) in the file."""
    for p in parts:
        for n, _ in p["channels"]:
            bits = n.split(".")
            if len(bits) >= 2 and bits[-2] in wanted:
                comps = [c.split(".")[-1] for c, _ in p["channels"] if c.rsplit(".", 1)[0] == n.rsplit(".", 1)[0]]
                if len([c for c in comps if c != "A"]) >= 3:
                    return True
    return False


def build_layered(cid, rng, seeds, d, cli, klass, ordinal, seed):
    from fuzz_cases import Case
    bufs = seed_buffers(seeds)
    kind = KINDS[(ordinal + seed) % len(KINDS)]
    cmd = COMMANDS[(ordinal + ordinal // len(KINDS) + seed) % len(COMMANDS)]  # every pair, in turn
    style = rng.choice(["blender5", "blender5", "blender4", "mitsuba"])
    if kind == "aovs":
        cmd = "color-albedo"
    if kind in ("othersize", "deep", "aovs"):
        style = "blender5"
    elif kind in ("twolayers", "onechannel") and style == "mitsuba":
        style = rng.choice(["blender5", "blender4"])
    f = os.path.join(d, rng.choice(["render.exr", "shot_0001.exr", "a b.exr"]))
    layers = ("A", "B") if kind == "twolayers" else ("ViewLayer",)
    must, good, extra_argv, names, which = None, False, [], [os.path.basename(f)], None
    override = None
    big_colour = kind == "specials" and rng.random() < 0.4
    passes = None
    if kind == "onechannel":
        what = rng.choice(["Normal", "Vector"])
        one = (what, rng.choice(["X", "Y", "W"]) if what == "Vector" else rng.choice(["X", "Z"]),
               "motion" if what == "Vector" else "normal")
        passes = [BLENDER[0], BLENDER[1], one]
    parts, multi = layered_file(rng, bufs, "blender4" if big_colour and style == "mitsuba" else style, layers,
                                colour_scale=1e20 if big_colour else 1.0, passes=passes,
                                typ="float" if big_colour else None)
    ci, cnames = colour_of(parts)
    note = "%s %s %s" % (kind, cmd, style)
    # The buffers the command surely reads (SURE by default: not depth, whose sigma is 0, nor motion;
    # those two may be read or skipped), export all of them, inspect none.
    read, maybe = {"denoise-in": (SURE_READS, ["depth", "motion"]), "add-pass": (SURE_READS, ["depth", "motion"]),
                   "export": (list(TIERS), []), "color-albedo": (["albedo", "normal"], []),
                   "inspect": ([], [])}[cmd]
    aux = sorted(taken(parts, read) - {ci}) if multi else []
    maybe_aux = sorted(taken(parts, maybe) - set(aux) - {ci}) if multi else []
    spare = [i for i in range(len(parts)) if i != ci and i not in taken(parts, TIERS)]
    if kind in ("valid", "aovs"):
        good = True
    elif kind == "huge":
        big = rng.choice([(16384, 16384), (16384, 2048), (1, 16384), (16000, 9000), (8192, 8192), (16384, 4096)])
        which = rng.choice(["all", "all", "one"]) if multi and (aux or spare) else "all"
        target = rng.choice(aux or spare) if which == "one" else None
        override = {}
        for i, p in enumerate(parts):
            if which == "all" or i == target:
                p["compression"] = 3 if big[1] >= 4096 else rng.choice([0, 2, 3])
                p["dw"] = (0, 0, big[0] - 1, big[1] - 1)
                override[i] = huge_chunks(p, i, multi, big[0], big[1])
        for p in parts:
            p["display"] = big if which == "all" else (W, H)
        # what all parts claim must fit in the file, whether the part is read or not
        must = True if cmd != "inspect" else None
        note += " %dx%d %s" % (big[0], big[1], which if which == "all" else "part %d" % target)
    elif kind == "offset":
        dx, dy = rng.choice([(5, 5), (-3, -2), (100, 0), (0, 7)])
        which = rng.choice(["all", "one", "one"]) if multi else "all"
        checked = [pass_channels(parts, b)[0] for b in ("albedo", "position", "depth")]
        target = rng.choice([i for i in checked if i] or list(range(1, len(parts))) or [0])
        for i, p in enumerate(parts):
            if which == "all" or i == target:
                p["dw"] = (dx, dy, dx + W - 1, dy + H - 1)
            p["display"] = (W, H)
        # The image is the first part's window clipped to the display window; a pass placed elsewhere
        # that does not cover it is refused where it is read
        # (a window wholly outside the display window: refused, or taken as it is; no oracle)
        empty = dx >= W or dy >= H
        if which == "all":
            good = not empty
        else:
            must = True if target in aux else None
        note += " (%d,%d) %s" % (dx, dy, which if which == "all" else "part %d" % target)
    elif kind == "othersize":
        used = bool(aux + maybe_aux) and rng.random() < 0.6
        if not used:
            parts.append(make_part(bufs, "ViewLayer.Shadow2", "RGB", "albedo", "ViewLayer.Shadow2."))
        i = rng.choice(aux + maybe_aux) if used else len(parts) - 1
        w2, h2 = rng.choice([(8, 6), (17, 12), (16, 13), (1, 1)])
        smaller = w2 < W or h2 < H  # a larger part from (0, 0) covers the image: read in place
        p = parts[i]
        parts[i] = make_part(bufs, p["name"], "".join(n[-1] for n, _ in p["channels"]), p["src"], p["name"] + ".",
                             p["channels"][0][1], p["compression"], w2, h2)
        must = True if used and smaller and i in aux else None
        good = not used and cmd != "add-pass"
        note += " part %s %dx%d%s" % (p["name"], w2, h2, " (taken)" if used else "")
    elif kind == "onechannel":
        must = True if one[2] in read else None  # one channel for a normal or motion, where it is read
        note += " " + parts[-1]["channels"][0][0] if multi else " " + parts[0]["channels"][-1][0]
    elif kind == "deep":
        used = bool(aux + maybe_aux) and rng.random() < 0.5
        if used:
            i = rng.choice(aux + maybe_aux)
        else:
            parts.append(make_part(bufs, "ViewLayer.Deep", "RGBZ", "albedo", "ViewLayer.Deep."))
            i = len(parts) - 1
        parts[i]["kind"] = "deep"
        parts[i]["compression"] = 0
        must = True if (used and i in aux) or cmd == "add-pass" else None
        good = not used and cmd in ("denoise-in", "export")
        note += " part %s%s" % (parts[i]["name"], " (taken)" if used else "")
    elif kind == "tiled":
        i = rng.randrange(len(parts))
        parts[i]["kind"] = "tiled"
        parts[i]["tile"] = rng.choice([(8, 8), (5, 7), (16, 12), (32, 32)])
        parts[i]["compression"] = rng.choice([0, 1, 2, 3])
        good = True
        note += " part %d tiles %s" % (i, parts[i]["tile"])
    elif kind == "twolayers":
        pick = rng.choice(["none", "A", "B", "C"])
        if pick != "none":
            extra_argv = ["--layer", pick]
            names.append("--layer")
        must = True if pick == "C" or (pick == "none" and cmd != "inspect") else None
        good = pick in ("A", "B")
        note += " --layer %s" % pick
    elif kind == "specials":
        ctype = dict(parts[ci]["channels"])[cnames[0]] if ci is not None else "half"
        if big_colour and ctype == "float":
            must = True if cmd not in ("inspect", "export") else None
            note += " colour x1e20"
        else:
            p = parts[rng.randrange(len(parts))]
            n = rng.choice([c for c, _ in p["channels"]])
            for _ in range(rng.choice([1, 5, 40])):
                p["pixels"][n][rng.randrange(len(p["pixels"][n]))] = rng.choice(
                    [float("nan"), float("inf"), float("-inf"), -1.0, 0.0, 1e4])
            note += " specials in " + n
    if kind == "attrsize":
        parts[0]["attrs"] = [("comments", "string", b"rendered by the fuzz harness"),
                             ("owner", "string", b"atrous")]
    data = E.exr_bytes(parts, multi, override)
    if kind == "damage":
        info = E.read_headers(data)
        colour_end = max(info["offsets"][ci or 0]) + 8
        data, k, bad = mutate_bytes(rng, data, 300)
        if k == "truncate":
            must = True if len(data) < colour_end and cmd != "inspect" else None
        note += " " + k
    if kind == "attrsize":  # a header attribute claiming a huge size (the reader must not allocate it)
        info_attrs = []
        pos = 8
        while data[pos] != 0:
            e1 = data.index(b"\0", pos)
            e2 = data.index(b"\0", e1 + 1)
            size = struct.unpack_from("<i", data, e2 + 1)[0]
            info_attrs.append((data[pos:e1].decode(), e2 + 1))
            pos = e2 + 5 + size
        # variable-size types only: OpenEXR reads box2i, float, v2f, ... at their own size
        name, at = rng.choice([a for a in info_attrs if a[0] in ("comments", "owner", "name", "type")])
        claim = rng.choice([0x7FFFFFF0, 0x40000000, 100000000, 20000000])
        data = data[:at] + struct.pack("<i", claim) + data[at + 4:]
        must = True
        note += " %s claims %d bytes" % (name, claim)
    open(f, "wb").write(data)
    out_exr = os.path.join(d, "out.exr")
    if kind == "outisinput":
        cmd, out_exr = "add-pass", f
        note = "outisinput add-pass " + style
    outs, check = [], None
    if cmd == "denoise-in":
        out = os.path.join(d, rng.choice(["out.exr", "out.pfm"]))
        argv = [cli, "denoise", "--in", f, "--out", out] + extra_argv
        outs = [out]
    elif cmd == "inspect":
        argv = [cli, "inspect", f] + extra_argv
    elif cmd == "export":
        ex = os.path.join(d, "export")
        argv = [cli, "inspect", f, "--export", ex] + extra_argv
        outs = [os.path.join(ex, "color.exr")]
        if kind in ("valid", "tiled") or (kind == "offset" and good):
            check = export_check(parts, ex)
    elif cmd == "color-albedo":
        out = os.path.join(d, "out.pfm")
        if kind == "aovs":  # a separate AOV file beside a plain or layered colour
            aovs = os.path.join(d, "aovs.exr")
            sub = [p for p in parts if p["src"] != "color"]
            if len(sub) == 1 and len(sub[0]["channels"]) < 3:
                sub.append(make_part(bufs, "ViewLayer.Denoising Albedo", "RGB", "albedo", "ViewLayer.Denoising Albedo."))
            if rng.random() < 0.3 and sub:
                sub = [make_part(bufs, q["name"], "".join(n[-1] for n, _ in q["channels"]), q["src"], q["name"] + ".",
                                 w=8, h=6) for q in sub]
                good, must = False, True
            E.write(aovs, sub or parts[1:2] or parts, len(sub) > 1)
            colour = rng.choice([f, os.path.join(seeds, "render", "color.exr"), os.path.join(seeds, "color.pfm")])
            argv = [cli, "denoise", "--color", colour, "--albedo", aovs, "--normal", aovs, "--out", out]
            names.append("aovs.exr")
            if not (has_pass(sub, ALBEDO_PASSES) or len(sub) == 1) or not (has_pass(sub, NORMAL_PASSES) or
                                                                            len(sub) == 1):
                good, must = False, True
            note += " colour %s" % os.path.basename(colour)
        else:
            argv = [cli, "denoise", "--color", f, "--albedo", f, "--normal", f, "--out", out] + extra_argv
            if not has_pass(parts, ALBEDO_PASSES) or not has_pass(parts, NORMAL_PASSES):
                good, must = False, True  # a layered file given for a buffer it has no pass for
        outs = [out]
    else:
        name = rng.choice(["Denoised", "Denoised", "denoised_sure", "Combined", "albedo", "x.y", "", "\u00c4 \u00f6",
                           "a" * 300])
        argv = [cli, "denoise", "--in", f, "--add-pass", name, "--out", out_exr] + extra_argv
        outs = [out_exr]
        names += ["--add-pass", name or "''"]
        existing = any((p["name"] or "").endswith("." + name) for p in parts) or any(
            n.startswith(name + ".") for p in parts for n, _ in p["channels"])
        if name == "" or existing:
            must, good = True, False
        elif not must and kind in ("valid", "tiled", "offset", "specials", "outisinput", "aovs"):
            check = copy_check(parts, out_exr, name)
        if name == "a" * 300:
            good = False
        note += " --add-pass %r" % name[:20]
    c = Case(cid, klass, argv, outs, names, must, note=note, good=good and must is not True, check=check)
    if cmd == "add-pass" or kind == "specials":
        c.unchecked = outs if cmd in ("add-pass", "export") else []
    return c
