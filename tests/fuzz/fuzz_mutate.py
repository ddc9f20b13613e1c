"""The fuzz harness's mutations (fuzz.py): of bytes, PFM headers and pixels, the numbers and
structure of scene JSON, OBJ and MTL text, and the numeric flags of render and denoise with the
rule each value must satisfy."""
import math
import struct

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
TEMPORAL_FLAGS = [
    ("--temporal-radius", _in(0, 16)), ("--temporal-depth-tolerance", _in(0, 3e38, False)),
    ("--temporal-normal-cos", _in(-1, 1, False)), ("--temporal-color-sigmas", _in(0, 3e38, False)),
    ("--temporal-falloff", _in(0, 3e38, False)), ("--temporal-firefly-k", _in(1e-6, 3e38, False, True)),
]
