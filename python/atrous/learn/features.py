"""The learned filter's per-pixel inputs (docs/learned.md, "Inputs"), in numpy, from the still
driver's prepared planes (atrous.prepared_planes: color, variance, albedo, normal, depth), exactly as
src/filters/learned.h computes them. No JAX here: the inputs are not differentiated.

    0-2   log1p(max(d_c, 0))
    3-5   albedo present ? clamp(albedo_c, 0, 1) : 1
    6-8   normal present ? normal_c : 0
    9     log(clamp(depth present ? depth : 1, 1e-3, 1e4))
    10    log1p(sqrt(max(mean_c var_c, 0)))
    11-13 3x3 box mean of inputs 0-2 (over the taps inside the image)
    14    3x3 local std of L = log1p(max(mean_c d_c, 0)): sqrt(max(E[L^2] - E[L]^2, 0)), same taps
Non-finite plane values read as 0."""
from __future__ import annotations

import numpy as np

DEPTH_MIN, DEPTH_MAX = 1e-3, 1e4
N_IN = 15
BOX = slice(11, 15)  # the neighbourhood inputs (the "no box" ablation masks them)


def _finite(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, np.float32)
    return np.where(np.isfinite(x), x, np.float32(0.0)).astype(np.float32)


def box3(x: np.ndarray) -> np.ndarray:
    """3x3 mean of an H x W x C array over the taps inside the image (edges: fewer taps)."""
    h, w = x.shape[:2]
    p = np.pad(x, ((1, 1), (1, 1), (0, 0)))
    ones = np.pad(np.ones((h, w, 1), np.float32), ((1, 1), (1, 1), (0, 0)))
    s = np.zeros_like(x)
    n = np.zeros((h, w, 1), np.float32)
    for dy in range(3):
        for dx in range(3):
            s += p[dy:dy + h, dx:dx + w]
            n += ones[dy:dy + h, dx:dx + w]
    return (s / n).astype(np.float32)


def inputs(d, var, albedo=None, normal=None, depth=None) -> np.ndarray:
    """The network inputs H x W x N_IN of one image's prepared planes (H x W x 3; depth H x W x 1 or
    x 3, channel 0 used; albedo/normal/depth None when absent)."""
    d = _finite(d)
    h, w = d.shape[:2]
    ld = np.log1p(np.maximum(d, 0.0))
    alb = np.clip(_finite(albedo), 0.0, 1.0) if albedo is not None else np.ones((h, w, 3), np.float32)
    nrm = _finite(normal) if normal is not None else np.zeros((h, w, 3), np.float32)
    z = _finite(depth)[..., :1] if depth is not None else np.ones((h, w, 1), np.float32)
    z = np.log(np.clip(z, DEPTH_MIN, DEPTH_MAX))
    sd = np.log1p(np.sqrt(np.maximum(_finite(var).mean(axis=2, keepdims=True), 0.0)))
    lum = np.log1p(np.maximum(d.mean(axis=2, keepdims=True), 0.0))
    m = box3(np.concatenate([ld, lum, lum * lum], axis=2))
    std = np.sqrt(np.maximum(m[..., 4:5] - m[..., 3:4] ** 2, 0.0))
    return np.concatenate([ld, alb, nrm, z, sd, m[..., :3], std], axis=2).astype(np.float32)


def variance_plane(var) -> np.ndarray:
    """The cascade's noise plane v (H x W x 1): max(mean_c var_c, 0), non-finite read as 0 (learned.h's
    LearnedLogPass writes the same)."""
    return np.maximum(_finite(var).mean(axis=2, keepdims=True), 0.0).astype(np.float32)


def inputs_of(planes: dict, suffix: str = "") -> np.ndarray:
    """inputs() of a dict holding d, var and optionally albedo, normal, depth (keys + suffix)."""
    g = planes.get
    return inputs(planes["color" + suffix], planes["variance" + suffix], g("albedo" + suffix), g("normal" + suffix),
                  g("depth" + suffix))
