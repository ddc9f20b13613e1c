"""The fuzz harness's files (fuzz.py): decoding the outputs atrous writes (EXR, PFM) to check they
are finite, and writing the seed inputs the cases mutate (PFM, EXR, PNG, HDR, a scene JSON with an
OBJ/MTL mesh, a render and a sequence rendered by the CLI under test)."""
import json
import math
import os
import struct
import subprocess
import sys
import zlib
from array import array

# ------------------------------------------------------------------------- reading outputs


def exr_floats_finite(path):
    """True when every sample of the scanline parts of an EXR is finite, for the compressions
    fuzz_exr decodes (none, RLE, ZIPS, ZIP: what atrous writes); other files are not checked."""
    import fuzz_exr
    data = open(path, "rb").read()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError("not an EXR")
    try:
        parts = fuzz_exr.read(path)
    except (ValueError, KeyError):  # KeyError: a compression read_headers has no line count for
        return True  # tiled, deep, PIZ/B44/DWA: not written by atrous, not checked
    return all(math.isfinite(v) for p in parts for vals in p["pixels"].values() for v in vals)


def pfm_finite(path):
    return all(math.isfinite(v) for v in read_pfm(path))


def read_pfm(path):
    data = open(path, "rb").read()
    parts = data.split(b"\n", 3)
    a = array("f")
    a.frombytes(parts[3][:len(parts[3]) // 4 * 4])
    if parts[2].strip().startswith(b"-") != (sys.byteorder == "little"):
        a.byteswap()
    return list(a)


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
