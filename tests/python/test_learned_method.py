"""The learned method from Python: atrous.prepared_planes (the driver's prepared planes the network
is trained on, docs/learned.md) and atrous.denoise(method="learned" | "auto")."""
import numpy as np
import pytest

import atrous

H, W = 20, 24


def _synthetic(seed=1):
    rng = np.random.default_rng(seed)
    color = rng.uniform(0.2, 2.0, (H, W, 3)).astype(np.float32)
    variance = rng.uniform(0.01, 0.1, (H, W, 3)).astype(np.float32)
    emission = np.zeros((H, W, 3), np.float32)
    emission[5:9, 6:12] = rng.uniform(0.05, 0.15, (4, 6, 3))
    albedo = rng.uniform(0.2, 0.9, (H, W, 3)).astype(np.float32)
    normal = rng.normal(size=(H, W, 3)).astype(np.float32)
    normal /= np.linalg.norm(normal, axis=2, keepdims=True)
    depth = rng.uniform(1.0, 5.0, (H, W, 3)).astype(np.float32)
    return dict(color=color, variance=variance, emission=emission, albedo=albedo, normal=normal, depth=depth)


def test_planes_without_albedo_are_the_colour_minus_the_emission():
    # Firefly pass off, emission filter off, no albedo: step 3 leaves d = colour - emission and
    # var = the variance, bit for bit (one float subtraction, as numpy does it); mod is 1 and the
    # emission comes back as given. A hook copying another buffer (var into d, the colour before
    # the emission split, ...) fails the exact comparisons.
    b = _synthetic()
    p = atrous.prepared_planes(b["color"], variance=b["variance"], emission=b["emission"], firefly=False,
                              emission_levels=0)
    assert set(p) == {"color", "variance", "modulation", "emission"}
    for k, v in p.items():
        assert v.dtype == np.float32 and v.shape == (H, W, 3), k
    np.testing.assert_array_equal(p["color"], b["color"] - b["emission"])
    np.testing.assert_array_equal(p["variance"], b["variance"])
    np.testing.assert_array_equal(p["modulation"], np.ones((H, W, 3), np.float32))
    np.testing.assert_array_equal(p["emission"], b["emission"])


def test_planes_with_every_buffer_remodulate_to_the_colour():
    # Albedos in [0.2, 0.9] are above the floor (0.05) and its rim rule: a' = albedo, so
    # d * mod + emission = colour up to the float rounding of (c - e) * (1 / a) * a (2 ulp:
    # rtol 1e-6), and var * mod^2 = the variance. The features come back as given (finite), depth
    # as one channel. emission_levels=0 so that the emission is added back as given.
    b = _synthetic(2)
    p = atrous.prepared_planes(b["color"], variance=b["variance"], albedo=b["albedo"], normal=b["normal"],
                              depth=b["depth"], emission=b["emission"], firefly=False, emission_levels=0)
    assert set(p) == {"color", "variance", "albedo", "normal", "depth", "modulation", "emission"}
    assert p["depth"].shape == (H, W, 1)
    np.testing.assert_array_equal(p["modulation"], b["albedo"])
    np.testing.assert_array_equal(p["albedo"], b["albedo"])
    np.testing.assert_array_equal(p["normal"], b["normal"])
    np.testing.assert_array_equal(p["depth"][..., 0], b["depth"][..., 0])
    np.testing.assert_allclose(p["color"] * p["modulation"] + p["emission"], b["color"], rtol=1e-6, atol=0)
    np.testing.assert_allclose(p["variance"] * p["modulation"] ** 2, b["variance"], rtol=1e-6, atol=0)
    # Not the colour itself: the demodulation happened.
    assert np.abs(p["color"] - b["color"]).max() > 0.1


def test_black_albedo_is_left_demodulated_by_the_rule():
    # Where the albedo is 0 the rule's divisor fades to 1 (albedo_floor): mod = 1 there, d = c - e.
    b = _synthetic(3)
    b["albedo"][10:14, 10:14] = 0.0
    p = atrous.prepared_planes(b["color"], variance=b["variance"], albedo=b["albedo"], firefly=False)
    np.testing.assert_array_equal(p["modulation"][11:13, 11:13], 1.0)
    np.testing.assert_array_equal(p["color"][11:13, 11:13], b["color"][11:13, 11:13])
    # demodulate=False: no albedo plane, mod 1 everywhere.
    q = atrous.prepared_planes(b["color"], variance=b["variance"], albedo=b["albedo"], demodulate=False)
    assert "albedo" not in q
    np.testing.assert_array_equal(q["modulation"], 1.0)


def test_planes_follow_the_preparation_fireflies_nan_and_estimated_noise():
    b = _synthetic(4)
    color = b["color"].copy()
    color[7, 9] = 500.0           # a firefly: clamped by the default pass
    color[3, 4, 1] = np.nan       # repaired by the sanitise stage
    normal = b["normal"].copy()
    normal[2, 2] = np.inf         # a non-finite feature reads 0
    p = atrous.prepared_planes(color, albedo=b["albedo"], normal=normal)  # no variance: estimated
    for k, v in p.items():
        assert np.isfinite(v).all(), k
    assert p["color"][7, 9].max() * p["modulation"][7, 9].max() < 50.0
    np.testing.assert_array_equal(p["normal"][2, 2], 0.0)
    assert (p["variance"] > 0).all()


def test_prepared_planes_checks_inputs_like_denoise():
    b = _synthetic()
    with pytest.raises(ValueError, match="albedo"):
        atrous.prepared_planes(b["color"], albedo=b["albedo"][:-1])
    with pytest.raises(ValueError, match="sigma_normal"):
        atrous.prepared_planes(b["color"], sigma_normal=-1.0)
    with pytest.raises(ValueError, match="unknown denoise parameter"):
        atrous.prepared_planes(b["color"], no_such_thing=1)
    with pytest.raises(ValueError, match="variance"):
        atrous.prepared_planes(b["color"], variance=-b["variance"])


def _fixture_weights(tmp_path):
    # The weight file inside tests/learned_fixture.bin (random, non-trivial weights: the tests do
    # not depend on how the built-in weights were trained). "ATRF" | u32 version | w | h | n | bytes.
    import struct
    from pathlib import Path

    b = (Path(__file__).resolve().parents[1] / "learned_fixture.bin").read_bytes()
    assert b[:4] == b"ATRF"
    n = struct.unpack("<I", b[16:20])[0]
    p = tmp_path / "fixture.atrl"
    p.write_bytes(b[20:20 + n])
    return p


def test_methods_list_learned_blend_and_auto():
    assert "learned" in atrous.METHODS and "blend" in atrous.METHODS and "auto" in atrous.METHODS


def test_learned_denoise_is_finite_filters_and_takes_a_path(tmp_path):
    w = _fixture_weights(tmp_path)
    b = _synthetic(5)
    b["color"][4, 4] = np.nan
    kw = dict(variance=b["variance"], albedo=b["albedo"], normal=b["normal"], depth=b["depth"],
              emission=b["emission"])
    out = atrous.denoise(b["color"], method="learned", learned_weights=w, **kw)
    assert out.shape == (H, W, 3) and out.dtype == np.float32 and np.isfinite(out).all()
    assert np.abs(out - np.nan_to_num(b["color"])).max() > 1e-3
    # str and PathLike give the same; levels is not a parameter of the learned filter.
    again = atrous.denoise(b["color"], method="learned", learned_weights=str(w), levels=2, **kw)
    np.testing.assert_array_equal(out, again)
    # A network loaded once (atrous.load_weights) gives the same as its file; the built-in is other.
    loaded = atrous.load_weights(w)
    assert isinstance(loaded, atrous.Weights)
    np.testing.assert_array_equal(atrous.denoise(b["color"], method="learned", learned_weights=loaded, **kw), out)
    assert np.abs(atrous.denoise(b["color"], method="learned", **kw) - out).max() > 1e-4
    # auto (the default) with albedo and normal is blend, the mean of learned and sure; without a
    # normal it is sure.
    blend = atrous.denoise(b["color"], method="blend", learned_weights=w, **kw)
    np.testing.assert_array_equal(atrous.denoise(b["color"], method="auto", learned_weights=w, **kw), blend)
    np.testing.assert_array_equal(atrous.denoise(b["color"], learned_weights=w, **kw), blend)
    sure = atrous.denoise(b["color"], method="sure", **kw)
    # (The mean is taken before remodulation: equal to the mean of the outputs up to float rounding.)
    np.testing.assert_allclose(blend, 0.5 * (out + sure), rtol=1e-5, atol=1e-5)
    assert np.abs(out - sure).max() > 1e-3
    kw.pop("normal")
    np.testing.assert_array_equal(atrous.denoise(b["color"], method="auto", learned_weights=w, **kw),
                                  atrous.denoise(b["color"], method="sure", **kw))


def test_learned_denoise_is_the_filtered_planes_remodulated(tmp_path):
    # A constant colour is a fixed point of the cascade (every level is a normalised average and
    # the blend a convex combination), so the output must be the colour again: the driver divided
    # by the albedo (d = 1.2) and multiplied it back. A missing remodulation gives 1.2, a doubled
    # one 0.3. rtol 1e-5: the float sums of the cascade's weights (~1e-7 each).
    w = _fixture_weights(tmp_path)
    c = np.full((H, W, 3), 0.6, np.float32)
    a = np.full((H, W, 3), 0.5, np.float32)
    n = np.zeros((H, W, 3), np.float32)
    n[..., 2] = 1
    out = atrous.denoise(c, variance=np.full_like(c, 0.01), albedo=a, normal=n, method="learned",
                         learned_weights=w)
    np.testing.assert_allclose(out, c, rtol=1e-5)


def test_bad_weights_raise_value_error_naming_the_file(tmp_path):
    b = _synthetic()
    missing = tmp_path / "none.atrl"
    with pytest.raises(ValueError, match="none.atrl"):
        atrous.denoise(b["color"], method="learned", learned_weights=missing)
    junk = tmp_path / "junk.atrl"
    junk.write_bytes(b"ATRL\x02\x00\x00\x00 truncated")
    with pytest.raises(ValueError, match="junk.atrl"):
        atrous.denoise(b["color"], albedo=b["albedo"], normal=b["normal"], method="auto", learned_weights=junk)
    with pytest.raises(ValueError, match="junk.atrl"):
        atrous.load_weights(junk)
    with pytest.raises(ValueError, match="unknown denoise method"):
        atrous.denoise(b["color"], method="learnt")


def test_eval_takes_learned_and_auto(tmp_path):
    # python -m atrous.eval --methods noisy,eaw,sure,learned,oidn: accepted, learned/auto are
    # atrous methods with the weight file passed through; the default set is unchanged.
    ev = pytest.importorskip("atrous.eval")
    w = _fixture_weights(tmp_path)
    cfg = ev.parse_args(["--methods", "noisy,eaw,sure,learned,auto,oidn", "--learned-weights", str(w)])
    assert cfg.methods == ["noisy", "eaw", "sure", "learned", "auto", "oidn"]
    assert cfg.learned_weights == str(w)
    assert ev.parse_args([]).methods == list(ev.DEFAULT_METHODS)
    with pytest.raises(SystemExit) as e:
        ev.parse_args(["--methods", "learned", "--learned-weights", str(tmp_path / "none.atrl")])
    assert e.value.code == 2
    methods = ev.build_methods(["learned", "blend", "auto"], [], str(w))
    b = atrous.render("cornell", width=24, height=20, spp=2, seed=1)
    kw = dict(albedo=b["albedo"], normal=b["normal"], position=b["position"], depth=b["depth"],
              variance=b["variance"], ids=b["ids"], emission=b["emission"], learned_weights=w)
    np.testing.assert_array_equal(methods["learned"](b), atrous.denoise(b["color"], method="learned", **kw))
    # auto with every buffer is blend, with the weight file passed through to its learned half.
    want = atrous.denoise(b["color"], method="blend", **kw)
    for name in ("blend", "auto"):
        np.testing.assert_array_equal(methods[name](b), want)
    # The report compares the best atrous method (learned among them) with OIDN.
    from atrous.eval import report

    assert "learned" in atrous.METHODS and "learned" in report.COLORS


def test_svgf_learned_spatial_takes_the_given_weights(tmp_path):
    # SVGF's learned spatial filter (learned_spatial=True) runs the weights it is given: the
    # fixture's random weights change the frames against the built-in ones (measured max 0.15 on
    # this scene; 1e-3 is far above float noise, far below that), a bad file is a ValueError
    # naming it, and without learned_weights the built-in weights are used (two runs equal).
    w = _fixture_weights(tmp_path)
    frames = [atrous.render("cornell", width=32, height=24, spp=1, seed=20 + i) for i in range(3)]
    motion = np.zeros((24, 32, 2), np.float32)

    def run(**kw):
        s = atrous.Svgf(device="cpu", learned_spatial=True, **kw)
        out = None
        for f in frames:
            out = s.denoise_frame(f["color"], albedo=f["albedo"], normal=f["normal"], depth=f["depth"],
                                  ids=f["ids"], motion=motion)
        assert out.shape == (24, 32, 3) and np.isfinite(out).all()
        return out

    builtin = run()
    np.testing.assert_array_equal(run(), builtin)
    assert np.abs(run(learned_weights=w) - builtin).max() > 1e-3
    junk = tmp_path / "junk.atrl"
    junk.write_bytes(b"not a weight file")
    with pytest.raises(ValueError, match="junk.atrl"):
        atrous.Svgf(device="cpu", learned_spatial=True, learned_weights=junk)
