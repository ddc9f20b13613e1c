"""The learned filter v3's training side (python/atrous/learn, docs/learned.md): the JAX forward pass
still gives tests/learned_fixture.bin's d_out (the file tests/learned_test.cpp holds the C++
inference to), the fixture exercises every term of the spec (the noise-relative colour term
included), the inputs and the noise plane follow the spec's formulas, and the weight file
round-trips and rejects corruption and the retired versions 1 and 2. Skipped without
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
    # Dropping the relative colour term, the noise-relative one, the blend or the 3x3 box inputs, or
    # another noise plane, must each change d_out clearly (>= 1% of its range), so a C++ port that
    # forgets one fails the parity test (its bound is 2e-5 relative).
    _, _, params, planes = _fixture()
    out = planes["out_d"]
    scale = np.abs(out).max()
    # make_fixture.ABLATIONS: colour=False, vcolour=False, blend=False, the box inputs zeroed, and the
    # noise plane 4 v with the inputs unchanged (the cascade reads v itself, not only input 10).
    names = [name for name, _ in make_fixture.ABLATIONS]
    assert len(names) == 5 and "noise-relative colour term" in names
    for name, kw in make_fixture.ABLATIONS:
        assert np.abs(make_fixture.d_out_np(params, planes, **kw) - out).max() > 0.01 * scale, name
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
    # The cascade's noise plane: max(mean_c var_c, 0), non-finite read as 0 (learned.h's pass A).
    var[0, 1] = [np.nan, 0.3, np.inf]
    var[1, 2] = [-1.0, -2.0, 0.5]
    v = features.variance_plane(var)
    assert v.shape == (4, 5, 1) and v.dtype == np.float32
    assert v[0, 1, 0] == pytest.approx(0.1) and v[1, 2, 0] == 0.0
    np.testing.assert_allclose(v[2:, :, 0], var[2:].mean(axis=2), rtol=1e-6)


def test_weight_file_round_trip_and_errors():
    params = make_fixture.fixture_params()
    b = weights.to_bytes(params)
    assert len(b) == 28 + 4 * 1834 + 4
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
    # Version 2 (no noise-relative colour term): the words src/filters/learned_weights.cpp uses too.
    v2 = b[:4] + struct.pack("<I", 2) + b[8:]
    with pytest.raises(ValueError, match=r"^w\.bin: version 2 \(the network without the noise-relative colour term, "
                                         r"retired\); retrain with make train$"):
        weights.from_bytes(v2, "w.bin")
    shape = b[:8] + struct.pack("<I", 11) + b[12:]
    with pytest.raises(ValueError, match="w.bin: network shape"):
        weights.from_bytes(shape, "w.bin")


def test_init_starts_near_a_plain_cascade():
    # The initial network is stable: b and c small, the blend leaning to d_5, every output finite.
    p = model.init_params(1)
    x = jax.numpy.asarray(np.random.default_rng(0).normal(0, 1, (1, 8, 8, features.N_IN)).astype(np.float32))
    f, a, m, b, c, beta = model.network(p, x)
    assert c.shape == b.shape == (1, 8, 8, model.N_LEVELS) and model.N_OUT == 34
    assert float(b.max()) < 0.2 and float(c.max()) < 0.2 and bool((beta.argmax(-1) == model.N_LEVELS).all())
