"""The refine method from Python (docs/refine.md): atrous.denoise(..., method="refine") equals
the training code's NumPy reference (python/atrous/learn/refine.py: features, the U-Net, the
residual) applied to the same method's output, so the weights trained in JAX mean in C++ what they
meant in training; and the built-in weight file reads back as the network's shapes."""
from pathlib import Path

import numpy as np
import pytest

import atrous
from atrous.learn import refine as R

ROOT = Path(__file__).resolve().parents[2]


def _scene(h, w, seed):
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w] / max(h, w)
    truth = np.stack([0.3 + xx, 0.2 + yy, 0.5 + 0.3 * np.sin(8 * xx)], -1)
    truth[h // 3:2 * h // 3, w // 4:w // 2] *= 3.0  # a bright box
    color = (truth * rng.gamma(2.0, 0.5, (h, w, 3))).astype(np.float32)  # 2-sample-like noise
    albedo = np.clip(truth / truth.max(), 0, 1).astype(np.float32)
    normal = np.zeros((h, w, 3), np.float32)
    normal[..., 2] = 1
    normal[h // 3:2 * h // 3, w // 4:w // 2] = (0.6, 0, 0.8)
    return color, albedo, normal


@pytest.mark.parametrize("h,w", [(37, 45), (64, 64)])
def test_refine_equals_the_training_reference(h, w):
    color, albedo, normal = _scene(h, w, 3)
    base = atrous.denoise(color, albedo=albedo, normal=normal, method="sure")
    out = atrous.denoise(color, albedo=albedo, normal=normal, method="refine")
    params, run, steps = R.from_bytes((ROOT / "src/filters/refine_default.atrf").read_bytes())
    ref = R.refine_numpy(params, base, color, albedo, normal)
    # Tolerance: float32 in C++ (oneDNN's summation order) against float64 accumulation here,
    # through eight layers and an exp: 1e-4 relative (measured ~2e-5). A wrong input order, a
    # missed padding row or another upsampling is off by 1e-2 or more.
    np.testing.assert_allclose(out, ref, rtol=1e-4, atol=1e-5)
    assert np.abs(out - base).mean() > 1e-3 * np.abs(base).mean()  # the stage did something


def test_refine_needs_albedo_and_normal():
    color, albedo, normal = _scene(24, 20, 4)
    with pytest.raises(ValueError, match="needs an albedo and a normal"):
        atrous.denoise(color, normal=normal, method="refine")
    with pytest.raises(ValueError, match="needs an albedo and a normal"):
        atrous.denoise(color, albedo=albedo, method="refine")


def test_builtin_weights_read_back():
    params, run, steps = R.from_bytes((ROOT / "src/filters/refine_default.atrf").read_bytes())
    assert run and steps > 0
    assert {k: v.shape for k, v in params.items()} == dict(R.SHAPES)
    assert sum(v.size for v in params.values()) == R.N_PARAMS == 47323
    assert R.from_bytes(R.to_bytes(params, run, steps))[1:] == (run, steps)
    bad = bytearray(R.to_bytes(params, run, steps))
    bad[100] ^= 1
    with pytest.raises(ValueError):
        R.from_bytes(bytes(bad))
