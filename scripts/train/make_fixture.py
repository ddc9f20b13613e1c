#!/usr/bin/env python3
"""Writes tests/learned_fixture.bin (the learned filter v4's parity fixture): synthetic prepared
planes (what the still driver hands the learned cascade: color, variance, albedo, normal, depth), a weight
file with random non-trivial weights and the JAX d_out on them, which tests/learned_test.cpp (C++
inference) and tests/python/test_learn.py (the JAX code as it is now) compare with.
Layout (little-endian):
  "ATRF" | u32 version (4) | u32 width | u32 height | u32 n (weight-file bytes) | the weight file
  | planes color(3), variance(3), albedo(3), normal(3), depth(1), out_d(3): f32, planar, channel-major
    (atrous's Image layout: channel c's plane is height x width row-major)."""
import struct
import sys
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from atrous.learn import context, features, model, weights

PLANES = (("color", 3), ("variance", 3), ("albedo", 3), ("normal", 3), ("depth", 1))
VERSION = 4  # the fixture's own version: 4 holds a version-4 weight file and the v4 d_out


# The terms each fixture must exercise (model.denoise_d's ablation switches, the box inputs, the
# noise plane the cascade reads: 4 v).
ABLATIONS = (("relative colour term", {"colour": False}), ("noise-relative colour term", {"vcolour": False}),
             ("blend", {"blend": False}), ("box inputs", {"box": False}),
             ("noise plane (4 v instead)", {"v_scale": 4.0}), ("context branch", {"ctx": False}))


def make_planes(w: int = 42, h: int = 37, seed: int = 5) -> dict:
    """Prepared planes with an edge (albedo, normal and brightness change at x = w/2), a black-albedo
    patch, sky depth 1e30 (clamped to 1e4 by the inputs), a bright firefly-ish pixel and noise."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w]
    edge = (xx > w // 2).astype(np.float32)[..., None]
    albedo = np.where(edge > 0, [0.8, 0.3, 0.2], [0.2, 0.6, 0.7]).astype(np.float32) * np.ones((h, w, 1), np.float32)
    albedo[:4, :5] = 0.0  # black albedo: inputs 3-5 read 0 there
    normal = np.where(edge > 0, [0, 1, 0], [0.6, 0, 0.8]).astype(np.float32) * np.ones((h, w, 1), np.float32)
    depth = (2.0 + 0.1 * xx + 0.05 * yy).astype(np.float32)[..., None]
    depth[-3:, -4:] = 1e30  # sky
    d = ((0.3 + 1.5 * edge) * rng.gamma(2.0, 0.5, (h, w, 3))).astype(np.float32)
    d[7, 9] = [60.0, 45.0, 30.0]  # a bright, firefly-ish pixel (the driver's clamp leaves some)
    d[12, 3] = 0.0  # a black pixel: kappa's 0.01
    var = (0.2 * d * d + 0.005).astype(np.float32)
    var[:2, -3:] = 0.0  # no variance: input 10 reads log1p(0)
    return {"color": d, "variance": var, "albedo": albedo, "normal": normal, "depth": depth}


def fixture_params(seed: int = 16) -> dict:
    """Random weights of unit-ish scale (every output term active: a, m, b, c of O(1), blend spread),
    the box inputs' rows of w1 4x (else the firefly's d_out of 60 makes their effect < 1% of the
    range). The seed is one of those where every check of main() clears 1%."""
    rng = np.random.default_rng(seed)
    p = {}
    for name, shape in model.SHAPES:
        scale = np.sqrt(2.0 / shape[0]) if name.startswith("w") else 0.5
        p[name] = (rng.standard_normal(shape) * scale).astype(np.float32)
    for name, shape in model.CTX_SHAPES:  # the context: He-scaled kernels, kz of the same order as w1
        fan_in = int(np.prod(shape[:-1]))
        scale = np.sqrt(2.0 / fan_in) if len(shape) > 1 else 0.2
        p[name] = (rng.standard_normal(shape) * scale).astype(np.float32)
    p["kz"] *= 5.0
    p["w3"] *= 0.5
    p["w1"][features.BOX] *= 4.0
    return {k: jnp.asarray(v) for k, v in p.items()}


def d_out_np(params: dict, planes: dict, box: bool = True, v_scale: float = 1.0, ctx: bool = True, **ablate) -> np.ndarray:
    """JAX d_out; box=False zeroes the box inputs, v_scale scales the noise plane (the inputs unchanged),
    ctx=False drops the context branch."""
    x = features.inputs_of(planes)
    cells = jnp.asarray(context.cell_inputs(x, planes["color"])[None]) if ctx else None
    if not box:
        x[..., features.BOX] = 0.0
    v = v_scale * features.variance_plane(planes["variance"])
    out = model.denoise_d(params, jnp.asarray(x[None]), cells, jnp.asarray(planes["color"][None]), jnp.asarray(v[None]),
                          **ablate)
    return np.asarray(out[0])


def read(path: Path):
    """(width, height, weight-file bytes, planes dict incl. out_d) of a fixture file."""
    data = path.read_bytes()
    if data[:4] != b"ATRF" or struct.unpack("<I", data[4:8])[0] != VERSION:
        raise ValueError(f"{path}: not a version-{VERSION} ATRF fixture")
    w, h, n = struct.unpack("<3I", data[8:20])
    wb = data[20:20 + n]
    flat = np.frombuffer(data[20 + n:], "<f4")
    planes, o = {}, 0
    for name, c in PLANES + (("out_d", 3),):
        planes[name] = flat[o:o + c * h * w].reshape(c, h, w).transpose(1, 2, 0).copy()
        o += c * h * w
    if o != flat.size:
        raise ValueError(f"{path}: {flat.size} floats after the weights, expected {o}")
    return w, h, wb, planes


def main() -> int:
    jax.config.update("jax_enable_x64", False)
    planes = make_planes()
    params = fixture_params()
    wbytes = weights.to_bytes(params)
    out = d_out_np(params, planes)
    h, w = out.shape[:2]
    with open(Path(__file__).resolve().parents[2] / "tests" / "learned_fixture.bin", "wb") as f:
        f.write(b"ATRF" + struct.pack("<4I", VERSION, w, h, len(wbytes)) + wbytes)
        for arr in [planes[n] for n, _ in PLANES] + [out]:
            f.write(np.ascontiguousarray(arr.transpose(2, 0, 1), "<f4").tobytes())
    print(f"fixture: {w}x{h}, d_out mean {np.mean(out):.4f}, min {out.min():.4f}, max {out.max():.4f}")
    scale = np.abs(out).max()
    for name, kw in ABLATIONS:
        diff = np.abs(d_out_np(params, planes, **kw) - out).max() / scale
        print(f"  without the {name}: max |change| {diff:.3g} of max |d_out|")
        # tests/learned_test.cpp's tolerance is far below 1%: a C++ port without the term fails it.
        assert diff >= 0.01, f"the fixture does not exercise the {name}"
    return 0


if __name__ == "__main__":
    sys.exit(main())
