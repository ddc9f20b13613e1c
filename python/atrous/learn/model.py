"""The learned filter v4's forward pass in JAX (docs/learned.md): a per-pixel MLP 15 -> 24 -> 24 -> 34, whose
first hidden layer the context branch (context.py) shifts per pixel, gives
a guide feature vector f, per level i a feature bandwidth a_i, a centre weight m_i, a relative colour
bandwidth b_i and a noise-relative colour bandwidth c_i, and 6 blend logits beta; a 5-level à-trous
cascade (B3 5x5 taps at step 2^i, taps outside the image dropped, as src/filters/atrous_level.h)
filters the demodulated colour d, v being the pixel's demodulated variance (mean over channels):

    kappa_i(p)   = 1 / (0.01 + mean_c d_i(p,c)^2)
    nu_i(p, q)   = 1 / (v(p) + v(q) + 0.001 (0.01 + mean_c d_i(p,c)^2))
    D_i(p, q)    = sum_c (d_i(q,c) - d_i(p,c))^2
    w_i(p,q)     = h(q) exp(-a_i(p) |f_p - f_q|^2 - (b_i(p) kappa_i(p) + c_i(p) nu_i(p,q)) D_i(p,q))
    w_i(p,p)     = h(0)^2 (1 + m_i(p))
    d_{i+1}(p)   = sum_q w_i(p,q) d_i(q) / sum_q w_i(p,q)
    d_out(p)     = sum_j softmax(beta(p))_j d_j(p)     (j = 0..5)

The noise-relative term (v3) is EAW's colour stop with a learned, per-pixel, per-level bandwidth: it
keeps an edge much stronger than the noise of the two pixels beside it whatever their brightness
(v2's kappa alone is relative to the pixel's own brightness, so a bright pixel beside a dark one
was averaged with it: the window and light-panel edges of the corpus at 16 spp).
src/filters/learned.h is the same math in C++; tests/learned_test.cpp holds the two equal on
tests/learned_fixture.bin. The ablation switches (colour, vcolour, blend) exist only here."""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from . import context
from .features import N_IN

N_HIDDEN = 24
N_FEAT = 8
N_LEVELS = 5
N_OUT = N_FEAT + 4 * N_LEVELS + (N_LEVELS + 1)
B3 = (1.0 / 16, 1.0 / 4, 3.0 / 8, 1.0 / 4, 1.0 / 16)
KAPPA_EPS = 0.01
NU_REL = 0.001  # nu's floor, relative to the pixel's brightness (0.01 + mean d^2)
SHAPES = (("w1", (N_IN, N_HIDDEN)), ("b1", (N_HIDDEN,)), ("w2", (N_HIDDEN, N_HIDDEN)), ("b2", (N_HIDDEN,)),
          ("w3", (N_HIDDEN, N_OUT)), ("b3", (N_OUT,)))
# Version 4: the context branch's parameters follow the MLP's.
CTX_SHAPES = context.SHAPES + context.z_shapes(N_HIDDEN)
ALL_SHAPES = SHAPES + CTX_SHAPES
# Output slices, in the weight file's order.
F_ = slice(0, N_FEAT)
A_ = slice(N_FEAT, N_FEAT + N_LEVELS)
M_ = slice(N_FEAT + N_LEVELS, N_FEAT + 2 * N_LEVELS)
BC_ = slice(N_FEAT + 2 * N_LEVELS, N_FEAT + 3 * N_LEVELS)
BV_ = slice(N_FEAT + 3 * N_LEVELS, N_FEAT + 4 * N_LEVELS)
BETA_ = slice(N_FEAT + 4 * N_LEVELS, N_OUT)


def init_params(seed: int) -> dict:
    """He-initialised MLP; the last layer small, its biases chosen so training starts near a plain
    B3 cascade: a_i, m_i about softplus(0) = 0.69, b_i and c_i small (softplus(-3) = 0.05), the blend
    leaning to d_5 (logit +1 against 0)."""
    rng = np.random.default_rng(seed)
    p = {}
    for name, shape in SHAPES:
        if name.startswith("w"):
            p[name] = (rng.standard_normal(shape) * np.sqrt(2.0 / shape[0])).astype(np.float32)
        else:
            p[name] = np.zeros(shape, np.float32)
    p["w3"] *= 0.1
    p["b3"][BC_] = -3.0
    p["b3"][BV_] = -3.0
    p["b3"][BETA_.stop - 1] = 1.0
    p.update(context.init_params(rng, N_HIDDEN))
    return {k: jnp.asarray(v) for k, v in p.items()}


def softplus(x):
    # log(1 + e^x) written as C++ writes it (learned.h): max(x, 0) + log1p(exp(-|x|)).
    return jnp.maximum(x, 0.0) + jnp.log1p(jnp.exp(-jnp.abs(x)))


def network(params: dict, x, cells=None):
    """x: B x H x W x N_IN, cells: its context cell inputs (context.cell_inputs) or None (no context)
    -> (f ... x N_FEAT, a, m, b, c ... x N_LEVELS, beta ... x N_LEVELS + 1)."""
    pre = x @ params["w1"] + params["b1"]
    if cells is not None:
        pre = pre + context.hidden_shift(params, cells, x.shape[1], x.shape[2])
    h = jax.nn.relu(pre)
    h = jax.nn.relu(h @ params["w2"] + params["b2"])
    o = h @ params["w3"] + params["b3"]
    return (o[..., F_], softplus(o[..., A_]), softplus(o[..., M_]), softplus(o[..., BC_]), softplus(o[..., BV_]),
            o[..., BETA_])


def _shift(arr, dy: int, dx: int, pad: int):
    """arr[b, y + dy, x + dx] (zero outside the image) of a B x H x W x C array padded by `pad`."""
    h, w = arr.shape[1] - 2 * pad, arr.shape[2] - 2 * pad
    return arr[:, pad + dy:pad + dy + h, pad + dx:pad + dx + w]


def _level(d, v, f, ai, mi, bi, ci, s, colour: bool, vcolour: bool, pad: int):
    """One level at step s (a traced int: one compiled body serves all levels), every array padded
    by `pad` >= 2 s; taps outside the image carry validity 0."""
    bsz, h, w = d.shape[0], d.shape[1], d.shape[2]
    padw = ((0, 0), (pad, pad), (pad, pad), (0, 0))
    dp, fp, varp = jnp.pad(d, padw), jnp.pad(f, padw), jnp.pad(v, padw)
    vp = jnp.pad(jnp.ones((bsz, h, w, 1), d.dtype), padw)
    bright = KAPPA_EPS + jnp.mean(jnp.square(d), axis=-1, keepdims=True)
    bk = bi / bright
    vfloor = v + NU_REL * bright

    def tap(arr, qy, qx):
        return jax.lax.dynamic_slice(arr, (0, pad + qy * s, pad + qx * s, 0), (bsz, h, w, arr.shape[3]))

    num = B3[2] * B3[2] * (1.0 + mi) * d
    den = B3[2] * B3[2] * (1.0 + mi)
    for qy in range(-2, 3):
        for qx in range(-2, 3):
            if qy == 0 and qx == 0:
                continue
            dq, fq, vq = tap(dp, qy, qx), tap(fp, qy, qx), tap(vp, qy, qx)
            e = ai * jnp.sum(jnp.square(f - fq), axis=-1, keepdims=True)
            dd = jnp.sum(jnp.square(dq - d), axis=-1, keepdims=True)
            if colour:
                e = e + bk * dd
            if vcolour:
                e = e + ci / (vfloor + tap(varp, qy, qx)) * dd
            wq = (B3[qy + 2] * B3[qx + 2]) * vq * jnp.exp(-e)
            num = num + wq * dq
            den = den + wq
    return num / den


def cascade(d, v, f, a, m, b, c, beta, colour: bool = True, blend: bool = True, vcolour: bool = True):
    """d: B x H x W x 3 demodulated colour, v: B x H x W x 1 its variance (variance_plane), the rest from
    network(); returns d_out (B x H x W x 3). colour=False drops the relative colour term (b = 0),
    vcolour=False the noise-relative one (c = 0), blend=False returns d_5 (ablations only)."""
    pad = 2 << (N_LEVELS - 1)

    def body(di, i):
        sel = lambda t: jax.lax.dynamic_slice_in_dim(t, i, 1, axis=-1)  # noqa: E731
        dn = _level(di, v, f, sel(a), sel(m), sel(b), sel(c), jnp.left_shift(1, i), colour, vcolour, pad)
        return dn, dn

    d_last, levels = jax.lax.scan(body, d, jnp.arange(N_LEVELS))
    if not blend:
        return d_last
    wts = jax.nn.softmax(beta, axis=-1)
    return wts[..., :1] * d + jnp.einsum("bhwl,lbhwc->bhwc", wts[..., 1:], levels)


def denoise_d(params: dict, x, cells, d, v, colour: bool = True, blend: bool = True, vcolour: bool = True):
    """d_out of the network inputs x (B x H x W x N_IN), their cell inputs (None: no context), the
    demodulated colour d and its variance v."""
    f, a, m, b, c, beta = network(params, x, cells)
    return cascade(d, v, f, a, m, b, c, beta, colour, blend, vcolour)


def forward(params: dict, x, cells, d, v, mod, e, colour: bool = True, blend: bool = True, vcolour: bool = True):
    """The library's output (safety net off): d_out mod + e (B x H x W x 3)."""
    return denoise_d(params, x, cells, d, v, colour, blend, vcolour) * mod + e


def relmse(out, ref, eps: float = 0.01, axis=None):
    """docs/eval.md's relMSE: mean of (x - r)^2 / (r^2 + eps) over pixels and channels (eps 0.01);
    axis: the axes to average over (None: all; the training loss takes each crop's)."""
    return jnp.mean(jnp.square(out - ref) / (jnp.square(ref) + eps), axis=axis)
