"""The learned filter v4's context branch (docs/learned.md, "Context"): a small multi-scale convolutional
network at a quarter and an eighth of the image's resolution whose output shifts the per-pixel MLP's
first hidden layer, so that what a pixel's 3x3 neighbourhood cannot tell (a stripe that continues, a
glass object whose albedo and normal passes are noise, a texture against the noise) is seen over
tens of pixels. src/filters/learned_context.h is the same math in C++.

  cell inputs (1/4 res, 13):  the mean over each 4x4 cell's pixels inside the image of
        log1p d (3), albedo (3), normal (3), log depth, noise (the MLP's inputs 0-10),
        and two spreads: std of L = log1p(mean_c d) and std of the mean albedo within the cell
  c1 = relu(conv3x3(cells, 13 -> 16))                       1/4
  c2 = relu(conv3x3(pool2(c1), 16 -> 16))                   1/8  (pool2: mean over the 2x2 cells inside)
  c3 = relu(conv3x3(c2, 16 -> 16))                          1/8
  c4 = relu(conv3x3(concat(c1, up2(c3)), 32 -> 16))         1/4
  z  = c4 . kz + kbz  (1x1, 16 -> N_HIDDEN)                  1/4
  the MLP's first layer: h1 = relu(x w1 + b1 + up4(z))      full resolution

Convolutions pad with zeros ('SAME'); up_f is bilinear with half-pixel centres and indices clamped
to the image (source coordinate (X + 0.5) / f - 0.5). z is linear and up4 is linear, so up4(z)
equals a 1x1 layer on up4(c4): the context enters the MLP as 16 more inputs would, at the cost of a
bias. With kz = 0 the network is exactly version 3 (how version 3 files are read)."""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from .features import _finite

CELL = 4
N_CTX_IN = 13
N_CTX = 16
# (name, shape): conv kernels HWIO, as the weight file stores them after the MLP's parameters.
SHAPES = (("k1", (3, 3, N_CTX_IN, N_CTX)), ("kb1", (N_CTX,)), ("k2", (3, 3, N_CTX, N_CTX)), ("kb2", (N_CTX,)),
          ("k3", (3, 3, N_CTX, N_CTX)), ("kb3", (N_CTX,)), ("k4", (3, 3, 2 * N_CTX, N_CTX)), ("kb4", (N_CTX,)))


def z_shapes(n_hidden: int):
    return (("kz", (N_CTX, n_hidden)), ("kbz", (n_hidden,)))


def cell_mean(q: np.ndarray, f: int) -> np.ndarray:
    """Mean of an [B x] H x W x C array over each f x f cell's pixels inside the image -> ceil(H/f) x ceil(W/f)."""
    q = np.asarray(q, np.float32)
    lead = q.shape[:-3]
    h, w, c = q.shape[-3:]
    hh, ww = -(-h // f), -(-w // f)
    pad = [(0, 0)] * len(lead) + [(0, hh * f - h), (0, ww * f - w), (0, 0)]
    s = np.pad(q, pad).reshape(*lead, hh, f, ww, f, c).sum(axis=(-4, -2))
    ones = np.pad(np.ones((h, w, 1), np.float32), [(0, hh * f - h), (0, ww * f - w), (0, 0)])
    n = ones.reshape(hh, f, ww, f, 1).sum(axis=(1, 3))
    return (s / n).astype(np.float32)


def cell_inputs(x: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The 13 cell inputs ([B x] ceil(H/4) x ceil(W/4) x 13) of the MLP inputs x ([B x] H x W x 15,
    features.inputs) and the demodulated colour d (for L)."""
    x = np.asarray(x, np.float32)
    lum = np.log1p(np.maximum(_finite(d).mean(axis=-1, keepdims=True), 0.0)).astype(np.float32)
    alum = x[..., 3:6].mean(axis=-1, keepdims=True)
    q = np.concatenate([x[..., 0:3], lum, lum * lum, x[..., 3:6], alum, alum * alum, x[..., 6:11]], axis=-1)
    m = cell_mean(q, CELL)
    sl = np.sqrt(np.maximum(m[..., 4:5] - m[..., 3:4] ** 2, 0.0))
    sa = np.sqrt(np.maximum(m[..., 9:10] - m[..., 8:9] ** 2, 0.0))
    return np.concatenate([m[..., 0:3], sl, m[..., 5:8], sa, m[..., 10:15]], axis=-1).astype(np.float32)


def _up_index(n_out: int, n_in: int, f: int):
    s = (np.arange(n_out) + 0.5) / f - 0.5
    i0 = np.floor(s).astype(np.int64)
    t = (s - i0).astype(np.float32)
    return np.clip(i0, 0, n_in - 1), np.clip(i0 + 1, 0, n_in - 1), t


def upsample(a, f: int, h: int, w: int):
    """Bilinear x f to h x w of a B x hh x ww x C array (half-pixel centres, clamped indices)."""
    y0, y1, ty = _up_index(h, a.shape[1], f)
    x0, x1, tx = _up_index(w, a.shape[2], f)
    ty, tx = jnp.asarray(ty)[None, :, None, None], jnp.asarray(tx)[None, None, :, None]
    r = a[:, y0] * (1.0 - ty) + a[:, y1] * ty
    return r[:, :, x0] * (1.0 - tx) + r[:, :, x1] * tx


def pool2(a):
    """Mean over each 2x2 block's cells inside the array (B x h x w x C -> ceil(h/2) x ceil(w/2))."""
    h, w = a.shape[1], a.shape[2]
    hh, ww = -(-h // 2), -(-w // 2)
    ap = jnp.pad(a, ((0, 0), (0, 2 * hh - h), (0, 2 * ww - w), (0, 0)))
    s = ap.reshape(a.shape[0], hh, 2, ww, 2, a.shape[3]).sum(axis=(2, 4))
    ones = np.pad(np.ones((h, w), np.float32), ((0, 2 * hh - h), (0, 2 * ww - w)))
    n = ones.reshape(hh, 2, ww, 2).sum(axis=(1, 3))
    return s / jnp.asarray(n)[None, :, :, None]


def conv3(a, k, b):
    return jax.lax.conv_general_dilated(a, k, (1, 1), "SAME", dimension_numbers=("NHWC", "HWIO", "NHWC")) + b


def hidden_shift(params: dict, cells, h: int, w: int):
    """up4(z): the context's shift of the first hidden layer (B x h x w x N_HIDDEN) from the cell
    inputs (B x ceil(h/4) x ceil(w/4) x 13)."""
    c1 = jax.nn.relu(conv3(cells, params["k1"], params["kb1"]))
    c2 = jax.nn.relu(conv3(pool2(c1), params["k2"], params["kb2"]))
    c3 = jax.nn.relu(conv3(c2, params["k3"], params["kb3"]))
    u = upsample(c3, 2, c1.shape[1], c1.shape[2])
    c4 = jax.nn.relu(conv3(jnp.concatenate([c1, u], axis=-1), params["k4"], params["kb4"]))
    z = c4 @ params["kz"] + params["kbz"]
    return upsample(z, CELL, h, w)


def init_params(rng: np.random.Generator, n_hidden: int) -> dict:
    """He-initialised convolutions; kz = 0, kbz = 0, so the untrained context changes nothing."""
    p = {}
    for name, shape in SHAPES:
        if name.startswith("kb"):
            p[name] = np.zeros(shape, np.float32)
        else:
            fan_in = shape[0] * shape[1] * shape[2]
            p[name] = (rng.standard_normal(shape) * np.sqrt(2.0 / fan_in)).astype(np.float32)
    for name, shape in z_shapes(n_hidden):
        p[name] = np.zeros(shape, np.float32)
    return p
