"""The fuzz harness's OpenEXR writer and reader (standard library only): layered files as Blender
(one part per pass, or one part of 'ViewLayer.Pass.C' channels) and Mitsuba (one part: R,G,B and
'name.C', half floats) write them, with offset or lying data windows, tiled and deep parts; and a
decoder of scanline files (NONE, RLE, ZIPS, ZIP; half, float, uint; single- or multipart) for the
outputs atrous writes and the copies `--add-pass` makes.

A part is a dict: name (None: no name attribute), channels [(name, type)] with type 'half',
'float' or 'uint', pixels {channel: [w*h values, row by row]}, dw (xmin, ymin, xmax, ymax) (default
0,0,w-1,h-1), kind 'scanline' | 'tiled' | 'deep', compression 0 NONE | 1 RLE | 2 ZIPS | 3 ZIP.
"""
import struct
import zlib

TYPES = {"uint": 0, "half": 1, "float": 2}
TYPE_NAMES = {0: "uint", 1: "half", 2: "float"}
SIZES = {0: 4, 1: 2, 2: 4}
LINES = {0: 1, 1: 1, 2: 1, 3: 16}  # scanlines per chunk by compression
MAGIC = b"\x76\x2f\x31\x01"


def _attr(name, typ, data):
    return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(data)) + data


def _pack(typ, values):
    if typ == "half":
        out = []
        for v in values:
            try:
                out.append(struct.pack("<e", v))
            except OverflowError:  # beyond half's range: Inf of that sign
                out.append(b"\x00\x7c" if v > 0 else b"\x00\xfc")
        return b"".join(out)
    if typ == "uint":
        return struct.pack("<%dI" % len(values), *[int(v) & 0xFFFFFFFF for v in values])
    return struct.pack("<%df" % len(values), *values)


def _predict(raw):
    """OpenEXR's ZIP/RLE preprocessing: bytes split into even/odd halves, then differences."""
    t = bytearray(len(raw))
    half = (len(raw) + 1) // 2
    t[:half] = raw[0::2]
    t[half:] = raw[1::2]
    p = t[0] if t else 0
    for i in range(1, len(t)):
        d = (t[i] - p + 128 + 256) & 0xFF
        p = t[i]
        t[i] = d
    return bytes(t)


def _unpredict(t):
    t = bytearray(t)
    for i in range(1, len(t)):
        t[i] = (t[i - 1] + t[i] - 128) & 0xFF
    half = (len(t) + 1) // 2
    out = bytearray(len(t))
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return bytes(out)


def _rle(data):
    out = bytearray()
    for i in range(0, len(data), 127):
        lit = data[i:i + 127]
        out.append((-len(lit)) & 0xFF)
        out += lit
    return bytes(out)


def _unrle(data):
    out, i = bytearray(), 0
    while i < len(data):
        n = struct.unpack("b", data[i:i + 1])[0]
        i += 1
        if n < 0:
            out += data[i:i - n]
            i -= n
        else:
            out += data[i:i + 1] * (n + 1)
            i += 1
    return bytes(out)


def compress(comp, raw):
    if comp == 0:
        return raw
    t = _predict(raw)
    c = _rle(t) if comp == 1 else zlib.compress(t)
    return c if len(c) < len(raw) else raw  # OpenEXR stores a chunk raw when it does not shrink


def _chlist(channels):
    channels = sorted(channels, key=lambda c: c[0].encode())  # OpenEXR's order (strcmp)
    return b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", TYPES[t], 0, 1, 1) for n, t in channels) + b"\0"


def _header(part, multipart, chunks, nparts, deep_file=False):
    x0, y0, x1, y1 = part["dw"]
    w0, h0 = part.get("display", (x1 + 1, y1 + 1))
    kind = part.get("kind", "scanline")
    h = (_attr("channels", "chlist", _chlist(part["channels"])) +
         _attr("compression", "compression", bytes([part.get("compression", 0)])) +
         _attr("dataWindow", "box2i", struct.pack("<4i", x0, y0, x1, y1)) +
         _attr("displayWindow", "box2i", struct.pack("<4i", 0, 0, w0 - 1, h0 - 1)) +
         _attr("lineOrder", "lineOrder", b"\0") + _attr("pixelAspectRatio", "float", struct.pack("<f", 1)) +
         _attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0)) +
         _attr("screenWindowWidth", "float", struct.pack("<f", 1)))
    if kind == "tiled":
        h += _attr("tiles", "tiledesc", struct.pack("<IIB", part["tile"][0], part["tile"][1], 0))
    if multipart or part.get("name") is not None:
        if part.get("name") is not None:
            h += _attr("name", "string", part["name"].encode())
        h += _attr("type", "string", {"scanline": b"scanlineimage", "tiled": b"tiledimage",
                                      "deep": b"deepscanline"}[kind])
    if multipart:
        h += _attr("chunkCount", "int", struct.pack("<i", chunks))
    for name, typ, data in part.get("attrs", ()):  # more attributes: (name, type, bytes)
        h += _attr(name, typ, data)
    if deep_file:  # OpenEXR Core wants it in every part of a file flagged as holding deep data
        h += _attr("version", "int", struct.pack("<i", 1))
    if kind == "deep":
        h += _attr("maxSamplesPerPixel", "int", struct.pack("<i", 1))
    return h + b"\0"


def _chunks(part, multipart, pidx):
    """The chunks of one part, each as bytes (with its part number in a multipart file)."""
    x0, y0, x1, y1 = part["dw"]
    w, h = x1 - x0 + 1, y1 - y0 + 1
    chans = sorted(part["channels"], key=lambda c: c[0].encode())  # OpenEXR stores channels in name order
    px = part["pixels"]
    comp = part.get("compression", 0)
    kind = part.get("kind", "scanline")
    pre = struct.pack("<i", pidx) if multipart else b""
    out = []
    if kind == "tiled":
        tw, th = part["tile"]
        for ty in range((h + th - 1) // th):
            for tx in range((w + tw - 1) // tw):
                raw = b""
                for y in range(ty * th, min(h, (ty + 1) * th)):
                    for n, t in chans:
                        raw += _pack(t, px[n][y * w + tx * tw:y * w + min(w, (tx + 1) * tw)])
                data = compress(comp, raw)
                out.append(pre + struct.pack("<iiiii", tx, ty, 0, 0, len(data)) + data)
        return out
    if kind == "deep":  # one sample per pixel, uncompressed
        for y in range(h):
            table = struct.pack("<%di" % w, *range(1, w + 1))
            raw = b"".join(_pack(t, px[n][y * w:(y + 1) * w]) for n, t in chans)
            out.append(pre + struct.pack("<iqqq", y0 + y, len(table), len(raw), len(raw)) + table + raw)
        return out
    lines = LINES[comp]
    for c in range((h + lines - 1) // lines):
        raw = b""
        for y in range(c * lines, min(h, (c + 1) * lines)):
            for n, t in chans:
                raw += _pack(t, px[n][y * w:(y + 1) * w])
        data = compress(comp, raw)
        out.append(pre + struct.pack("<ii", y0 + c * lines, len(data)) + data)
    return out


def exr_bytes(parts, multipart=None, chunk_override=None):
    """The bytes of an EXR holding `parts` (multipart when there are several, or when asked).
    chunk_override: {part index: (claimed chunk count, list of chunk bytes)} for lying files."""
    multipart = len(parts) > 1 if multipart is None else multipart
    for p in parts:
        if "dw" not in p:
            p["dw"] = (0, 0, p["w"] - 1, p["h"] - 1)
    x0, y0, x1, y1 = parts[0]["dw"]
    for p in parts:  # the display window is an attribute every part of a file shares
        p.setdefault("display", parts[0].get("display", (x1 + 1, y1 + 1)))
    bodies = []
    for i, p in enumerate(parts):
        if chunk_override and i in chunk_override:
            bodies.append(chunk_override[i])
        else:
            ch = _chunks(p, multipart, i)
            bodies.append((len(ch), ch))
    deep = any(p.get("kind") == "deep" for p in parts)
    heads = b"".join(_header(p, multipart, bodies[i][0], len(parts), deep) for i, p in enumerate(parts))
    if multipart:
        heads += b"\0"
    names = [n for p in parts for n, _ in p["channels"]] + [p.get("name") or "" for p in parts]
    flags = (0x1000 if multipart else 0) | (0x400 if any(len(n) > 31 for n in names) else 0)
    if not multipart and parts[0].get("kind") == "tiled":
        flags |= 0x200
    if any(p.get("kind") == "deep" for p in parts):
        flags |= 0x800
    head = MAGIC + struct.pack("<i", 2 | flags) + heads
    table_len = 8 * sum(n for n, _ in bodies)
    pos = len(head) + table_len
    tables, blob = b"", b""
    for n, chunks in bodies:
        offs = []
        for k in range(n):
            c = chunks[k % len(chunks)] if chunks else b""
            if k < len(chunks):
                offs.append(pos + len(blob))
                blob += c
            else:  # more chunks claimed than written: the rest point at the last one written
                offs.append(offs[-1] if offs else 0)
        tables += struct.pack("<%dQ" % n, *offs)
    return head + tables + blob


def write(path, parts, multipart=None, chunk_override=None):
    data = exr_bytes(parts, multipart, chunk_override)
    with open(path, "wb") as f:
        f.write(data)
    return data


def part_end_offsets(data):
    """{part index: end offset of its last chunk} of a file written by exr_bytes (for truncation oracles)."""
    info = read_headers(data)
    ends = {}
    for i, (attrs, offs) in enumerate(zip(info["headers"], info["offsets"])):
        ends[i] = max(offs) if offs else 0
    return ends


# ------------------------------------------------------------------------- reading


def read_headers(data):
    if data[:4] != MAGIC:
        raise ValueError("not an EXR")
    version = struct.unpack_from("<i", data, 4)[0]
    multi = bool(version & 0x1000)
    tiled_single = bool(version & 0x200)
    pos, headers = 8, []
    while True:
        attrs = {}
        while data[pos] != 0:
            end = data.index(b"\0", pos)
            name = data[pos:end].decode()
            end2 = data.index(b"\0", end + 1)
            size = struct.unpack_from("<i", data, end2 + 1)[0]
            attrs[name] = data[end2 + 5:end2 + 5 + size]
            pos = end2 + 5 + size
        pos += 1
        headers.append(attrs)
        if not multi or data[pos] == 0:
            break
    if multi:
        pos += 1
    offsets = []
    for a in headers:
        x0, y0, x1, y1 = struct.unpack("<4i", a["dataWindow"])
        if "chunkCount" in a:
            n = struct.unpack("<i", a["chunkCount"])[0]
        elif tiled_single or "tiles" in a:
            tw, th = struct.unpack_from("<II", a["tiles"])
            n = ((x1 - x0 + tw) // tw) * ((y1 - y0 + th) // th)
        else:
            n = (y1 - y0 + LINES[a["compression"][0]]) // LINES[a["compression"][0]]
        offsets.append(list(struct.unpack_from("<%dQ" % n, data, pos)))
        pos += 8 * n
    return {"multipart": multi, "headers": headers, "offsets": offsets}


def channels_of(attrs):
    cl, p, out = attrs["channels"], 0, []
    while cl[p] != 0:
        e = cl.index(b"\0", p)
        out.append((cl[p:e].decode(), TYPE_NAMES.get(struct.unpack_from("<i", cl, e + 1)[0], "?")))
        p = e + 1 + 16
    return sorted(out, key=lambda c: c[0].encode())  # pixel data follows the sorted order


def _unpack(typ, raw):
    n = len(raw) // SIZES[TYPES[typ]]
    return list(struct.unpack("<%d%s" % (n, {"half": "e", "float": "f", "uint": "I"}[typ]), raw[:n * SIZES[TYPES[typ]]]))


def read(path):
    """Every scanline part of an EXR: [{name, dw, channels, pixels {channel: values}}]. Raises
    ValueError on what it cannot decode (tiled/deep parts, PIZ/B44/DWA compression)."""
    data = open(path, "rb").read()
    info = read_headers(data)
    parts = []
    for i, (a, offs) in enumerate(zip(info["headers"], info["offsets"])):
        typ = a.get("type", b"scanlineimage").rstrip(b"\0").decode()
        if typ != "scanlineimage" or "tiles" in a:
            raise ValueError("part %d is %s: not decoded" % (i, typ))
        comp = a["compression"][0]
        if comp not in LINES:
            raise ValueError("compression %d: not decoded" % comp)
        x0, y0, x1, y1 = struct.unpack("<4i", a["dataWindow"])
        w, h = x1 - x0 + 1, y1 - y0 + 1
        chans = channels_of(a)
        px = {n: [0.0] * (w * h) for n, _ in chans}
        for off in offs:
            if info["multipart"]:
                off += 4
            y, size = struct.unpack_from("<ii", data, off)
            raw = data[off + 8:off + 8 + size]
            nl = min(LINES[comp], y1 - y + 1)
            full = sum(SIZES[TYPES[t]] for _, t in chans) * w * nl
            if comp != 0 and size < full:
                raw = _unpredict(zlib.decompress(raw) if comp in (2, 3) else _unrle(raw))
            p = 0
            for ly in range(nl):
                row = y - y0 + ly
                for n, t in chans:
                    k = SIZES[TYPES[t]] * w
                    px[n][row * w:(row + 1) * w] = _unpack(t, raw[p:p + k])
                    p += k
        name = a["name"].rstrip(b"\0").decode() if "name" in a else None
        parts.append({"name": name, "dw": (x0, y0, x1, y1), "channels": chans, "pixels": px})
    return parts
