"""A small OpenEXR reader and writer in pure Python (numpy + zlib from the standard library).

numpy has no EXR reader and the evaluation must not need a new dependency, so this reads the
subset the atrous renderer and sequence tools write: single-part scanline files with HALF, FLOAT
or UINT channels and NONE, RLE, ZIPS or ZIP compression (the C++ writer, src/io/image_io.cpp, uses
ZIP + FLOAT R, G, B). Tiled, multi-part, deep and the lossy/wavelet codecs (PIZ, PXR24, B44, DWA)
are rejected with a ValueError naming the file and the feature. The writer writes uncompressed
FLOAT R, G, B, which every EXR reader accepts.
"""
from __future__ import annotations

import struct
import zlib
from pathlib import Path
from typing import Dict, Tuple, Union

import numpy as np

_MAGIC = 20000630
_COMPRESSIONS = {0: "NONE", 1: "RLE", 2: "ZIPS", 3: "ZIP", 4: "PIZ", 5: "PXR24", 6: "B44", 7: "B44A",
                 8: "DWAA", 9: "DWAB"}
_LINES_PER_CHUNK = {0: 1, 1: 1, 2: 1, 3: 16}
_PIXEL_TYPES = {0: ("uint32", 4), 1: ("float16", 2), 2: ("float32", 4)}


def _cstring(buf: bytes, pos: int, path: str) -> Tuple[str, int]:
    end = buf.find(b"\0", pos)
    if end < 0:
        raise ValueError(f"{path}: truncated EXR header")
    return buf[pos:end].decode("latin-1"), end + 1


def _parse_header(buf: bytes, path: str) -> Tuple[Dict[str, Tuple[str, bytes]], int]:
    if len(buf) < 8:
        raise ValueError(f"{path}: not an EXR file (too short)")
    magic, version = struct.unpack_from("<ii", buf, 0)
    if magic != _MAGIC:
        raise ValueError(f"{path}: not an EXR file (bad magic number)")
    flags = version >> 8
    if flags & 0x2:
        raise ValueError(f"{path}: tiled EXR files are not supported")
    if flags & 0x8 or flags & 0x10:
        raise ValueError(f"{path}: deep or multi-part EXR files are not supported")
    pos = 8
    attrs: Dict[str, Tuple[str, bytes]] = {}
    while True:
        name, pos = _cstring(buf, pos, path)
        if name == "":
            return attrs, pos
        typ, pos = _cstring(buf, pos, path)
        if pos + 4 > len(buf):
            raise ValueError(f"{path}: truncated EXR header")
        (size,) = struct.unpack_from("<i", buf, pos)
        pos += 4
        if size < 0 or pos + size > len(buf):
            raise ValueError(f"{path}: truncated EXR header (attribute {name})")
        attrs[name] = (typ, buf[pos:pos + size])
        pos += size


def _channels(value: bytes, path: str) -> list:
    out = []
    pos = 0
    while pos < len(value) and value[pos] != 0:
        name, pos = _cstring(value, pos, path)
        ptype, _plinear, xs, ys = struct.unpack_from("<iB3xii", value, pos)
        pos += 16
        if ptype not in _PIXEL_TYPES:
            raise ValueError(f"{path}: channel {name} has unknown pixel type {ptype}")
        if xs != 1 or ys != 1:
            raise ValueError(f"{path}: channel {name} is subsampled ({xs}x{ys}), not supported")
        out.append((name, ptype))
    return out


def _undo_zip_predictor(raw: bytes) -> bytes:
    """OpenEXR's ZIP/RLE byte predictor and even/odd interleave, reversed."""
    t = np.frombuffer(raw, np.uint8)
    # Predictor: each byte was stored as the difference to the previous one plus 128 (mod 256).
    d = np.cumsum(np.concatenate([[int(t[0])], t[1:].astype(np.int64) - 128])) % 256
    d = d.astype(np.uint8)
    half = (len(d) + 1) // 2
    out = np.empty_like(d)
    out[0::2] = d[:half]
    out[1::2] = d[half:]
    return out.tobytes()


def _rle_decode(data: bytes, expected: int, path: str) -> bytes:
    out = bytearray()
    i = 0
    while i < len(data):
        count = struct.unpack_from("b", data, i)[0]
        i += 1
        if count < 0:
            out += data[i:i - count]
            i += -count
        else:
            out += data[i:i + 1] * (count + 1)
            i += 1
    if len(out) != expected:
        raise ValueError(f"{path}: corrupt RLE block")
    return bytes(out)


def read_exr_channels(path: Union[str, Path]) -> Dict[str, np.ndarray]:
    """Every channel of a scanline EXR as an H x W float32 array, by channel name."""
    path = str(path)
    try:
        buf = Path(path).read_bytes()
    except OSError as e:
        raise ValueError(f"{path}: cannot read ({e.strerror})") from None
    attrs, pos = _parse_header(buf, path)
    for need in ("channels", "compression", "dataWindow"):
        if need not in attrs:
            raise ValueError(f"{path}: EXR header has no {need} attribute")
    chans = _channels(attrs["channels"][1], path)
    comp = attrs["compression"][1][0]
    if comp not in _LINES_PER_CHUNK:
        raise ValueError(f"{path}: EXR compression {_COMPRESSIONS.get(comp, comp)} is not supported "
                         "(NONE, RLE, ZIPS and ZIP are)")
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    if width <= 0 or height <= 0:
        raise ValueError(f"{path}: empty data window")
    lines = _LINES_PER_CHUNK[comp]
    nchunks = (height + lines - 1) // lines
    if pos + 8 * nchunks > len(buf):
        raise ValueError(f"{path}: truncated offset table")
    offsets = struct.unpack_from(f"<{nchunks}Q", buf, pos)
    bytes_per_pixel_row = [(_PIXEL_TYPES[t][1] * width) for _, t in chans]
    row_bytes = sum(bytes_per_pixel_row)
    planes = {name: np.zeros((height, width), np.float32) for name, _ in chans}
    for off in offsets:
        if off + 8 > len(buf):
            raise ValueError(f"{path}: chunk offset past the end of the file")
        y, size = struct.unpack_from("<ii", buf, off)
        data = buf[off + 8: off + 8 + size]
        if len(data) != size:
            raise ValueError(f"{path}: truncated chunk at scanline {y}")
        first = y - y0
        nlines = min(lines, height - first)
        if first < 0 or nlines <= 0:
            raise ValueError(f"{path}: chunk scanline {y} outside the data window")
        expected = row_bytes * nlines
        if size < expected and comp != 0:
            # A compressed block; blocks that did not shrink are stored raw (size == expected).
            try:
                raw = zlib.decompress(data) if comp in (2, 3) else _rle_decode(data, expected, path)
            except zlib.error as e:
                raise ValueError(f"{path}: corrupt ZIP block at scanline {y} ({e})") from None
            data = _undo_zip_predictor(raw)
        if len(data) != expected:
            raise ValueError(f"{path}: chunk at scanline {y} has {len(data)} bytes, expected {expected}")
        p = 0
        for line in range(nlines):
            for (name, ptype), nbytes in zip(chans, bytes_per_pixel_row):
                dtype = np.dtype(_PIXEL_TYPES[ptype][0]).newbyteorder("<")
                planes[name][first + line] = np.frombuffer(data, dtype, width, p).astype(np.float32)
                p += nbytes
    return planes


def read_exr(path: Union[str, Path]) -> np.ndarray:
    """An EXR as H x W x 3 float32 (R, G, B; a single channel, e.g. Y or Z, is repeated)."""
    planes = read_exr_channels(path)
    if all(c in planes for c in "RGB"):
        return np.stack([planes["R"], planes["G"], planes["B"]], axis=-1)
    if len(planes) == 1 or "Y" in planes:
        p = planes["Y"] if "Y" in planes else next(iter(planes.values()))
        return np.repeat(p[:, :, None], 3, axis=2)
    if "R" in planes and "G" in planes:  # two-channel data such as motion vectors
        return np.stack([planes["R"], planes["G"], np.zeros_like(planes["R"])], axis=-1)
    raise ValueError(f"{path}: no R, G, B (or single) channels; has {', '.join(sorted(planes))}")


def write_exr(path: Union[str, Path], image: np.ndarray) -> None:
    """Writes H x W x 3 (or H x W) float data as an uncompressed FLOAT R, G, B scanline EXR."""
    img = np.asarray(image, np.float32)
    if img.ndim == 2:
        img = np.repeat(img[:, :, None], 3, axis=2)
    if img.ndim != 3 or img.shape[2] != 3:
        raise ValueError(f"{path}: write_exr needs H x W x 3 or H x W data, got {img.shape}")
    h, w = img.shape[:2]

    def attr(name: str, typ: str, value: bytes) -> bytes:
        return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    header = struct.pack("<ii", _MAGIC, 2)
    header += attr("channels", "chlist", chlist)
    header += attr("compression", "compression", b"\0")
    header += attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    header += attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    header += attr("lineOrder", "lineOrder", b"\0")
    header += attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    header += attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
    header += attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
    header += b"\0"
    row = 12 * w
    table_end = len(header) + 8 * h
    offsets = [table_end + y * (8 + row) for y in range(h)]
    chunks = []
    le = img.astype("<f4")
    for y in range(h):
        # Channels are stored in the chlist's (alphabetical) order: B, G, R.
        data = le[y, :, 2].tobytes() + le[y, :, 1].tobytes() + le[y, :, 0].tobytes()
        chunks.append(struct.pack("<ii", y, row) + data)
    out = Path(path)
    tmp = out.with_name(out.name + ".tmp")
    tmp.write_bytes(header + struct.pack(f"<{h}Q", *offsets) + b"".join(chunks))
    tmp.replace(out)
