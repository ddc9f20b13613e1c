"""The Python API: shapes, dtypes, the array rule, errors, and agreement with the library."""
import numpy as np
import pytest

import atrous


@pytest.fixture(scope="module")
def bufs():
    return atrous.render("cornell", width=48, height=40, spp=8, seed=3)


def test_render_returns_every_buffer_as_float32_hwc(bufs):
    assert set(bufs) == {"color", "variance", "albedo", "normal", "position", "depth", "ids", "emission"}
    for name, arr in bufs.items():
        assert arr.shape == (40, 48, 3), name
        assert arr.dtype == np.float32, name
        assert arr.flags.c_contiguous, name
        assert np.isfinite(arr).all(), name


def test_render_is_deterministic(bufs):
    again = atrous.render("cornell", width=48, height=40, spp=8, seed=3)
    np.testing.assert_array_equal(again["color"], bufs["color"])
    other = atrous.render("cornell", width=48, height=40, spp=8, seed=4)
    assert not np.array_equal(other["color"], bufs["color"])


@pytest.mark.parametrize("method", ["eaw", "sure"])
def test_denoise_reduces_error_against_a_better_render(bufs, method):
    # cornell-point: no emitter in view, whose anti-aliased edge would dominate the MSE. A
    # 512-spp render has 1/64 of the input's noise variance; both filters must cut the 8-spp
    # input's MSE against it by at least 2x (measured ~3.5x while the filters were young; the
    # quality benchmark, docs/quality.md, holds the real targets).
    noisy_bufs = atrous.render("cornell-point", width=64, height=64, spp=8, seed=3)
    ref = atrous.render("cornell-point", width=64, height=64, spp=512, seed=99)["color"]
    out = atrous.denoise(noisy_bufs["color"], albedo=noisy_bufs["albedo"], normal=noisy_bufs["normal"],
                         position=noisy_bufs["position"], variance=noisy_bufs["variance"],
                         ids=noisy_bufs["ids"], method=method)
    bufs = noisy_bufs
    assert out.shape == bufs["color"].shape and out.dtype == np.float32
    noisy = atrous.metrics(bufs["color"], ref)["mse"]
    den = atrous.metrics(out, ref)["mse"]
    assert den < noisy / 2, (method, noisy, den)


def test_emission_keeps_the_visible_light_out_of_the_ceiling():
    # cornell sees its ceiling light. Filtering color - emission and adding it back keeps the
    # light's anti-aliased edge from spreading into the ceiling: with the emission buffer the
    # filtered image's relMSE is at least 1.5x lower (measured 2-3.5x at this size).
    b = atrous.render("cornell", width=64, height=64, spp=16, seed=3)
    ref = atrous.render("cornell", width=64, height=64, spp=1024, seed=9)["color"]
    assert b["emission"].max() > 1.0
    kw = dict(albedo=b["albedo"], normal=b["normal"], position=b["position"], variance=b["variance"],
              ids=b["ids"], method="eaw")
    without = atrous.metrics(atrous.denoise(b["color"], **kw), ref)["relmse"]
    with_e = atrous.metrics(atrous.denoise(b["color"], emission=b["emission"], **kw), ref)["relmse"]
    assert with_e < without / 1.5, (with_e, without)


def test_noncontiguous_and_float64_inputs_give_the_same_result(bufs):
    c = bufs["color"]
    base = atrous.denoise(c, method="eaw")
    # A float64 copy is converted to float32: identical input values, identical output.
    np.testing.assert_array_equal(atrous.denoise(c.astype(np.float64), method="eaw"), base)
    # A non-contiguous view (every other column of a wider array) is read through its strides.
    wide = np.zeros((c.shape[0], c.shape[1] * 2, 3), np.float32)
    wide[:, ::2] = c
    np.testing.assert_array_equal(atrous.denoise(wide[:, ::2], method="eaw"), base)
    # Channel-last with a transposed memory layout.
    t = np.ascontiguousarray(c.transpose(2, 0, 1)).transpose(1, 2, 0)
    assert not t.flags.c_contiguous
    np.testing.assert_array_equal(atrous.denoise(t, method="eaw"), base)


def _strided(a, dtype=np.float32):
    """`a` as every other pixel of every other row of a wider, taller array of `dtype`, read
    through its strides (no copy of a C-contiguous array)."""
    h, w, c = a.shape
    big = np.zeros((2 * h, 2 * w, c), dtype)
    big[::2, ::2] = a
    v = big[::2, ::2]
    assert not v.flags.c_contiguous and v.base is big
    return v


@pytest.mark.parametrize("dtype", [np.float32, np.float16])
def test_strided_and_half_arrays_are_taken_without_a_copy_of_the_colour(bufs, dtype):
    # issue 48: a strided float32 or float16 array is handed to the library where it is. The
    # report says what was copied: never the colour (nor the variance or the emission, converted
    # into the filter's planes by its first pass); the features the filter reads, named.
    # The values half holds (the depth's background, 1e30, does not: it is left out).
    b = {k: bufs[k].astype(dtype).astype(np.float32) for k in ("color", "albedo", "normal", "variance", "emission")}
    feats = {k: b[k] for k in ("albedo", "normal", "variance", "emission")}
    want, want_rep = atrous.denoise(b["color"], method=atrous.names.EAW, report=True, **feats)
    got, rep = atrous.denoise(_strided(b["color"], dtype), method=atrous.names.EAW, report=True,
                              **{k: _strided(v, dtype) for k, v in feats.items()})
    np.testing.assert_array_equal(got, want)  # the same values in, bit for bit the same out
    # C-contiguous or not, the features the filter reads are copied into its planar layout.
    assert want_rep["copies"] == ["albedo (float32, 3 channels)", "normal (float32, 3 channels)"], want_rep["copies"]
    names = [c.split(" ")[0] for c in rep["copies"]]
    assert not {"color", "variance", "emission"} & set(names), rep["copies"]
    kind = "float16" if dtype == np.float16 else "float32"
    assert rep["copies"] == [f"albedo ({kind}, 3 channels)", f"normal ({kind}, 3 channels)"], rep["copies"]
    assert rep["method_used"] == atrous.names.EAW and rep["buffers_used"].startswith("color,variance")


def test_a_c_contiguous_colour_alone_makes_no_copy(bufs):
    out, rep = atrous.denoise(bufs["color"], method=atrous.names.EAW, report=True)
    assert rep["copies"] == [] and out.shape == bufs["color"].shape and out.flags.c_contiguous
    assert rep["noise_estimated"] and [s for s, _ in rep["stages"]]
    # float16 colour: the same output as its values in float32.
    h = bufs["color"].astype(np.float16)
    np.testing.assert_array_equal(atrous.denoise(h, method=atrous.names.EAW),
                                  atrous.denoise(h.astype(np.float32), method=atrous.names.EAW))


def test_rgba_colour_reads_rgb(bufs):
    # An RGBA array is read in place (no copy): the filter reads R, G, B, and the alpha comes back
    # beside the result unchanged (test_user_inputs.py: files and the CLI).
    c = bufs["color"]
    rgba = np.concatenate([c, np.full(c.shape[:2] + (1,), 0.5, np.float32)], axis=2)
    out = atrous.denoise(rgba, method=atrous.names.EAW)
    np.testing.assert_array_equal(out[..., :3], atrous.denoise(c, method=atrous.names.EAW))
    np.testing.assert_array_equal(out[..., 3], rgba[..., 3])


def test_gray_features_are_repeated(bufs):
    d = bufs["depth"]
    a = atrous.denoise(bufs["color"], depth=d, method="eaw", sigma_depth=0.1)
    b = atrous.denoise(bufs["color"], depth=d[:, :, 0], method="eaw", sigma_depth=0.1)
    np.testing.assert_array_equal(a, b)


def test_every_keyword_reaches_the_filter(bufs):
    kw = dict(albedo=bufs["albedo"], normal=bufs["normal"], position=bufs["position"],
              variance=bufs["variance"], ids=bufs["ids"])
    base = atrous.denoise(bufs["color"], method="sure", **kw)
    for name, value in [("levels", 3), ("color_scale", 2.0), ("sigma_normal", 0.05),
                        ("sure_window", 1), ("sure_mode", "james-stein"), ("demodulate", False)]:
        out = atrous.denoise(bufs["color"], method="sure", **kw, **{name: value})
        assert not np.array_equal(out, base), name


@pytest.mark.parametrize("keyword", ["color", "albedo", "variance", "depth"])
@pytest.mark.parametrize("bad, match", [
    (np.zeros((8, 8, 3, 1), np.float32), "shape"),         # a fourth dimension
    (np.zeros(8, np.float32), "shape"),                    # one
    (np.zeros((8, 8, 3), np.int32), "float32 or float16"),  # another dtype
    (np.zeros((8, 8, 3), np.bool_), "float32 or float16"),
    (np.zeros((8, 8, 3), np.complex64), "float32 or float16"),
    (np.zeros((0, 8, 3), np.float32), "empty"),
    (np.zeros((8, 8, 5), np.float32), "channels"),  # (8, 8, 4) is RGBA: test_user_inputs.py
])
def test_bad_arrays_raise_value_error_naming_the_keyword(keyword, bad, match):
    # The array rule is checked once, by the library (python/src/arrays.cpp): the message starts
    # with the keyword.
    c = np.ones((8, 8, 3), np.float32)
    kw = {"color": c, keyword: bad}
    with pytest.raises(ValueError, match=match) as e:
        atrous.denoise(kw.pop("color"), **kw)
    assert str(e.value).startswith(keyword + ":"), str(e.value)


def test_two_channel_colour_is_refused_by_name():
    with pytest.raises(ValueError, match=r"^color: expected 3 channels \(or 1\), got 2"):
        atrous.denoise(np.ones((8, 8, 2), np.float32))
    with pytest.raises(ValueError, match="^normal: expected 3 channels"):
        atrous.denoise(np.ones((8, 8, 3), np.float32), normal=np.ones((8, 8, 2), np.float32))


def test_bad_arguments_raise_value_error(bufs):
    c = bufs["color"]
    with pytest.raises(ValueError, match="^albedo buffer is 4x4 but the color is"):
        atrous.denoise(c, albedo=np.ones((4, 4, 3), np.float32))
    with pytest.raises(ValueError, match="method"):
        atrous.denoise(c, method="bilateral")
    with pytest.raises(ValueError, match="levels"):
        atrous.denoise(c, levels=0)
    with pytest.raises(ValueError, match="unknown denoise parameter"):
        atrous.denoise(c, sigma_colour=1.0)
    with pytest.raises(ValueError, match="variance"):
        atrous.denoise(c, variance=-np.ones_like(c))
    with pytest.raises(ValueError, match="parameter scene must be a built-in scene"):
        atrous.render("no-such-scene", width=8, height=8, spp=1)
    with pytest.raises(ValueError):
        atrous.render("cornell", width=8, height=8, spp=0)
    if not atrous.cuda_available():
        with pytest.raises(ValueError, match="cuda"):
            atrous.denoise(c, device="cuda")


def test_messages_name_keywords_not_cli_flags():
    # The library's messages name the CLI's flags; Python shows the keyword instead.
    with pytest.raises(ValueError) as e:
        atrous.render("cornell", width=-1, height=8, spp=1)
    assert "width" in str(e.value) and "--width" not in str(e.value), str(e.value)
    with pytest.raises(ValueError) as e:
        atrous.render("cornell", width=8, height=8, spp=1, max_depth=-3)
    assert "--" not in str(e.value), str(e.value)


def test_cli_switch_names_are_accepted(bufs):
    # no_firefly=True is firefly=False, and so on for the CLI's other --no-* switches.
    c = bufs["color"]
    kw = dict(normal=bufs["normal"], variance=bufs["variance"], albedo=bufs["albedo"], ids=bufs["ids"])
    for alias, name in (("no_firefly", "firefly"), ("no_demodulate", "demodulate"), ("no_ids", "use_ids"),
                        ("no_correlated_variance", "correlated_variance")):
        a = atrous.denoise(c, method="sure", **kw, **{alias: True})
        b = atrous.denoise(c, method="sure", **kw, **{name: False})
        np.testing.assert_array_equal(a, b, err_msg=alias)


def test_a_zero_variance_is_ignored(bufs):
    # What a 1-spp render returns: taken at face value it would mean "noise-free" (no filtering).
    c = bufs["color"]
    zero = np.zeros_like(c)
    a = atrous.denoise(c, variance=zero, normal=bufs["normal"], method="eaw")
    b = atrous.denoise(c, normal=bufs["normal"], method="eaw")
    np.testing.assert_array_equal(a, b)
    assert np.abs(a - c).max() > 1e-3


def test_metrics_count_non_finite_pixels(bufs):
    c = bufs["color"]
    bad = c.copy()
    bad[1, 2, 0] = np.nan
    bad[3, 4, 1] = np.inf
    m = atrous.metrics(bad, c)
    assert m["non_finite_pixels"] == 2 and m["reference_non_finite_pixels"] == 0
    assert np.isfinite(m["mse"])


def test_nan_and_inf_in_color_do_not_spread(bufs):
    c = bufs["color"].copy()
    c[10, 10] = np.nan
    c[20, 5, 1] = np.inf
    for method in ("eaw", "sure"):
        out = atrous.denoise(c, normal=bufs["normal"], variance=bufs["variance"], method=method)
        assert np.isfinite(out).all(), method


def test_svgf_stream(bufs):
    s = atrous.Svgf(device="cpu", levels=3)
    motion = np.zeros((40, 48, 2), np.float32)
    for i in range(3):
        f = atrous.render("cornell", width=48, height=40, spp=1, seed=10 + i)
        out = s.denoise_frame(f["color"], albedo=f["albedo"], normal=f["normal"], depth=f["depth"],
                              ids=f["ids"], motion=motion)
        assert out.shape == (40, 48, 3) and np.isfinite(out).all()
    s.reset()
    with pytest.raises(ValueError):
        atrous.Svgf(sigma_q=1.0)


def test_torch_tensors_come_back_as_tensors(bufs):
    torch = pytest.importorskip("torch")
    out = atrous.denoise(torch.from_numpy(bufs["color"]), method="eaw")
    assert isinstance(out, torch.Tensor)
    np.testing.assert_array_equal(out.numpy(), atrous.denoise(bufs["color"], method="eaw"))


def test_render_sequence_gives_frames_with_motion_for_svgf():
    frames = list(atrous.render_sequence("cornell-moving", 3, width=32, height=24, spp=1, seed=5))
    assert len(frames) == 3
    assert [f["time"] for f in frames] == [0.0, 0.5, 1.0]
    for f in frames:
        for k in ("color", "albedo", "normal", "depth", "ids", "emission", "motion"):
            assert f[k].shape == (24, 32, 3) and f[k].dtype == np.float32, k
    assert np.abs(frames[0]["motion"]).max() < 1e-3  # no previous frame
    assert np.abs(frames[2]["motion"][..., :2]).max() > 0.1  # the box turns, the sphere slides
    assert not np.array_equal(frames[0]["color"], frames[1]["color"])  # fresh samples per frame
    again = next(atrous.render_sequence("cornell-moving", 3, width=32, height=24, spp=1, seed=5))
    np.testing.assert_array_equal(again["color"], frames[0]["color"])
    s = atrous.Svgf(device="cpu")
    for f in frames:
        out = s.denoise_frame(f["color"], albedo=f["albedo"], normal=f["normal"], depth=f["depth"],
                              ids=f["ids"], motion=f["motion"], emission=f["emission"])
        assert out.shape == (24, 32, 3) and np.isfinite(out).all()
    with pytest.raises(ValueError, match="camera_path"):
        next(atrous.render_sequence("cornell", 2, width=8, height=8, camera_path="spiral"))
    with pytest.raises(ValueError, match="frames"):
        next(atrous.render_sequence("cornell", 0, width=8, height=8))
