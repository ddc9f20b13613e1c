#!/usr/bin/env python3
"""Writes tests/learned_fixture.bin: a small input set, a weight file and the JAX forward pass's
output on them, which tests/learned_test.cpp (C++ inference) and tests/python/test_learn.py (the
JAX code as it is now) compare with. Layout (little-endian):
  "ATRF" | u32 width | u32 height | u32 n (weight-file bytes) | the weight file
  | 6 inputs (color, variance, albedo, normal, depth, emission) and the output, each 3 planes of
    height x width f32 (atrous's Image layout)."""
import struct
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python" / "atrous"))
import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
from learn import features, model, weights  # noqa: E402

INPUTS = ("color", "variance", "albedo", "normal", "depth", "emission")


def make_inputs(w: int = 24, h: int = 20, seed: int = 5) -> dict:
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w]
    edge = (xx > w // 2).astype(np.float32)[..., None]
    albedo = np.where(edge > 0, [0.8, 0.3, 0.2], [0.2, 0.6, 0.7]).astype(np.float32) * np.ones((h, w, 1), np.float32)
    albedo[:4, :5] = 0.0  # a black-albedo patch: the rim rule and floor
    albedo[4, 2] = 0.07
    normal = np.where(edge > 0, [0, 1, 0], [1, 0, 0]).astype(np.float32) * np.ones((h, w, 1), np.float32)
    depth = (2.0 + 0.1 * xx + 0.05 * yy).astype(np.float32)[..., None].repeat(3, 2)
    depth[-3:, -4:] = 1e30  # sky
    color = (albedo * (0.5 + 2 * edge) * rng.gamma(1.5, 1.0, (h, w, 3))).astype(np.float32)
    color[7, 9] = 40.0  # a firefly
    color[3, 3] = np.nan  # a non-finite sample
    variance = (0.1 * color * color + 0.01).astype(np.float32)
    variance[3, 3] = 0.0
    emission = np.zeros((h, w, 3), np.float32)
    emission[-2:, :3] = 5.0
    color[-2:, :3] += 5.0
    return {"color": color, "variance": variance, "albedo": albedo, "normal": normal, "depth": depth,
            "emission": emission}


def fixture_params(seed: int = 7) -> dict:
    p = model.init_params(seed)
    rng = np.random.default_rng(seed + 1)
    return {k: jnp.asarray(np.asarray(v) + rng.normal(0, 0.3, v.shape).astype(np.float32)) for k, v in p.items()}


def forward_np(params: dict, inputs: dict) -> np.ndarray:
    x, d, a, e = features.prepare(*(inputs[n] for n in INPUTS))
    out = model.forward(params, jnp.asarray(x[None]), jnp.asarray(d[None]), jnp.asarray(a[None]), jnp.asarray(e[None]))
    return np.asarray(out[0])


def main() -> int:
    jax.config.update("jax_enable_x64", False)
    inputs = make_inputs()
    params = fixture_params()
    wbytes = weights.to_bytes(params)
    out = forward_np(params, inputs)
    h, w = out.shape[:2]
    with open(Path(__file__).resolve().parents[2] / "tests" / "learned_fixture.bin", "wb") as f:
        f.write(b"ATRF" + struct.pack("<3I", w, h, len(wbytes)) + wbytes)
        for arr in [inputs[n] for n in INPUTS] + [out]:
            f.write(np.ascontiguousarray(arr.transpose(2, 0, 1), "<f4").tobytes())
    print(f"fixture: {w}x{h}, output mean {np.mean(out):.4f}, min {out.min():.4f}, max {out.max():.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
