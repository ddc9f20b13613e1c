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
import math
import os
import random
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from array import array

FAILURES = ["crash", "hang", "wrong-code", "bad-message", "partial-output", "nan-inf", "accepted-bad"]
# Findings whose fix is in another engineer's file, listed so that they stay visible in every run
# without failing it (docs/reliability.md, "Open"): (class, message prefix, what is needed).
KNOWN = [("bad-message", "atrous: error: color buffer has a value of magnitude",
          "apps/atrous/cmd_denoise.cpp names the file of every buffer's error but the colour's"),
         ("accepted-bad", "denoise-empty-number",
          "apps/atrous/cmd_denoise.cpp: CLI11 reads an empty number (--sigma-depth '') as 0 (render checks it)")]
CLASSES = ["ok", "clean"] + FAILURES + ["known"]

# ------------------------------------------------------------------------- reading outputs


def exr_floats_finite(path):
    """True when every FLOAT/HALF sample of a scanline EXR (no or ZIP/ZIPS compression) is finite."""
    data = open(path, "rb").read()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError("not an EXR")
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        end2 = data.index(b"\0", end + 1)
        size = struct.unpack_from("<i", data, end2 + 1)[0]
        attrs[name] = data[end2 + 5:end2 + 5 + size]
        pos = end2 + 5 + size
    pos += 1
    comp = attrs["compression"][0]
    xmin, ymin, xmax, ymax = struct.unpack("<4i", attrs["dataWindow"])
    h = ymax - ymin + 1
    chans, p = [], 0
    cl = attrs["channels"]
    while cl[p] != 0:
        e = cl.index(b"\0", p)
        ptype = struct.unpack_from("<i", cl, e + 1)[0]
        chans.append(ptype)
        p = e + 1 + 16
    lines = {0: 1, 2: 1, 3: 16}.get(comp)
    if lines is None:
        return True  # not written by atrous: not checked
    nchunks = (h + lines - 1) // lines
    offsets = struct.unpack_from("<%dQ" % nchunks, data, pos)
    w = xmax - xmin + 1
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        raw = data[off + 8:off + 8 + size]
        nl = min(lines, ymax - y + 1)
        full = sum((2 if t == 1 else 4) for t in chans) * w * nl
        if comp != 0 and size < full:
            t = bytearray(zlib.decompress(raw))
            for i in range(1, len(t)):
                t[i] = (t[i - 1] + t[i] - 128) & 0xFF
            half = (len(t) + 1) // 2
            out = bytearray(len(t))
            out[0::2] = t[:half]
            out[1::2] = t[half:]
            raw = bytes(out)
        # Channels are stored one after the other per scanline; atrous writes FLOAT only.
        if all(c == 2 for c in chans):
            a = array("f")
            a.frombytes(raw[:len(raw) // 4 * 4])
            if not all(math.isfinite(v) for v in a):
                return False
        else:
            for i in range(0, len(raw) - 1, 2):  # halves: exponent bits 0x7c00
                if (raw[i + 1] & 0x7C) == 0x7C:
                    return False
    return True


def pfm_finite(path):
    data = open(path, "rb").read()
    parts = data.split(b"\n", 3)
    a = array("f")
    a.frombytes(parts[3][:len(parts[3]) // 4 * 4])
    if parts[2].strip().startswith(b"-") != (sys.byteorder == "little"):
        a.byteswap()
    return all(math.isfinite(v) for v in a)


def outputs_finite(paths):
    for p in paths:
        if p.endswith(".exr") and not exr_floats_finite(p):
            return False, p
        if p.endswith(".pfm") and not pfm_finite(p):
            return False, p
    return True, None


# ------------------------------------------------------------------------- seeds


def write_pfm(path, w, h, values):
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(struct.pack("<%df" % len(values), *values))


def write_exr(path, w, h, rgb):
    """An uncompressed FLOAT R,G,B scanline EXR; rgb is interleaved, row by row."""
    def attr(name, typ, data):
        return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(data)) + data
    ch = b"".join(n + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for n in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<4i", 0, 0, w - 1, h - 1)
    head = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + attr("channels", "chlist", ch) +
            attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box) +
            attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0") +
            attr("pixelAspectRatio", "float", struct.pack("<f", 1)) +
            attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0)) +
            attr("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    line = 8 + 12 * w
    table = b"".join(struct.pack("<Q", len(head) + 8 * h + y * line) for y in range(h))
    body = b""
    for y in range(h):
        row = rgb[y * w * 3:(y + 1) * w * 3]
        body += struct.pack("<ii", y, 12 * w)
        for c in (2, 1, 0):
            body += struct.pack("<%df" % w, *row[c::3])
    open(path, "wb").write(head + table + body)


def write_png(path, w, h, rgb):
    raw = b"".join(b"\0" + bytes(rgb[(y * w) * 3:(y * w + w) * 3]) for y in range(h))

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def write_hdr(path, w, h):
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
        for y in range(h):
            f.write(bytes([2, 2, w >> 8, w & 0xFF]))
            for c in range(4):
                f.write(bytes([128 + w, 128 if c == 3 else 60 + 20 * c]))


SCENE = {
    "camera": {"position": [0, 1, 4], "lookAt": [0, 0.5, 0], "up": [0, 1, 0], "fov": 45},
    "materials": {
        "white": {"albedo": [0.7, 0.7, 0.7]},
        "lamp": {"type": "emissive", "emission": [8, 7, 6]},
        "chk": {"checker": {"color1": [0.8, 0.8, 0.8], "color2": [0.1, 0.1, 0.1], "scale": 8}},
        "tex": {"texture": "tex.png", "roughness": 0.3},
        "gold": {"type": "conductor", "albedo": [1, 0.8, 0.3], "roughness": 0.2},
        "glass": {"type": "dielectric", "ior": 1.5},
    },
    "objects": [
        {"type": "quad", "corner": [-2, 0, -2], "edge1": [4, 0, 0], "edge2": [0, 0, 4], "material": "chk"},
        {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "gold",
         "motion": {"translate": [0.5, 0, 0], "rotateY": 10}},
        {"type": "sphere", "center": [1, 0.3, 0.5], "radius": 0.3, "material": "glass"},
        {"type": "quad", "corner": [-0.5, 2, -0.5], "edge1": [0, 0, 1], "edge2": [1, 0, 0], "material": "lamp"},
        {"type": "mesh", "file": "mesh.obj", "transform": {"scale": [0.5, 0.5, 0.5], "rotateY": 30,
                                                            "translate": [-1, 0, 0]}},
    ],
    "lights": [{"type": "point", "position": [1, 2, 1], "intensity": [5, 5, 5]},
               {"type": "environment", "file": "env.pfm", "scale": 0.5}],
}
OBJ = ("mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
       "vn 0 0 1\nusemtl red\nf 1/1/1 2/2/1 3/3/1 4/4/1\nusemtl lit\nf 1/1 2/2 5/3\nf 2 3 5\n")
MTL = ("newmtl red\nKd 0.8 0.1 0.1\nmap_Kd tex.png\nnewmtl lit\nKd 0.5 0.5 0.5\nKe 2 2 2\nillum 2\n")


def make_seeds(cli, root):
    s = os.path.join(root, "seeds")
    os.makedirs(s, exist_ok=True)
    write_png(os.path.join(s, "tex.png"), 8, 8, [(i * 37) % 256 for i in range(8 * 8 * 3)])
    write_pfm(os.path.join(s, "env.pfm"), 8, 4, [0.5 + (i % 7) * 0.1 for i in range(8 * 4 * 3)])
    write_hdr(os.path.join(s, "env.hdr"), 8, 4)
    open(os.path.join(s, "mesh.obj"), "w").write(OBJ)
    open(os.path.join(s, "mesh.mtl"), "w").write(MTL)
    json.dump(SCENE, open(os.path.join(s, "scene.json"), "w"), indent=1)
    key = dict(SCENE)
    key["camera"] = dict(SCENE["camera"], keyframes=[{"t": 0, "position": [0, 1, 4], "target": [0, 0.5, 0]},
                                                     {"t": 1, "position": [1, 1, 4], "target": [0, 0.5, 0]}])
    json.dump(key, open(os.path.join(s, "keyed.json"), "w"), indent=1)
    r = subprocess.run([cli, "render", "--scene", os.path.join(s, "scene.json"), "--width", "16", "--height", "12",
                        "--spp", "4", "--quiet", "--out", os.path.join(s, "render")], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("fuzz: cannot render the seed scene: " + r.stderr)
    r = subprocess.run([cli, "render", "--scene", "cornell-moving", "--width", "16", "--height", "12", "--spp", "1",
                        "--frames", "3", "--quiet", "--out", os.path.join(s, "seq")], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("fuzz: cannot render the seed sequence: " + r.stderr)
    # PFM copies of the render's buffers.
    for name in ("color", "variance", "albedo", "normal"):
        src = os.path.join(s, "render", name + ".exr")
        dst = os.path.join(s, name + ".pfm")
        subprocess.run([cli, "denoise", "--color", src, "--levels", "1", "--no-firefly", "--sigma-color", "1e-6",
                        "--method", "eaw", "--out", dst], capture_output=True)
    return s


# ------------------------------------------------------------------------- mutations

BIG = ["1e39", "-1e39", "3e38", "-3e38", "1e19", "1e10", "99999999999999999999", "1e308", "-1e308"]
ODD = ["0", "-0", "-1", "1e-45", "1e-20", "2147483648", "-2147483649", "1e9", "1e8", "0.5", "65537", "16385"]
FLOAT_SPECIALS = [float("nan"), float("inf"), float("-inf"), 3e38, -3e38, 1e-45, 1e30, 1e20, -1.0, 0.0]


def mutate_bytes(rng, data, header_len=64):
    data = bytearray(data)
    kind = rng.choice(["flip", "set", "truncate", "insert", "delete", "header"])
    if kind == "truncate" and len(data) > 1:
        return bytes(data[:rng.randrange(1, len(data))]), "truncate", True
    for _ in range(rng.choice([1, 1, 2, 4, 16])):
        if not data:
            break
        i = rng.randrange(min(len(data), header_len)) if kind == "header" else rng.randrange(len(data))
        if kind in ("flip", "header"):
            data[i] ^= 1 << rng.randrange(8)
        elif kind == "set":
            data[i] = rng.choice([0, 0xFF, 0x7F, 0x80, 0x01])
        elif kind == "insert":
            data[i:i] = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 9)))
        elif kind == "delete":
            del data[i:i + rng.randrange(1, 9)]
    return bytes(data), kind, False


def mutate_pfm(rng, data):
    """PFM: a lying header, truncation, or special floats in the pixels (values: accepted, sanitised)."""
    head = data.split(b"\n", 3)
    kind = rng.choice(["dims", "values", "values", "scale", "bytes"])
    if kind == "dims":
        w, h = rng.choice([(16384, 16384), (16385, 4), (0, 4), (-3, 4), (99999999999, 1), (16, 13), (15, 12)])
        return b"\n".join([head[0], b"%d %d" % (w, h), head[2], head[3]]), "pfm-dims", (w, h) != (15, 12) or True
    if kind == "scale":
        return b"\n".join([head[0], head[1], rng.choice([b"0", b"nan", b"inf", b"x"]), head[3]]), "pfm-scale", True
    if kind == "values":
        px = bytearray(head[3])
        for _ in range(rng.choice([1, 3, 20])):
            i = rng.randrange(len(px) // 4) * 4
            px[i:i + 4] = struct.pack("<f", rng.choice(FLOAT_SPECIALS))
        return b"\n".join(head[:3] + [bytes(px)]), "pfm-values", None
    m, k, bad = mutate_bytes(rng, data, 24)
    return m, "pfm-" + k, bad


def mutate_text_numbers(rng, text, pool):
    import re
    nums = list(re.finditer(r"(?<![A-Za-z_])-?\d+(\.\d+)?([eE][-+]?\d+)?", text))
    if not nums:
        return text, None
    m = rng.choice(nums)
    v = rng.choice(pool)
    return text[:m.start()] + v + text[m.end():], v


def mutate_json(rng, text):
    kind = rng.choice(["big", "big", "odd", "odd", "type", "delete-key", "truncate", "garbage", "triple"])
    if kind == "big":
        t, v = mutate_text_numbers(rng, text, BIG)
        # Every number a scene carries is bounded (coordinates 1e9, radiance 1e8): must be refused.
        return t, "json-big", True
    if kind == "odd":
        t, v = mutate_text_numbers(rng, text, ODD)
        return t, "json-odd", None
    if kind == "triple":  # the one-number form of a triple
        import re
        arrs = list(re.finditer(r"\[[^\[\]{}]*\]", text))
        m = rng.choice(arrs)
        v = rng.choice(BIG + ["0", "0.5", "-1"])
        return text[:m.start()] + v + text[m.end():], "json-triple", True if v in BIG else None
    if kind == "type":
        t, _ = mutate_text_numbers(rng, text, ['"x"', "null", "true", "[]", "{}", "[1,2]"])
        return t, "json-type", None
    if kind == "delete-key":
        lines = text.split("\n")
        i = rng.randrange(len(lines))
        return "\n".join(lines[:i] + lines[i + 1:]), "json-delete-line", None
    if kind == "truncate":
        return text[:rng.randrange(1, len(text))], "json-truncate", True
    i = rng.randrange(len(text))
    return text[:i] + rng.choice(["\0", "}", "{", ",", "\"", "\\u0000", "NaN", "Infinity"]) + text[i:], "json-garbage", None


def mutate_obj(rng, text):
    lines = text.split("\n")
    kind = rng.choice(["v-big", "vt-big", "vn-big", "f-index", "f-long", "f-zero", "dup", "delete", "garbage"])
    idx = [i for i, l in enumerate(lines) if l.startswith(kind.split("-")[0] + " ")]
    if kind in ("v-big", "vt-big") and idx:
        i = rng.choice(idx)
        lines[i], _ = mutate_text_numbers(rng, lines[i], ["1e39", "-1e39", "nan", "inf", "1e19", "3e38"])
        return "\n".join(lines), "obj-" + kind, True
    if kind == "vn-big" and idx:
        i = rng.choice(idx)
        lines[i], _ = mutate_text_numbers(rng, lines[i], ["1e39", "nan", "0"])
        return "\n".join(lines), "obj-vn", None  # bad normals are dropped (the geometric normal)
    fi = [i for i, l in enumerate(lines) if l.startswith("f ")]
    if kind == "f-index":
        i = rng.choice(fi)
        v = rng.choice(["99999999999999999999", "2147483648", "-2147483649", "999", "-99"])
        lines[i], _ = mutate_text_numbers(rng, lines[i], [v])
        return "\n".join(lines), "obj-f-index", True
    if kind == "f-long":
        n = rng.choice([2000, 5000, 200000])
        lines.append("f " + " ".join(str(1 + k % 5) for k in range(n)))
        return "\n".join(lines), "obj-f-long", True
    if kind == "f-zero":
        i = rng.choice(fi)
        lines[i] = "f 0 0 0"
        return "\n".join(lines), "obj-f-zero", True
    if kind == "dup":
        i = rng.randrange(len(lines))
        lines[i:i] = [lines[i]] * rng.choice([2, 50])
        return "\n".join(lines), "obj-dup", None
    if kind == "delete":
        i = rng.randrange(len(lines))
        del lines[i]
        return "\n".join(lines), "obj-delete", None
    i = rng.randrange(len(text))
    return text[:i] + rng.choice(["\0", "/", " -", "\\\n", "#", "1e39"]) + text[i:], "obj-garbage", None


def mutate_mtl(rng, text):
    lines = text.split("\n")
    kind = rng.choice(["ke-big", "ke-neg", "kd-big", "kd-neg", "map", "ni", "garbage", "missing"])
    if kind == "missing":
        return None, "mtl-missing", True
    if kind.startswith("ke") or kind.startswith("kd"):
        key = "Ke" if kind.startswith("ke") else "Kd"
        idx = [i for i, l in enumerate(lines) if l.startswith(key + " ")]
        i = rng.choice(idx)
        v = rng.choice(["1e39", "3e38", "inf", "nan", "1e9"]) if kind.endswith("big") else rng.choice(["-10", "-1e-3"])
        lines[i], _ = mutate_text_numbers(rng, lines[i], [v])
        return "\n".join(lines), "mtl-" + kind, True
    if kind == "map":
        lines.append("map_Kd " + rng.choice([".", "missing.png", "mesh.obj", "../", "env.pfm"]))
        return "\n".join(lines), "mtl-map", None
    if kind == "ni":
        lines.append("illum 7")
        lines.append("Ni " + rng.choice(["1e39", "5", "-1", "1.3"]))
        return "\n".join(lines), "mtl-ni", None
    i = rng.randrange(len(text))
    return text[:i] + rng.choice(["\0", " ", "1e39", "newmtl"]) + text[i:], "mtl-garbage", None


# Numeric flags: (flag, allowed(v) -> bool, values); a value outside the rule must be refused.
def _num(v):
    try:
        return float(v)
    except ValueError:
        return float("nan")


def _isint(v):
    try:
        int(v)
        return True
    except ValueError:
        return False


def _in(lo, hi, integer=True, zero=False, fmin=None):
    def ok(v):
        if integer and not _isint(v):
            return False
        x = _num(v)
        if not math.isfinite(x):
            return False
        if zero and x == 0:
            return True
        if fmin is not None and x < fmin:
            return False
        return lo <= x <= hi
    return ok


NUM_VALUES = ["0", "-1", "1", "2", "3", "65537", "100000", "16384", "16385", "2147483648", "-2147483649", "1e-20",
              "1e-7", "1e-6", "0.5", "1e30", "1e39", "nan", "inf", "-inf", "x", "", "4096", "11", "10"]
RENDER_FLAGS = [
    ("--width", _in(1, 64)), ("--height", _in(1, 64)), ("--spp", _in(1, 8)), ("--max-depth", _in(0, 1024)),
    ("--threads", _in(0, 4096)), ("--seed", _in(0, 4294967295)), ("--frames", _in(1, 3)),
    ("--reference-spp", _in(1, 4, zero=True)),  # 0 = no reference
]
# Values that would make a case slow rather than bad are never drawn (width > 64 etc. are skipped).
DENOISE_FLAGS = [
    ("--levels", _in(1, 10)), ("--sigma-color", _in(1e-6, 3e38, False, True)),
    ("--color-scale", _in(1e-6, 1e6, False)), ("--color-level-factor", _in(1e-38, 1, False)),
    ("--sigma-normal", _in(1e-6, 3e38, False, True)), ("--sigma-position", _in(1e-6, 3e38, False, True)),
    ("--position-scale", _in(1e-6, 1e6, False)), ("--sigma-depth", _in(1e-6, 3e38, False, True)),
    ("--emission-levels", _in(0, 10)), ("--emission-scale", _in(1e-6, 1e6, False)),
    ("--firefly-k", _in(1e-6, 3e38, False)), ("--albedo-epsilon", _in(1e-6, 3e38, False)),
    ("--albedo-floor", _in(0, 1, False)), ("--sure-window", _in(1, 10)), ("--sure-first-level", _in(0, 16)),
]
SVGF_FLAGS = [
    ("--svgf-sigma-l", _in(1e-6, 3e38, False)), ("--svgf-sigma-n", _in(0, 3e38, False)),
    ("--svgf-sigma-z", _in(1e-6, 3e38, False)), ("--svgf-alpha", _in(1e-38, 1, False)),
    ("--svgf-moments-alpha", _in(1e-38, 1, False)), ("--svgf-history-cap", _in(1, 1 << 20)),
    ("--svgf-levels", _in(0, 10)), ("--taa-alpha", _in(1e-38, 1, False)),
]


# ------------------------------------------------------------------------- cases


class Case:
    def __init__(self, cid, klass, argv, outs, names, must_fail=None, files=None, note=""):
        self.id, self.klass, self.argv, self.outs, self.names = cid, klass, argv, outs, names
        self.must_fail, self.files, self.note = must_fail, files or {}, note


def build_case(cid, rng, seeds, work, cli, klass):
    d = os.path.join(work, "c%05d" % cid)
    os.makedirs(d)
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
        method = rng.choice(["svgf", "svgf", "sure", "eaw"])
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
            flag, ok = rng.choice(SVGF_FLAGS if method == "svgf" else DENOISE_FLAGS)
            v = rng.choice(NUM_VALUES)
            extra = [flag, v]
            bad = not ok(v)
        argv = [cli, "denoise", "--sequence", seq, "--method", method, "--out", out] + extra
        outs = [os.path.join(out, "frame_%04d.exr" % k) for k in range(3)]
        return Case(cid, klass, argv, outs, [name, "frame_", seq] + extra[:1], bad,
                    note="%s %s frame %d %s %s" % (method, kind, f, name, " ".join(extra)))
    raise ValueError(klass)


KLASSES = ["exr", "pfm", "png", "hdr", "json", "obj", "mtl", "render-flag", "denoise-flag", "sizes", "sequence"]


def classify(case, rc, stderr, elapsed, timed_out):
    san = "ERROR: AddressSanitizer" in stderr or "runtime error:" in stderr or "LeakSanitizer" in stderr
    if timed_out:
        return "hang", "timed out after %.0f s" % elapsed
    if san or rc < 0 or rc >= 128:
        return "crash", (stderr.strip().splitlines() or ["signal %d" % -rc])[-1][:300]
    if rc not in (0, 2):
        return "wrong-code", "exit %d: %s" % (rc, stderr.strip()[:300])
    if rc == 2:
        d = os.path.dirname(case.argv[case.argv.index("--out") + 1])
        out_root = os.path.join(d, "out")
        left = [p for p in [out_root, out_root + ".pfm"] if os.path.exists(p) and
                (os.path.isfile(p) or os.listdir(p))]
        left += [os.path.join(d, f) for f in os.listdir(d) if f.startswith(".out")]  # temporary files
        lines = [l for l in stderr.strip().splitlines() if l.strip()]
        if left:
            return "partial-output", "left " + left[0]
        if len(lines) != 1 or not any(n in lines[0] for n in case.names):
            for cls, prefix, _ in KNOWN:
                if cls == "bad-message" and len(lines) == 1 and lines[0].startswith(prefix):
                    return "known", lines[0][:300]
            return "bad-message", " | ".join(lines)[:300]
        return "clean", lines[0][:300]
    missing = [p for p in case.outs if not os.path.exists(p)]
    if missing:
        return "partial-output", "exit 0 without " + missing[0]
    ok, bad = outputs_finite(case.outs)
    if not ok:
        return "nan-inf", bad
    if case.must_fail:
        if case.argv[1] == "denoise" and "" in case.argv:
            return "known", "denoise-empty-number"
        return "accepted-bad", "exit 0"
    return "ok", ""


def run_case(case, timeout, env):
    t0 = time.time()
    try:
        r = subprocess.run(case.argv, capture_output=True, text=True, errors="replace", timeout=timeout, env=env)
        rc, err, to = r.returncode, r.stderr, False
    except subprocess.TimeoutExpired as e:
        rc, err, to = -9, (e.stderr or b"").decode(errors="replace") if isinstance(e.stderr, bytes) else "", True
    el = time.time() - t0
    cls, why = classify(case, rc, err, el, to)
    return cls, why, el


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
