"""atrous.denoise_temporal: the offline sequence denoiser from Python (docs/temporal.md)."""
import numpy as np
import pytest

import atrous


@pytest.fixture(scope="module")
def frames():
    return list(atrous.render_sequence("cornell-moving", 5, width=40, height=32, spp=2, seed=11))


@pytest.fixture(scope="module")
def reference():
    # frame 2's reference: the same frame at 256 spp, another seed
    return list(atrous.render_sequence("cornell-moving", 5, width=40, height=32, spp=256, seed=900))[2]["color"]


def test_beats_the_still_method_on_the_centre_frame(frames, reference):
    out = atrous.denoise_temporal(frames, 2, method="eaw")
    assert out.shape == (32, 40, 3) and out.dtype == np.float32 and np.isfinite(out).all()
    alone = atrous.denoise(frames[2]["color"], albedo=frames[2]["albedo"], normal=frames[2]["normal"],
                           depth=frames[2]["depth"], ids=frames[2]["ids"], emission=frames[2]["emission"],
                           position=frames[2]["position"], method="eaw")
    e_t = atrous.metrics(out, reference)["relmse"]
    e_s = atrous.metrics(alone, reference)["relmse"]
    assert e_t < 0.9 * e_s, (e_t, e_s)


def test_radius_zero_is_the_still_method(frames):
    f = frames[1]
    out = atrous.denoise_temporal(frames, 1, method="sure", device="cpu", temporal={"radius": 0})
    alone = atrous.denoise(f["color"], albedo=f["albedo"], normal=f["normal"], depth=f["depth"], ids=f["ids"],
                           emission=f["emission"], position=f["position"], variance=f["variance"], method="sure",
                           device="cpu")
    np.testing.assert_array_equal(out, alone)


def test_params_table_and_its_keywords(frames):
    names = [r["name"] for r in atrous.temporal_params()]
    assert names == ["radius", "depth_tolerance", "normal_cos", "color_sigmas", "falloff", "firefly_k", "causal", "causal_falloff", "static_radius"]
    # causal: the frames after the centre are not used (the window 0..4 centred on 2 is 0..2),
    # with the causal falloff (1) in place of the two-sided one, and no static window
    np.testing.assert_array_equal(atrous.denoise_temporal(frames, 2, temporal={"causal": True}),
                                  atrous.denoise_temporal(frames[:3], 2, temporal={"falloff": 1.0, "static_radius": 0}))
    # how far the method reads: the static window (6) unless causal, 0 for radius 0
    assert atrous.temporal_window_radius() == 6
    assert atrous.temporal_window_radius({"radius": 8}) == 8
    assert atrous.temporal_window_radius({"causal": True}) == 3
    assert atrous.temporal_window_radius({"radius": 0}) == 0
    with pytest.raises(ValueError, match="static_radius"):
        atrous.temporal_window_radius({"static_radius": -1})
    with pytest.raises(ValueError, match="radius"):
        atrous.denoise_temporal(frames, 2, temporal={"radius": 99})
    with pytest.raises(ValueError, match="radios"):
        atrous.denoise_temporal(frames, 2, temporal={"radios": 1})


def test_bad_windows_raise(frames):
    with pytest.raises(ValueError, match="center"):
        atrous.denoise_temporal(frames, 5)
    with pytest.raises(ValueError, match="non-empty"):
        atrous.denoise_temporal([], 0)
    with pytest.raises(ValueError, match="albdo"):
        atrous.denoise_temporal([dict(frames[0], albdo=frames[0]["albedo"])] + frames[1:], 1)
    no_albedo = {k: v for k, v in frames[0].items() if k != "albedo"}
    with pytest.raises(ValueError, match="other buffers"):
        atrous.denoise_temporal([no_albedo] + frames[1:], 1)
    small = {k: (v[:16] if isinstance(v, np.ndarray) else v) for k, v in frames[0].items()}
    with pytest.raises(ValueError, match="frame 0"):
        atrous.denoise_temporal([small] + frames[1:], 1)
    nan = dict(frames[3], color=frames[3]["color"].copy())
    nan["color"][5, 5] = np.nan
    out = atrous.denoise_temporal(frames[:3] + [nan] + frames[4:], 2)
    assert np.isfinite(out).all()


def test_sequence_methods_from_the_library():
    assert atrous.SEQUENCE_METHODS == ("temporal", "svgf")
    assert not set(atrous.SEQUENCE_METHODS) & set(atrous.METHODS)


def test_motion_from_positions_when_no_frame_has_motion(frames, reference):
    no_motion = [{k: v for k, v in f.items() if k != "motion"} for f in frames]
    still = [{k: v for k, v in f.items() if k not in ("motion", "position")} for f in frames]
    # static_radius 0: the three then average with the same weights (a camera that stands still
    # gives exact zero vectors, but a fitted camera's motion is a few hundredths of a pixel, and
    # the static window tells them apart); what is compared is the motion alone.
    e = {name: atrous.metrics(atrous.denoise_temporal(fs, 2, method="eaw", temporal={"static_radius": 0}),
                              reference)["relmse"]
         for name, fs in (("vectors", frames), ("fitted", no_motion), ("still", still))}
    assert e["fitted"] < 1.1 * e["vectors"], e
    assert e["fitted"] < e["still"], e


def test_the_static_window_needs_the_renderers_motion(frames):
    # Motion fitted to the Position pass, or estimated from the colours, sees the moving sphere as
    # still: the static window (static_radius) is then off, as in the CLI.
    no_motion = [{k: v for k, v in f.items() if k != "motion"} for f in frames]
    colours = [{"color": f["color"]} for f in frames]
    for fs in (no_motion, colours):
        np.testing.assert_array_equal(atrous.denoise_temporal(fs, 2, method="eaw"),
                                      atrous.denoise_temporal(fs, 2, method="eaw", temporal={"static_radius": 0}))
    # with the renderer's vectors it is on (cornell-moving: a still camera)
    assert not np.array_equal(atrous.denoise_temporal(frames, 2, method="eaw"),
                              atrous.denoise_temporal(frames, 2, method="eaw", temporal={"static_radius": 0}))


def test_a_dolly_without_motion_or_positions_uses_the_colours_motion():
    # As `denoise --sequence` does (tests/camera_fit_test.cpp): frames with neither motion nor
    # positions get motion estimated from their colours; zero motion (frames taken as still)
    # averages what moved. The same dolly gives 0.061 against 0.397 from the CLI; the bound is half.
    seq = list(atrous.render_sequence("cornell-spheres", 6, camera_path="dolly", width=96, height=72, spp=2, seed=5))
    refs = list(atrous.render_sequence("cornell-spheres", 6, camera_path="dolly", width=96, height=72, spp=128,
                                       seed=77))
    bare = [{k: v for k, v in f.items() if k not in ("motion", "position", "time")} for f in seq]
    still = [dict(f, motion=np.zeros(f["color"].shape[:2] + (2,), np.float32)) for f in bare]
    est = np.mean([atrous.relmse(atrous.denoise_temporal(bare, c, method="eaw"), refs[c]["color"]) for c in range(6)])
    zero = np.mean([atrous.relmse(atrous.denoise_temporal(still, c, method="eaw"), refs[c]["color"]) for c in range(6)])
    assert est < 0.5 * zero, (est, zero)


def test_ids_of_two_channels_as_read_buffers_gives_them(frames):
    # atrous.read_buffers gives ids as H x W x 2 (object, material): denoise_temporal takes that.
    two = [dict(f, ids=np.ascontiguousarray(f["ids"][..., :2])) for f in frames]
    np.testing.assert_array_equal(atrous.denoise_temporal(two, 2, method="eaw"),
                                  atrous.denoise_temporal(frames, 2, method="eaw"))


def test_estimated_motion_only_for_the_window(frames):
    # Colour-only frames: motion is estimated for the frames the window reads; a frame of another
    # size outside the window is not looked at (as with motion vectors), and one inside is named.
    small = [{"color": f["color"]} for f in frames[:2]]
    odd = {"color": np.ones((32, 48, 3), np.float32)}
    one = {"radius": 1, "static_radius": 0}  # the window: t-1..t+1
    out = atrous.denoise_temporal(small + [odd], 0, method="eaw", temporal=one)
    assert out.shape == (32, 40, 3) and np.isfinite(out).all()
    with pytest.raises(ValueError, match="frame 2"):
        atrous.denoise_temporal(small + [odd], 1, method="eaw", temporal=one)
