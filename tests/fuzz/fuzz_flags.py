"""The fuzz harness's flag cases (fuzz.py) for the new input paths:

  pass-flag  --pass BUFFER=NAME, --layer NAME, --add-pass NAME (and inspect's --export '') with good,
             bad, empty, repeated and inapplicable values, on every path: --in DIR, --in FILE.exr,
             --color LAYERED.exr, --color PLAIN, --sequence of frame_NNNN/ folders or of numbered
             layered files, inspect FILE.exr, inspect DIR. A flag that cannot apply must be an
             error, never ignored.
  oidn       oidnDenoise's command line: --hdr/--alb/--nrm/-o, --ldr (output within [0, 1]), --srgb,
             -f/--filter, -q/--quality, --clean_aux, -d/--device.
  weights    --method learned|auto --learned-weights FILE (and svgf --svgf-learned-spatial): a valid
             copy of the built-in weights, a directory, truncated, another version, a flipped byte,
             a non-finite weight or another shape with a correct checksum, over-long, empty,
             missing, not a weight file.
Each case's variant follows from its ordinal in the class (the CI subset covers them all)."""
import os
import re
import shutil
import struct

import fuzz_exr as E
from fuzz_files import write_pfm
from fuzz_layered import BLENDER, MITSUBA, layered_file, seed_buffers
from fuzz_seqs import frame_buffers

HERE = os.path.dirname(os.path.abspath(__file__))
WEIGHTS_CPP = os.path.join(HERE, "..", "..", "src", "filters", "learned_weights_default.cpp")

# ------------------------------------------------------------------------- pass-flag

PATHS = ["in-file", "color-file", "in-dir", "color-plain", "seq-dirs", "seq-files", "inspect-file", "inspect-dir"]
# (variant, flags for a Blender file, flags for a Mitsuba file, good?) ; good None: bad values.
VARIANTS = [
    ("pass-layer", ["--pass", "albedo=ViewLayer.DiffCol"], ["--pass", "albedo=albedo"], True),
    ("pass-passname", ["--pass", "albedo=DiffCol"], ["--pass", "normal=nn"], True),
    ("pass-channel", ["--pass", "depth=ViewLayer.Depth.Z"], ["--pass", "depth=dd.T"], True),
    ("pass-two", ["--pass", "albedo=DiffCol", "--pass", "normal=ViewLayer.Normal"],
     ["--pass", "albedo=albedo", "--pass", "normal=nn"], True),
    ("pass-color", ["--pass", "color=ViewLayer.Combined"], ["--pass", "color=albedo"], True),
    ("pass-nope", ["--pass", "albedo=Nope"], ["--pass", "albedo=Nope"], False),
    ("pass-buffer", ["--pass", "colour=ViewLayer.Combined"], ["--pass", "colour=albedo"], False),
    ("pass-noeq", ["--pass", "albedo"], ["--pass", "albedo"], False),
    ("pass-empty", ["--pass", ""], ["--pass", ""], False),
    ("pass-emptyname", ["--pass", "albedo="], ["--pass", "albedo="], False),
    ("pass-emptybuf", ["--pass", "=DiffCol"], ["--pass", "=albedo"], False),
    ("pass-same-twice", ["--pass", "albedo=DiffCol", "--pass", "albedo=DiffCol"],
     ["--pass", "albedo=albedo", "--pass", "albedo=albedo"], False),
    ("pass-twice", ["--pass", "albedo=DiffCol", "--pass", "albedo=ViewLayer.Denoising Albedo"],
     ["--pass", "albedo=albedo", "--pass", "albedo=nn"], False),
    ("pass-onechannel", ["--pass", "normal=ViewLayer.Depth"], ["--pass", "normal=dd"], False),
    ("layer-good", ["--layer", "ViewLayer"], ["--layer", "ViewLayer"], True),
    ("layer-nope", ["--layer", "Nope"], ["--layer", "Nope"], False),
    ("layer-empty", ["--layer", ""], ["--layer", ""], False),
    ("layer-passname", ["--layer", "ViewLayer.Combined"], ["--layer", "albedo"], False),
    ("add-pass-good", ["--add-pass", "Denoised"], ["--add-pass", "Denoised"], True),
    ("add-pass-existing", ["--add-pass", "Combined"], ["--add-pass", "albedo"], False),
    ("add-pass-empty", ["--add-pass", ""], ["--add-pass", ""], False),
    ("export-empty", ["--export", ""], ["--export", ""], False),
]
FILE_PASSES = [BLENDER[0], BLENDER[1], BLENDER[2], BLENDER[3], BLENDER[5], BLENDER[7]]


def build_pass_flag(cid, rng, seeds, d, cli, klass, ordinal, seed):
    from fuzz_cases import Case
    from fuzz_seqs import _outputs_present
    variant, fb, fm, good_value = VARIANTS[(ordinal + seed) % len(VARIANTS)]
    path = PATHS[(3 * ordinal + ordinal // 88 + seed) % len(PATHS)]  # 3 is prime to 8: every path soon
    style = rng.choice(["blender5", "blender4", "mitsuba"])
    bufs = seed_buffers(seeds)
    flags = list(fm if style == "mitsuba" else fb)
    flag = flags[0]
    if style == "mitsuba" and flag == "--layer" and good_value:
        good_value = False  # Mitsuba's files have no view layers
    if style == "blender4" and variant == "add-pass-existing":
        flags = ["--add-pass", "Denoised"]  # a single-part Blender file has no pass 'Combined' of its own
        good_value = True
    render = os.path.join(seeds, "render")
    f = os.path.join(d, "render.exr")
    passes = list(MITSUBA[:3]) if style == "mitsuba" else FILE_PASSES
    parts, multi = layered_file(rng, bufs, style, passes=passes)
    E.write(f, parts, multi)
    names = [flag, os.path.basename(f)] + [v for v in flags[1::2] if v]
    out_exr, out_pfm = os.path.join(d, "out.exr"), os.path.join(d, "out.pfm")
    check = None
    outs = []
    applies = path in ("in-file", "color-file", "inspect-file")  # a layered file to apply it to
    if flag == "--add-pass":
        applies = path in ("in-file", "seq-files")
    if flag == "--export":
        applies = path.startswith("inspect")
    if path == "color-file" and flag == "--pass" and variant in ("pass-channel",):
        applies = None  # a pass for a buffer this command does not read from the file
    if path == "seq-files" and flag != "--export":
        applies = None if good_value else True  # applied to every frame, or refused: either; never ignored
    if path == "in-file":
        argv = [cli, "denoise", "--in", f, "--out", out_exr if flag == "--add-pass" else rng.choice([out_exr, out_pfm])]
        outs = [argv[-1]]
    elif path == "color-file":
        argv = [cli, "denoise", "--color", f, "--albedo", f, "--normal", f, "--out", out_pfm]
        outs = [out_pfm]
    elif path == "in-dir":
        argv = [cli, "denoise", "--in", render, "--out", out_pfm]
        outs = [out_pfm]
    elif path == "color-plain":
        c = rng.choice([os.path.join(seeds, "color.pfm"), os.path.join(render, "color.exr")])
        argv = [cli, "denoise", "--color", c, "--albedo", os.path.join(seeds, "albedo.pfm"), "--out", out_pfm]
        outs = [out_pfm]
    elif path in ("seq-dirs", "seq-files"):
        seq = os.path.join(d, "seq")
        if path == "seq-dirs":
            shutil.copytree(os.path.join(seeds, "seq"), seq)
        else:
            os.makedirs(seq)
            for k in range(3):
                p2, m2 = layered_file(rng, frame_buffers(seeds, k), style, passes=passes)
                E.write(os.path.join(seq, "render%04d.exr" % k), p2, m2)
        out = os.path.join(d, "out")
        names.append(seq)  # a message may name a frame's file instead of render.exr
        argv = [cli, "denoise", "--sequence", seq, "--method", rng.choice(["svgf", "sure"]), "--out", out]
        check = lambda case, out=out: _outputs_present(out)
        if flag == "--add-pass" and path == "seq-files":
            check = lambda case, out=out, name=flags[1]: _added(out, name)
    elif path == "inspect-file":
        argv = [cli, "inspect", f]
        if rng.random() < 0.4 and flag != "--export":
            argv += ["--export", os.path.join(d, "export")]
    else:
        argv = [cli, "inspect", render]
        if rng.random() < 0.4 and flag != "--export":
            argv += ["--export", os.path.join(d, "export")]
    if flag == "--add-pass" and path.startswith("inspect"):
        applies = False  # not an inspect flag: CLI11 refuses it (exit 2, naming it)
    argv += flags
    # applies True: the value decides; False: the flag is inapplicable (an error); None: either.
    if applies is False:
        must, good = True, False
    elif applies is None:
        must, good = (None if good_value else True), False
    else:
        must, good = not good_value, good_value
    if path == "in-file" and flag == "--add-pass" and argv[argv.index("--out") + 1].endswith(".pfm"):
        must, good = True, False
    note = "%s %s %s %s" % (variant, path, style, " ".join(repr(x) for x in flags))
    c = Case(cid, klass, argv, outs, names, must, note=note, good=good, check=check)
    if flag == "--add-pass":
        c.unchecked = outs
    return c


def _added(out, name):
    """exit 0 of --sequence with --add-pass: the frames must carry the pass (else it was ignored)."""
    frames = sorted(f for f in os.listdir(out) if f.endswith(".exr")) if os.path.isdir(out) else []
    if not frames:
        return "partial-output", "exit 0 but no frames in " + out
    try:
        parts = E.read(os.path.join(out, frames[0]))
    except (ValueError, OSError, IndexError, KeyError, struct.error) as e:
        return "wrong-output", "%s unreadable: %s" % (frames[0], e)
    if not any(name in (p["name"] or "") or any(n.startswith(name + ".") for n, _ in p["channels"]) for p in parts):
        return "accepted-bad", "--add-pass %s ignored with --sequence (%s has no such pass)" % (name, frames[0])
    return None


# ------------------------------------------------------------------------- oidn

OIDN = ["basic", "ldr", "ldr-srgb", "ldr-and-hdr", "srgb-alone", "filter", "quality", "clean-aux", "device",
        "out", "alb-size", "layered-hdr", "ldr-png"]


def _ldr_check(out):
    def check(case):
        from fuzz_files import read_pfm
        vals = read_pfm(out)
        bad = [v for v in vals if not (0.0 <= v <= 1.0)]
        if bad:
            return "wrong-output", "--ldr output has %d values outside [0, 1] (e.g. %r)" % (len(bad), bad[0])
        return None
    return check


def build_oidn(cid, rng, seeds, d, cli, klass, ordinal, seed):
    from fuzz_cases import Case
    variant = OIDN[(ordinal + seed) % len(OIDN)]
    col, alb, nrm = (os.path.join(seeds, n + ".pfm") for n in ("color", "albedo", "normal"))
    out = os.path.join(d, "out.pfm")
    ldr = os.path.join(d, "ldr.pfm")
    bufs = seed_buffers(seeds)
    vals = [min(1.0, max(0.0, bufs["color"][c][i])) for i in range(16 * 12) for c in range(3)]
    if rng.random() < 0.3:
        vals[rng.randrange(len(vals))] = rng.choice([1.5, 40.0, -0.2])
    write_pfm(ldr, 16, 12, vals)
    argv = [cli, "denoise"]
    must, good, names, check = None, False, [], None
    aux = ["--alb", alb, "--nrm", nrm] if rng.random() < 0.7 else (["--alb", alb] if rng.random() < 0.5 else [])
    if variant == "basic":
        argv += ["--hdr", col] + aux + ["-o", out]
        good = True
    elif variant in ("ldr", "ldr-srgb"):
        argv += ["--ldr", ldr] + aux + ["-o", out] + (["--srgb"] if variant == "ldr-srgb" else [])
        good, check = True, _ldr_check(out)
    elif variant == "ldr-and-hdr":
        argv += ["--hdr", col, "--ldr", ldr, "-o", out]
        must, names = True, ["--ldr", "--hdr"]
    elif variant == "srgb-alone":
        argv += ["--hdr", col, "--srgb", "-o", out]
        must, names = True, ["--srgb"]
    elif variant == "filter":
        v = rng.choice(["RT", "RT", "RTLightmap", "rt", "", "x"])
        argv += ["-f" if rng.random() < 0.5 else "--filter", v, "--hdr", col] + aux + ["-o", out]
        must, good, names = v != "RT", v == "RT", ["-f", "--filter", v]
    elif variant == "quality":
        v = rng.choice(["default", "high", "balanced", "fast", "", "x"])
        argv += ["-q" if rng.random() < 0.5 else "--quality", v, "--hdr", col] + aux + ["-o", out]
        must = True if v == "" else None
        good = v in ("default", "high", "balanced", "fast")
        names = ["-q", "--quality"]
    elif variant == "clean-aux":
        argv += ["--hdr", col] + aux + ["--clean_aux", "-o", out]
        good = True
    elif variant == "device":
        v = rng.choice(["default", "cpu", "auto", "cuda", "", "gpu", "sycl", "hip", "metal", "0"])
        argv += ["-d" if rng.random() < 0.5 else "--device", v, "--hdr", col] + aux + ["-o", out]
        must = True if v in ("", "gpu", "sycl", "hip", "metal", "0") else None
        good = v in ("default", "cpu", "auto")
        names = ["-d", "--device", v or "''"]
    elif variant == "out":
        v = rng.choice(["none", "jpg", "nodir", "dir", "same"])
        target = {"none": None, "jpg": os.path.join(d, "o.jpg"), "nodir": os.path.join(d, "no", "o.pfm"),
                  "dir": d, "same": os.path.join(d, "in.pfm")}[v]
        if v == "same":
            shutil.copy(col, target)
            argv += ["--hdr", target] + aux + ["-o", target]
            must = None  # refusing, or writing without touching the input: inputs are hashed
        else:
            argv += ["--hdr", col] + aux + (["-o", target] if target else [])
            must = True
        names = ["-o", "--out", "o.jpg", "no", d]
        out = target
    elif variant == "alb-size":
        small = os.path.join(d, "small.pfm")
        write_pfm(small, 8, 6, [0.5] * (8 * 6 * 3))
        argv += ["--hdr", col, rng.choice(["--alb", "--nrm"]), small, "-o", out]
        must, names = True, ["small.pfm"]
    elif variant == "ldr-png":  # an 8-bit LDR colour; its IDAT chunk may claim far more than the file holds
        from fuzz_files import write_png
        png = os.path.join(d, "ldr.png")
        write_png(png, 16, 12, [int(255 * min(1.0, max(0.0, v))) for v in vals[:16 * 12 * 3]])
        lie = rng.choice([None, 0x7FFFFFF0, 0x10000000, 5000000])
        if lie:
            data = open(png, "rb").read()
            open(png, "wb").write(data[:33] + struct.pack(">I", lie) + data[37:])  # IDAT's length field
        argv += ["--ldr", png] + aux + ["-o", out]
        must, good, names = (True, False, ["ldr.png"]) if lie else (None, True, ["ldr.png"])
    else:
        f = os.path.join(d, "render.exr")
        parts, multi = layered_file(rng, bufs, rng.choice(["blender5", "blender4", "mitsuba"]))
        E.write(f, parts, multi)
        argv += ["--hdr", f, "--alb", f, "--nrm", f, "-o", out]
        must, names = None, ["render.exr"]
    return Case(cid, klass, argv, [out] if out and (good or must is None) else [], names, must,
                note=variant + " " + " ".join(repr(a) for a in argv[2:] if not a.startswith("/")), good=good,
                check=check)


# ------------------------------------------------------------------------- weights

_WEIGHTS = []


def builtin_weights():
    if not _WEIGHTS:
        text = open(WEIGHTS_CPP).read()
        body = text[text.index("kLearnedDefaultWeights[] = {"):]
        body = body[:body.index("};")]
        _WEIGHTS.append(bytes(int(x, 16) for x in re.findall(r"0x([0-9a-fA-F]{2})", body)))
    return _WEIGHTS[0]


def fnv1a(data):
    h = 0x811C9DC5
    for b in data:
        h = ((h ^ b) * 0x01000193) & 0xFFFFFFFF
    return h


def with_checksum(body):
    return body + struct.pack("<I", fnv1a(body))


WEIGHT_KINDS = ["valid", "directory", "truncated", "version", "flip", "nonfinite", "shape", "overlong", "empty",
                "missing", "notweights", "sure-ignores"]


def build_weights(cid, rng, seeds, d, cli, klass, ordinal, seed):
    from fuzz_cases import Case
    kind = WEIGHT_KINDS[(ordinal + seed) % len(WEIGHT_KINDS)]
    w = builtin_weights()
    body = w[:-4]
    v4 = struct.unpack("<I", w[4:8])[0] == 4
    head = 36 if v4 else 28  # the first weight's offset (versions 4 and 3)
    p = os.path.join(d, rng.choice(["weights.bin", "learned_v3.atrl", "w"]))
    must, good = True, False
    if kind in ("valid", "sure-ignores"):
        data = w
        good = kind == "valid"
        must = False if kind == "valid" else None
        if kind == "sure-ignores":
            data = w[:rng.randrange(1, len(w))]
    elif kind == "directory":
        os.makedirs(p)
        data = None
    elif kind == "truncated":
        data = w[:rng.choice([0, 3, 8, 27, 28, 31, rng.randrange(32, len(w))])]
    elif kind == "version":
        # The other readable version on this body has the wrong header (its shape fields disagree).
        data = with_checksum(body[:4] + struct.pack("<I", rng.choice([0, 1, 2, 3 if v4 else 4, 5, 0xFFFFFFFF])) + body[8:])
    elif kind == "flip":
        b = bytearray(w)
        i = rng.randrange(len(b))
        b[i] ^= 1 << rng.randrange(8)
        data = bytes(b)
    elif kind == "nonfinite":
        b = bytearray(body)
        i = head + 4 * rng.randrange((len(body) - head) // 4)
        b[i:i + 4] = struct.pack("<f", rng.choice([float("nan"), float("inf"), float("-inf")]))
        data = with_checksum(bytes(b))
    elif kind == "shape":
        b = bytearray(body)
        i = rng.choice([8, 12, 16, 20, 24] + ([28, 32] if v4 else []))
        b[i:i + 4] = struct.pack("<I", rng.choice([0, 1, 16, 25, 0xFFFFFFFF]))
        data = with_checksum(bytes(b))
    elif kind == "overlong":
        data = with_checksum(body + b"\0" * rng.choice([4, 1, 1000]))
    elif kind == "empty":
        data = b""
    elif kind == "missing":
        data = None
    else:
        data = open(os.path.join(seeds, "tex.png"), "rb").read()
    if data is not None:
        open(p, "wb").write(data)
    render = os.path.join(seeds, "render")
    out = os.path.join(d, "out.pfm")
    how = rng.choice(["learned", "auto", "svgf"]) if kind != "sure-ignores" else rng.choice(["sure", "eaw"])
    if how == "svgf":
        seq = os.path.join(d, "seq")
        shutil.copytree(os.path.join(seeds, "seq"), seq)
        argv = [cli, "denoise", "--sequence", seq, "--method", "svgf", "--svgf-learned-spatial", "--out",
                os.path.join(d, "out")]
        outs = [os.path.join(d, "out", "frame_%04d.exr" % k) for k in range(3)]
    else:
        argv = [cli, "denoise", "--color", os.path.join(render, "color.exr"), "--albedo",
                os.path.join(render, "albedo.exr"), "--normal", os.path.join(render, "normal.exr"), "--method", how,
                "--out", out]
        outs = [out]
    argv += ["--learned-weights", p]
    return Case(cid, klass, argv, outs if not must else [], [os.path.basename(p), "--learned-weights"], must,
                note="%s %s %s" % (kind, how, os.path.basename(p)), good=good)
