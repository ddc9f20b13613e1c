"""The learned filter's forward pass in JAX (docs/learned.md): a per-pixel MLP gives a guide feature
vector f and, per level i, a bandwidth a_i and a centre weight m_i; a 5-level à-trous cascade (B3
5x5 taps at step 2^i, taps outside the image dropped, as src/filters/atrous_level.h) filters the
demodulated colour with w = h(q) exp(-a_i(p) |f_p - f_q|^2), the centre tap h(0)^2 (1 + m_i(p)).
src/filters/learned.h is the same math in C++; tests/learned_test.cpp holds the two equal."""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from .features import N_IN

N_HIDDEN = 16
N_FEAT = 8
N_LEVELS = 5
N_OUT = N_FEAT + 2 * N_LEVELS
B3 = (1.0 / 16, 1.0 / 4, 3.0 / 8, 1.0 / 4, 1.0 / 16)
SHAPES = (("w1", (N_IN, N_HIDDEN)), ("b1", (N_HIDDEN,)), ("w2", (N_HIDDEN, N_HIDDEN)), ("b2", (N_HIDDEN,)),
          ("w3", (N_HIDDEN, N_OUT)), ("b3", (N_OUT,)))


def init_params(seed: int) -> dict:
    rng = np.random.default_rng(seed)
    p = {}
    for name, shape in SHAPES:
        if name.startswith("w"):
            p[name] = (rng.standard_normal(shape) * np.sqrt(2.0 / shape[0])).astype(np.float32)
        else:
            p[name] = np.zeros(shape, np.float32)
    p["w3"] *= 0.3
    return {k: jnp.asarray(v) for k, v in p.items()}


def softplus(x):
    # log(1 + e^x) written as C++ writes it (learned.h): max(x, 0) + log1p(exp(-|x|)).
    return jnp.maximum(x, 0.0) + jnp.log1p(jnp.exp(-jnp.abs(x)))


def network(params: dict, x):
    """x: ... x N_IN -> (f ... x N_FEAT, a ... x N_LEVELS, m ... x N_LEVELS)."""
    h = jax.nn.relu(x @ params["w1"] + params["b1"])
    h = jax.nn.relu(h @ params["w2"] + params["b2"])
    o = h @ params["w3"] + params["b3"]
    return o[..., :N_FEAT], softplus(o[..., N_FEAT:N_FEAT + N_LEVELS]), softplus(o[..., N_FEAT + N_LEVELS:])


def _shift(arr, dy: int, dx: int, pad: int):
    """arr[b, y + dy, x + dx] (zero outside the image) of a B x H x W x C array padded by `pad`."""
    h, w = arr.shape[1] - 2 * pad, arr.shape[2] - 2 * pad
    return arr[:, pad + dy:pad + dy + h, pad + dx:pad + dx + w]


def cascade(d, f, a, m):
    """d: B x H x W x 3 demodulated colour, f/a/m from network(); returns the filtered d."""
    ones = jnp.ones(d.shape[:3] + (1,), d.dtype)
    for i in range(N_LEVELS):
        s = 1 << i
        P = 2 * s
        padw = ((0, 0), (P, P), (P, P), (0, 0))
        dp, fp, vp = jnp.pad(d, padw), jnp.pad(f, padw), jnp.pad(ones, padw)
        ai, mi = a[..., i:i + 1], m[..., i:i + 1]
        num = jnp.zeros_like(d)
        den = jnp.zeros_like(ones)
        for qy in range(-2, 3):
            for qx in range(-2, 3):
                hxy = B3[qy + 2] * B3[qx + 2]
                dq = _shift(dp, qy * s, qx * s, P)
                if qy == 0 and qx == 0:
                    w = hxy * (1.0 + mi)
                else:
                    fq = _shift(fp, qy * s, qx * s, P)
                    vq = _shift(vp, qy * s, qx * s, P)
                    w = hxy * vq * jnp.exp(-ai * jnp.sum(jnp.square(f - fq), axis=-1, keepdims=True))
                num = num + w * dq
                den = den + w
        d = num / den
    return d


def forward(params: dict, x, d, alb, e):
    """The filtered colour: cascade(d) a' + e (B x H x W x 3)."""
    f, a, m = network(params, x)
    return cascade(d, f, a, m) * alb + e


def relmse(out, ref):
    """docs/eval.md's relMSE: mean of (x - r)^2 / (r^2 + 0.01) over pixels and channels."""
    return jnp.mean(jnp.square(out - ref) / (jnp.square(ref) + 0.01))
