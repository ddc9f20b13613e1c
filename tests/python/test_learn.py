"""The learned filter v2's training side (python/atrous/learn, docs/learned.md): the JAX forward pass
still gives tests/learned_fixture.bin's d_out (the file tests/learned_test.cpp holds the C++
inference to), the fixture exercises every term of the spec, the inputs follow the spec's
formulas, and the weight file round-trips and rejects corruption and version 1. Skipped without
jax (it lives in .venv-train: scripts/train/setup.sh)."""
import struct
import sys
from pathlib import Path

import numpy as np
import pytest

jax = pytest.importorskip("jax")
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python" / "atrous"))
sys.path.insert(0, str(ROOT / "scripts" / "train"))
from learn import features, model, weights  # noqa: E402

import make_fixture  # noqa: E402

FIXTURE = ROOT / "tests" / "learned_fixture.bin"


def _fixture():
    w, h, wb, planes = make_fixture.read(FIXTURE)
    params = {k: jax.numpy.asarray(v) for k, v in weights.from_bytes(wb, "fixture").items()}
    return w, h, params, planes


def test_jax_forward_equals_fixture():
    w, h, params, planes = _fixture()
    assert (w, h) == (24, 20)
    out = make_fixture.d_out_np(params, planes)
    # Same code, same float32 inputs: only XLA's reduction order may differ between versions/CPUs
    # (float32 rounding, ~1e-7 relative a step, a few hundred steps: 1e-5 is far above it and far
    # below any change of the math, which moves d_out by > 1e-2, see the next test).
    np.testing.assert_allclose(out, planes["out_d"], rtol=1e-5, atol=1e-5)


def test_fixture_exercises_every_term():
    # Dropping the colour term, the blend or the 3x3 box inputs must each change d_out clearly
    # (>= 1% of its range), so a C++ port that forgets one fails the parity test.
    _, _, params, planes = _fixture()
    out = planes["out_d"]
    scale = np.abs(out).max()
    for kw in ({"colour": False}, {"blend": False}):
        assert np.abs(make_fixture.d_out_np(params, planes, **kw) - out).max() > 0.01 * scale, kw
    x = features.inputs_of(planes)
    x[..., features.BOX] = 0.0
    nobox = np.asarray(model.denoise_d(params, jax.numpy.asarray(x[None]), jax.numpy.asarray(planes["d"][None]))[0])
    assert np.abs(nobox - out).max() > 0.01 * scale
    # The fixture has sky depth, black albedo and a bright pixel (the cases the spec names).
    assert planes["depth"].max() >= 1e30 and planes["albedo"].min() == 0.0 and planes["d"].max() > 40


def test_inputs_follow_the_spec():
    rng = np.random.default_rng(3)
    d = rng.uniform(-0.1, 2.0, (4, 5, 3)).astype(np.float32)
    var = rng.uniform(0.0, 1.0, (4, 5, 3)).astype(np.float32)
    depth = np.full((4, 5, 1), 1e30, np.float32)
    depth[0, 0] = np.nan
    x = features.inputs(d, var, None, None, depth)
    ld = np.log1p(np.maximum(d, 0))
    np.testing.assert_allclose(x[..., 0:3], ld, rtol=1e-6)
    np.testing.assert_array_equal(x[..., 3:6], 1.0)  # no albedo
    np.testing.assert_array_equal(x[..., 6:9], 0.0)  # no normal
    assert x[1, 1, 9] == pytest.approx(np.log(1e4)) and x[0, 0, 9] == pytest.approx(np.log(1e-3))
    np.testing.assert_allclose(x[..., 10], np.log1p(np.sqrt(var.mean(axis=2))), rtol=1e-6)
    # Box statistics: the corner averages its 4 taps inside the image, an interior pixel 9.
    np.testing.assert_allclose(x[0, 0, 11:14], ld[:2, :2].reshape(-1, 3).mean(0), rtol=1e-5)
    np.testing.assert_allclose(x[2, 3, 11:14], ld[1:4, 2:5].reshape(-1, 3).mean(0), rtol=1e-5)
    lum = np.log1p(np.maximum(d.mean(axis=2), 0))
    assert x[2, 3, 14] == pytest.approx(lum[1:4, 2:5].std(), rel=1e-3, abs=1e-6)
    assert x[0, 4, 14] == pytest.approx(lum[:2, 3:5].std(), rel=1e-3, abs=1e-6)
    no_depth = features.inputs(d, var)
    np.testing.assert_array_equal(no_depth[..., 9], 0.0)  # log(1)


def test_weight_file_round_trip_and_errors():
    params = make_fixture.fixture_params()
    b = weights.to_bytes(params)
    assert len(b) == 28 + 4 * 1709 + 4
    back = weights.from_bytes(b)
    for k, v in params.items():
        np.testing.assert_array_equal(np.asarray(v), back[k])
    bad = bytearray(b)
    bad[40] ^= 1
    with pytest.raises(ValueError, match="w.bin: truncated or corrupt"):
        weights.from_bytes(bytes(bad), "w.bin")
    with pytest.raises(ValueError, match="no ATRL header"):
        weights.from_bytes(b"XXXX" + b[4:], "w.bin")
    v1 = b[:4] + struct.pack("<I", 1) + b[8:]
    with pytest.raises(ValueError, match="w.bin: version 1 .*retired.*make train"):
        weights.from_bytes(v1, "w.bin")
    shape = b[:8] + struct.pack("<I", 11) + b[12:]
    with pytest.raises(ValueError, match="w.bin: network shape"):
        weights.from_bytes(shape, "w.bin")


def test_init_starts_near_a_plain_cascade():
    # The initial network is stable: b small, the blend leaning to d_5, every output finite.
    p = model.init_params(1)
    x = jax.numpy.asarray(np.random.default_rng(0).normal(0, 1, (1, 8, 8, features.N_IN)).astype(np.float32))
    f, a, m, b, beta = model.network(p, x)
    assert float(b.max()) < 0.2 and bool((beta.argmax(-1) == model.N_LEVELS).all())
