"""The learned method from Python: atrous.learned_planes (the driver's prepared planes the network
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
    p = atrous.learned_planes(b["color"], variance=b["variance"], emission=b["emission"], firefly=False,
                              emission_levels=0)
    assert set(p) == {"d", "var", "mod", "emission"}
    for k, v in p.items():
        assert v.dtype == np.float32 and v.shape == (H, W, 3), k
    np.testing.assert_array_equal(p["d"], b["color"] - b["emission"])
    np.testing.assert_array_equal(p["var"], b["variance"])
    np.testing.assert_array_equal(p["mod"], np.ones((H, W, 3), np.float32))
    np.testing.assert_array_equal(p["emission"], b["emission"])


def test_planes_with_every_buffer_remodulate_to_the_colour():
    # Albedos in [0.2, 0.9] are above the floor (0.05) and its rim rule: a' = albedo, so
    # d * mod + emission = colour up to the float rounding of (c - e) * (1 / a) * a (2 ulp:
    # rtol 1e-6), and var * mod^2 = the variance. The features come back as given (finite), depth
    # as one channel. emission_levels=0 so that the emission is added back as given.
    b = _synthetic(2)
    p = atrous.learned_planes(b["color"], variance=b["variance"], albedo=b["albedo"], normal=b["normal"],
                              depth=b["depth"], emission=b["emission"], firefly=False, emission_levels=0)
    assert set(p) == {"d", "var", "albedo", "normal", "depth", "mod", "emission"}
    assert p["depth"].shape == (H, W, 1)
    np.testing.assert_array_equal(p["mod"], b["albedo"])
    np.testing.assert_array_equal(p["albedo"], b["albedo"])
    np.testing.assert_array_equal(p["normal"], b["normal"])
    np.testing.assert_array_equal(p["depth"][..., 0], b["depth"][..., 0])
    np.testing.assert_allclose(p["d"] * p["mod"] + p["emission"], b["color"], rtol=1e-6, atol=0)
    np.testing.assert_allclose(p["var"] * p["mod"] ** 2, b["variance"], rtol=1e-6, atol=0)
    # Not the colour itself: the demodulation happened.
    assert np.abs(p["d"] - b["color"]).max() > 0.1


def test_black_albedo_is_left_demodulated_by_the_rule():
    # Where the albedo is 0 the rule's divisor fades to 1 (albedo_floor): mod = 1 there, d = c - e.
    b = _synthetic(3)
    b["albedo"][10:14, 10:14] = 0.0
    p = atrous.learned_planes(b["color"], variance=b["variance"], albedo=b["albedo"], firefly=False)
    np.testing.assert_array_equal(p["mod"][11:13, 11:13], 1.0)
    np.testing.assert_array_equal(p["d"][11:13, 11:13], b["color"][11:13, 11:13])
    # demodulate=False: no albedo plane, mod 1 everywhere.
    q = atrous.learned_planes(b["color"], variance=b["variance"], albedo=b["albedo"], demodulate=False)
    assert "albedo" not in q
    np.testing.assert_array_equal(q["mod"], 1.0)


def test_planes_follow_the_preparation_fireflies_nan_and_estimated_noise():
    b = _synthetic(4)
    color = b["color"].copy()
    color[7, 9] = 500.0           # a firefly: clamped by the default pass
    color[3, 4, 1] = np.nan       # repaired by the sanitise stage
    normal = b["normal"].copy()
    normal[2, 2] = np.inf         # a non-finite feature reads 0
    p = atrous.learned_planes(color, albedo=b["albedo"], normal=normal)  # no variance: estimated
    for k, v in p.items():
        assert np.isfinite(v).all(), k
    assert p["d"][7, 9].max() * p["mod"][7, 9].max() < 50.0
    np.testing.assert_array_equal(p["normal"][2, 2], 0.0)
    assert (p["var"] > 0).all()


def test_learned_planes_checks_inputs_like_denoise():
    b = _synthetic()
    with pytest.raises(ValueError, match="albedo"):
        atrous.learned_planes(b["color"], albedo=b["albedo"][:-1])
    with pytest.raises(ValueError, match="sigma_normal"):
        atrous.learned_planes(b["color"], sigma_normal=-1.0)
    with pytest.raises(ValueError, match="unknown denoise parameter"):
        atrous.learned_planes(b["color"], no_such_thing=1)
    with pytest.raises(ValueError, match="variance"):
        atrous.learned_planes(b["color"], variance=-b["variance"])
