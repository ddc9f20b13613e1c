"""The learned filter v4's training side (python/atrous/learn, docs/learned.md): the JAX forward pass
still gives tests/learned_fixture.bin's d_out (the file tests/learned_test.cpp holds the C++
inference to), the fixture exercises every term of the spec (the noise-relative colour term and the
context branch included), the inputs, the context's cell inputs and the noise plane follow the
spec's formulas, and the weight file round-trips, reads version 3 as version 4 without a context and
rejects corruption and the retired versions 1 and 2. Skipped without
jax (it lives in .venv-train: scripts/train/setup.sh)."""
import struct
from pathlib import Path

import numpy as np
import pytest

jax = pytest.importorskip("jax")
ROOT = Path(__file__).resolve().parents[2]
from atrous.learn import context, features, model, weights  # noqa: E402

import make_fixture  # noqa: E402  (scripts/train: pytest's pythonpath, pyproject.toml)

FIXTURE = ROOT / "tests" / "learned_fixture.bin"


def _fixture():
    w, h, wb, planes = make_fixture.read(FIXTURE)
    params = {k: jax.numpy.asarray(v) for k, v in weights.from_bytes(wb, "fixture").items()}
    return w, h, params, planes


def test_jax_forward_equals_fixture():
    w, h, params, planes = _fixture()
    assert (w, h) == (42, 37)  # partial 4x4 cells and 8x8 blocks on both axes
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
    assert len(names) == 6 and "noise-relative colour term" in names and "context branch" in names
    for name, kw in make_fixture.ABLATIONS:
        assert np.abs(make_fixture.d_out_np(params, planes, **kw) - out).max() > 0.01 * scale, name
    # The fixture has sky depth, black albedo and a bright pixel (the cases the spec names).
    assert planes["depth"].max() >= 1e30 and planes["albedo"].min() == 0.0 and planes["color"].max() > 40


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
    assert len(b) == 36 + 4 * (1834 + 11560) + 4
    back = weights.from_bytes(b)
    for k, v in params.items():
        np.testing.assert_array_equal(np.asarray(v), back[k])
    assert weights.has_context(back)
    # Version 3: the MLP alone, read with the context zero (the same function as no context).
    body = b[:4] + struct.pack("<6I", 3, *struct.unpack("<4I", b[8:24]), 1834) + b[36:36 + 4 * 1834]
    v3 = weights.from_bytes(body + struct.pack("<I", weights.fnv1a(body)), "v3.bin")
    np.testing.assert_array_equal(v3["w1"], back["w1"])
    assert not weights.has_context(v3) and not np.any(v3["k1"])
    # Parameters whose context is all zero are written as that version-3 file, byte for byte.
    assert weights.to_bytes(v3) == body + struct.pack("<I", weights.fnv1a(body))
    with pytest.raises(ValueError, match="w.bin: version 5, this build reads versions 3 and 4"):
        weights.from_bytes(b[:4] + struct.pack("<I", 5) + b[8:], "w.bin")
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


def test_cell_inputs_follow_the_spec():
    # 4x4 cells, the last ones partial (7 x 6 pixels: 2 x 2 cells): means over the pixels inside, the
    # spreads of L and of the mean albedo input within each cell.
    rng = np.random.default_rng(4)
    d = rng.uniform(0.0, 3.0, (7, 6, 3)).astype(np.float32)
    var = rng.uniform(0.0, 0.5, (7, 6, 3)).astype(np.float32)
    alb = rng.uniform(0.0, 1.0, (7, 6, 3)).astype(np.float32)
    x = features.inputs(d, var, alb, rng.normal(0, 1, (7, 6, 3)), rng.uniform(1, 9, (7, 6, 1)))
    c = context.cell_inputs(x, d)
    assert c.shape == (2, 2, context.N_CTX_IN)
    for cy, cx, ys, xs in ((0, 0, slice(0, 4), slice(0, 4)), (1, 1, slice(4, 7), slice(4, 6))):
        cell = x[ys, xs]
        np.testing.assert_allclose(c[cy, cx, 0:3], cell[..., 0:3].reshape(-1, 3).mean(0), rtol=1e-5)
        lum = np.log1p(d[ys, xs].mean(axis=2))
        assert c[cy, cx, 3] == pytest.approx(lum.std(), rel=1e-3, abs=1e-5)
        np.testing.assert_allclose(c[cy, cx, 4:7], cell[..., 3:6].reshape(-1, 3).mean(0), rtol=1e-5)
        assert c[cy, cx, 7] == pytest.approx(cell[..., 3:6].mean(axis=2).std(), rel=1e-3, abs=1e-5)
        np.testing.assert_allclose(c[cy, cx, 8:13], cell[..., 6:11].reshape(-1, 5).mean(0), rtol=1e-5)


def test_upsampling_and_pooling_follow_the_spec():
    # Bilinear x4 with half-pixel centres and clamped indices: output 0 and 1 are sample 0, output 2
    # is 7/8 sample 0 + 1/8 sample 1; the pooling averages the samples inside (a 3-wide row: 2 + 1).
    a = jax.numpy.asarray(np.arange(3, dtype=np.float32).reshape(1, 1, 3, 1))
    up = np.asarray(context.upsample(a, 4, 1, 11))[0, 0, :, 0]
    np.testing.assert_allclose(up[:4], [0.0, 0.0, 0.125, 0.375], atol=1e-7)
    assert up[-1] == 2.0 and up[-2] == 1.875  # 9.5 / 4 - 0.5 = 1.875; 10.5 / 4 - 0.5 = 2.125 clamps to 2
    pooled = np.asarray(context.pool2(a))[0, 0, :, 0]
    np.testing.assert_allclose(pooled, [0.5, 2.0])


def test_zero_context_is_the_mlp_alone():
    # kz = kbz = 0 (a version-3 file, or the start of training from one): exactly no context.
    p = model.init_params(2)
    rng = np.random.default_rng(1)
    x = jax.numpy.asarray(rng.normal(0, 1, (1, 12, 9, features.N_IN)).astype(np.float32))
    cells = jax.numpy.asarray(rng.normal(0, 1, (1, 3, 3, context.N_CTX_IN)).astype(np.float32))
    for a, b in zip(model.network(p, x, cells), model.network(p, x, None)):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


def _tiny_prep(folder, rng):
    """One prepared scene at 1 and 64 spp (prepare.py's keys), 24x24, random but plausible planes."""
    h = w = 24
    ref = rng.uniform(0.05, 1.0, (h, w, 3)).astype(np.float32)
    z = {"reference": ref}
    for spp, sd in ((1, 0.8), (64, 0.1)):
        d = np.clip(ref + rng.normal(0, sd, ref.shape), 0, None).astype(np.float32)
        planes = {"color": d, "variance": np.full((h, w, 3), sd * sd, np.float32), "albedo": np.ones((h, w, 3), np.float32),
                  "normal": np.tile(np.float32([0, 0, 1]), (h, w, 1)), "depth": np.ones((h, w, 1), np.float32),
                  "modulation": np.ones((h, w, 3), np.float32), "emission": np.zeros((h, w, 3), np.float32)}
        z.update({f"given_{spp}_{k}": v for k, v in planes.items()})
    (folder / "train").mkdir(parents=True)
    np.savez(folder / "train" / "scene_0000.npz", **z)


def test_training_losses_and_an_evaluation_only_run(tmp_path):
    # train.py --steps 0 returns the starting weights untouched (evaluation only); each loss trains
    # (finite weights that moved), and the losses are different objectives (different weights).
    from atrous.learn import train

    _tiny_prep(tmp_path / "prep", np.random.default_rng(3))
    common = dict(splits=["train"], spps=[1, 64], variants=["given"], crop=16, context=False)
    init = model.init_params(1)
    same = train.train(tmp_path / "prep", tmp_path / "r0", 0, **common)
    assert all(np.array_equal(np.asarray(same[k]), np.asarray(init[k])) for k in init)
    got = {}
    for loss in ("relmse", "sqrt", "log"):
        p = train.train(tmp_path / "prep", tmp_path / loss, 6, ckpt_every=1000, loss=loss, **common)
        assert all(np.isfinite(np.asarray(v)).all() for v in p.values()), loss
        assert any(not np.array_equal(np.asarray(p[k]), np.asarray(init[k])) for k in init), loss
        got[loss] = p
    for a, b in (("relmse", "sqrt"), ("sqrt", "log")):
        assert any(not np.allclose(np.asarray(got[a][k]), np.asarray(got[b][k])) for k in init), (a, b)
