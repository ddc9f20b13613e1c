"""Per-pixel inputs of the learned filter, in numpy, exactly as src/filters/learned.h computes them
(docs/learned.md, "Inputs"). No JAX here: the pre-processing is not differentiated."""
from __future__ import annotations

import numpy as np

ALBEDO_EPS = 1e-3      # DenoiseOptions::albedoEpsilon
ALBEDO_FLOOR = 0.05    # DenoiseOptions::albedoFloor
RIM_FLOOR_MUL = 2.0    # filters/filter_math.h kRimFloorMul
BLACK_FRACTION = 0.1   # kBlackAlbedoFraction
DEPTH_MIN, DEPTH_MAX = 1e-3, 1e4
N_IN = 11


def _finite(x: np.ndarray) -> np.ndarray:
    return np.where(np.isfinite(x), x, 0.0).astype(np.float32)


def modulation_albedo(albedo: np.ndarray, eps: float = ALBEDO_EPS, floor: float = ALBEDO_FLOOR) -> np.ndarray:
    """a'_c of filter_math.h pixelModulationAlbedo for an H x W x 3 albedo (rim rule included)."""
    v = _finite(albedo)
    m = v.max(axis=2)
    pad = np.pad(m, 1, mode="edge")
    h, w = m.shape
    mn = np.min([pad[dy:dy + h, dx:dx + w] for dy in range(3) for dx in range(3)], axis=0)
    near = ((floor > 0) & (m > 0) & (m < RIM_FLOOR_MUL * floor) & (mn < BLACK_FRACTION * floor)).astype(np.float32)
    fl = np.float32(floor) * (1.0 + near * np.float32(RIM_FLOOR_MUL - 1.0))
    t = np.minimum(m / fl, 1.0) if floor > 0 else np.ones_like(m)
    t = np.where(np.isfinite(t) & (t > 0), t * t, 0.0).astype(np.float32)[..., None]
    mm = np.maximum(v, np.float32(eps))
    return np.where(t >= 1.0, mm, 1.0 + t * (mm - 1.0)).astype(np.float32)


def prepare(color, variance, albedo, normal, depth, emission):
    """(x, d, a', e): network inputs H x W x N_IN, demodulated colour H x W x 3, a' and the emission
    (colour = d a' + e). All buffers H x W x 3 float32 (depth: channel 0 is used)."""
    e = _finite(emission)
    c = np.maximum(_finite(color) - e, 0.0)
    a = modulation_albedo(albedo)
    d = (c / a).astype(np.float32)
    var = np.maximum(_finite(variance), 0.0) / (a * a)
    z = np.log(np.clip(_finite(depth[..., 0]), DEPTH_MIN, DEPTH_MAX))
    sd = np.sqrt(var.mean(axis=2))
    x = np.concatenate([np.log1p(d), np.clip(_finite(albedo), 0.0, 1.0), _finite(normal),
                        z[..., None], np.log1p(sd)[..., None]], axis=2).astype(np.float32)
    return x, d, a, e
