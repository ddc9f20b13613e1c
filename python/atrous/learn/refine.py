"""The refine stage (docs/learned.md, "Refine"; src/filters/refine.h is the same math in C++/CUDA):
a U-Net that predicts a residual r in log space after a still method, refined = max(expm1(log1p(
max(base, 0)) + clip(r, +-3)), 0), then scaled by a smooth gain that gives it the method's light at
the scale of 64-pixel blocks (the energy gain). Its inputs, the network, its weight file. NumPy only, except `forward`, which takes
the array module and a convolution (NumPy here for the reference, JAX in scripts/train/refine.py).

Weight file, version 1 (read by src/filters/refine_weights.cpp): little-endian
  "ATRF" | u32 version | u32 n_in, c1, c2, c3, n_floats | u32 steps | 48 bytes: the run's name,
  NUL-padded | n_floats f32 in SHAPES' order (kernels HWIO) | u32 FNV-1a of every byte before it.
"""
from __future__ import annotations

import math
import struct

import numpy as np

N_IN, C1, C2, C3, N_OUT = 15, 16, 24, 32, 3
NOISE_RADIUS = 3
MAX_RESIDUAL = 3.0
ENERGY_BLOCK, GAIN_EPS, GAIN_MAX, GAIN_ITERATIONS = 64, 1e-4, 4.0, 3
MAGIC, VERSION, RUN_BYTES = b"ATRF", 1, 48

SHAPES = (("k1", (3, 3, N_IN, C1)), ("b1", (C1,)), ("k1b", (3, 3, C1, C1)), ("b1b", (C1,)),
          ("k2", (3, 3, C1, C2)), ("b2", (C2,)), ("k2b", (3, 3, C2, C2)), ("b2b", (C2,)),
          ("k3", (3, 3, C2, C3)), ("b3", (C3,)), ("k3b", (3, 3, C3, C3)), ("b3b", (C3,)),
          ("ku2", (3, 3, C3 + C2, C2)), ("bu2", (C2,)), ("ku1", (3, 3, C2 + C1, C1)), ("bu1", (C1,)),
          ("ko", (1, 1, C1, N_OUT)), ("bo", (N_OUT,)))
N_PARAMS = sum(int(np.prod(s)) for _, s in SHAPES)  # 47 323


def _log(v):
    v = np.where(np.isfinite(v) & (v > 0), v, 0).astype(np.float32)
    return np.log1p(v)


def noise_level(lbase, lcolor, radius=NOISE_RADIUS):
    """The 7x7 mean (edges replicated) of |log1p(noisy) - log1p(base)| per channel."""
    d = np.abs(lcolor - lbase).astype(np.float64)
    k = 2 * radius + 1
    s = np.pad(d, ((radius, radius), (radius, radius), (0, 0)), mode="edge").cumsum(0).cumsum(1)
    s = np.pad(s, ((1, 0), (1, 0), (0, 0)))
    return ((s[k:, k:] - s[:-k, k:] - s[k:, :-k] + s[:-k, :-k]) / (k * k)).astype(np.float32)


def features(base, color, albedo, normal):
    """The network's inputs, H x W x 15 float32: log1p of the method's output and of the noisy
    colour, the albedo in [0, 1], the normal in [-1, 1], the noise level."""
    lb, lc = _log(base[..., :3]), _log(color[..., :3])
    a = np.clip(np.nan_to_num(albedo[..., :3], nan=0, posinf=0, neginf=0), 0, 1)
    n = np.clip(np.nan_to_num(normal[..., :3], nan=0, posinf=0, neginf=0), -1, 1)
    return np.concatenate([lb, lc, a, n, noise_level(lb, lc)], axis=-1).astype(np.float32)


def pad4(a):
    """Rows and columns replicated to a multiple of 4 a side (H x W x C)."""
    h, w = a.shape[:2]
    return np.pad(a, ((0, (-h) % 4), (0, (-w) % 4), (0, 0)), mode="edge")


def init(seed=0):
    rng = np.random.default_rng(seed)
    p = {}
    for name, shp in SHAPES:
        if name.startswith("b"):
            p[name] = np.zeros(shp, np.float32)
        else:
            p[name] = (rng.standard_normal(shp) * math.sqrt(2.0 / (shp[0] * shp[1] * shp[2]))).astype(np.float32)
    p["ko"] *= 0.01  # start near the method's output
    return p


def forward(p, x, conv, xp=np):
    """x: N x H x W x 15 (H, W multiples of 4) -> the residual r, N x H x W x 3 (unclipped).
    conv(a, k, b): a SAME convolution (NHWC, HWIO) plus bias; xp: the array module."""
    def relu(a):
        return xp.maximum(a, 0)

    def down(a):
        n, h, w, c = a.shape
        return a.reshape(n, h // 2, 2, w // 2, 2, c).mean(axis=(2, 4))

    def up(a):
        return xp.repeat(xp.repeat(a, 2, axis=1), 2, axis=2)

    e1 = relu(conv(relu(conv(x, p["k1"], p["b1"])), p["k1b"], p["b1b"]))
    e2 = relu(conv(relu(conv(down(e1), p["k2"], p["b2"])), p["k2b"], p["b2b"]))
    e3 = relu(conv(relu(conv(down(e2), p["k3"], p["b3"])), p["k3b"], p["b3b"]))
    d2 = relu(conv(xp.concatenate([up(e3), e2], -1), p["ku2"], p["bu2"]))
    d1 = relu(conv(xp.concatenate([up(d2), e1], -1), p["ku1"], p["bu1"]))
    return conv(d1, p["ko"], p["bo"])


def apply_residual(base, r, xp=np):
    """refined = max(expm1(log1p(max(base, 0)) + clip(r, +-MAX_RESIDUAL)), 0)."""
    return xp.maximum(xp.expm1(xp.log1p(xp.maximum(base, 0.0)) + xp.clip(r, -MAX_RESIDUAL, MAX_RESIDUAL)), 0.0)


def energy_gain_crop(base, refined, xp=np):
    """The energy gain on crops of one block (training's 64^2 crops): the hat weights are then 1
    everywhere and the fixed point is the crop's mean of the base over the refined's, per image
    and channel (N x H x W x 3)."""
    mb, mr = base.mean(axis=(1, 2), keepdims=True), refined.mean(axis=(1, 2), keepdims=True)
    return refined * xp.clip((mb + GAIN_EPS) / (mr + GAIN_EPS), 1 / GAIN_MAX, GAIN_MAX)


def _hat(n):
    """n x blocks: the weight output i's bilinear taps (half-pixel centres, clamped) give block b."""
    nb = -(-n // ENERGY_BLOCK)
    s = (np.arange(n) + 0.5) / ENERGY_BLOCK - 0.5
    fl = np.floor(s)
    t = (s - fl).astype(np.float32)
    i0, i1 = np.clip(fl.astype(int), 0, nb - 1), np.clip(fl.astype(int) + 1, 0, nb - 1)
    m = np.zeros((n, nb), np.float32)
    np.add.at(m, (np.arange(n), i0), 1 - t)
    np.add.at(m, (np.arange(n), i1), t)
    return m


def energy_gain(base, refined):
    """The energy gain on one image (H x W x 3, NumPy; src/filters/refine.h RefineGainRows,
    RefineGainStep, RefineApply): G = Wy g Wx^T per channel with the hat weights W, g from
    GAIN_ITERATIONS steps g *= (Wy^T base Wx + eps) / (Wy^T (refined G) Wx + eps) from 1, clamped."""
    h, w = base.shape[:2]
    wy, wx = _hat(h).astype(np.float64), _hat(w).astype(np.float64)
    g = np.ones((wy.shape[1], wx.shape[1], 3))
    sb = np.einsum("yb,yxk,xc->bck", wy, base.astype(np.float64), wx)
    for _ in range(GAIN_ITERATIONS):
        G = np.einsum("yb,bck,xc->yxk", wy, g, wx)
        sr = np.einsum("yb,yxk,xc->bck", wy, refined.astype(np.float64) * G, wx)
        g = np.clip(g * (sb + GAIN_EPS) / (sr + GAIN_EPS), 1 / GAIN_MAX, GAIN_MAX)
    return (refined * np.einsum("yb,bck,xc->yxk", wy, g, wx)).astype(np.float32)


def conv_numpy(a, k, b):
    """The reference convolution (float64 accumulation): zero padding, cross-correlation."""
    kh, kw, _, co = k.shape
    n, h, w, _ = a.shape
    ap = np.pad(a.astype(np.float64), ((0, 0), (kh // 2, kh // 2), (kw // 2, kw // 2), (0, 0)))
    out = np.zeros((n, h, w, co)) + b
    for dy in range(kh):
        for dx in range(kw):
            out += ap[:, dy:dy + h, dx:dx + w, :] @ k[dy, dx].astype(np.float64)
    return out


def refine_numpy(p, base, color, albedo, normal):
    """The stage on one image (H x W x 3 each), the reference for the C++ (tests/python)."""
    h, w = base.shape[:2]
    x = pad4(features(base, color, albedo, normal))[None]
    r = forward(p, x, conv_numpy)[0, :h, :w]
    b = np.where(np.isfinite(base[..., :3]), base[..., :3], 0).astype(np.float32)
    return energy_gain(b, apply_residual(b, r).astype(np.float32)).astype(np.float32)


def fnv1a(data: bytes) -> int:
    h = 0x811C9DC5
    for b in data:
        h = ((h ^ b) * 0x01000193) & 0xFFFFFFFF
    return h


def to_bytes(params: dict, run: str = "", steps: int = 0) -> bytes:
    flat = np.concatenate([np.asarray(params[n], np.float32).reshape(-1) for n, _ in SHAPES]).astype("<f4")
    assert flat.size == N_PARAMS
    name = run.encode()[:RUN_BYTES].ljust(RUN_BYTES, b"\0")
    body = MAGIC + struct.pack("<7I", VERSION, N_IN, C1, C2, C3, flat.size, int(steps)) + name + flat.tobytes()
    return body + struct.pack("<I", fnv1a(body))


def from_bytes(data: bytes) -> tuple:
    """-> (params, run, steps); ValueError on anything else than a version-1 file of this shape."""
    if data[:4] != MAGIC:
        raise ValueError("not a refine weight file")
    version, n_in, c1, c2, c3, n, steps = struct.unpack_from("<7I", data, 4)
    if (version, n_in, c1, c2, c3, n) != (VERSION, N_IN, C1, C2, C3, N_PARAMS):
        raise ValueError(f"version/shape {version}/{n_in}/{c1}/{c2}/{c3}/{n} is not {VERSION}/{N_IN}/{C1}/{C2}/{C3}/{N_PARAMS}")
    head = 32 + RUN_BYTES
    if len(data) != head + 4 * n + 4 or struct.unpack_from("<I", data, len(data) - 4)[0] != fnv1a(data[:-4]):
        raise ValueError("truncated or corrupt refine weight file")
    flat = np.frombuffer(data, "<f4", n, head).astype(np.float32)
    params, o = {}, 0
    for name, shp in SHAPES:
        size = int(np.prod(shp))
        params[name] = flat[o:o + size].reshape(shp)
        o += size
    return params, data[32:head].rstrip(b"\0").decode(), steps
