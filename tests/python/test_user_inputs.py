"""What a user hands atrous.denoise besides an HDR RGB array (issue 49): an (H, W, 4) array whose
alpha comes back untouched, an LDR colour (ldr=True: what the CLI does for an 8-bit PNG by itself, bit
for bit), an all-NaN colour, a misspelt keyword, and read_buffers' errors in Python's words."""
import subprocess

import numpy as np
import pytest

import atrous
from atrous_cli import atrous_cli


@pytest.fixture(scope="module")
def render():
    return atrous.render("cornell", width=32, height=24, spp=4, seed=3)


def _alpha(h, w):
    # Values that any arithmetic would disturb: thirds, and a float32 that is no half.
    a = (np.arange(h * w, dtype=np.float32).reshape(h, w, 1) % 7) / np.float32(3.0)
    a[0, 0, 0] = np.float32(0.1234567)
    return a


def test_an_rgba_array_keeps_its_alpha(render):
    c = render["color"]
    a = _alpha(*c.shape[:2])
    rgba = np.concatenate([c, a], axis=2)
    out = atrous.denoise(rgba, albedo=render["albedo"], normal=render["normal"])
    assert out.shape == rgba.shape and out.dtype == np.float32
    np.testing.assert_array_equal(out[..., 3:], a)  # bit for bit
    # The colour is denoised exactly as without the alpha.
    np.testing.assert_array_equal(out[..., :3], atrous.denoise(c, albedo=render["albedo"], normal=render["normal"]))
    # A non-contiguous view of a wider array works too.
    wide = np.concatenate([rgba, rgba], axis=1)[:, ::2]
    np.testing.assert_array_equal(atrous.denoise(wide)[..., 3], wide[..., 3])


def test_rgba_files_round_trip_their_alpha(tmp_path, render):
    c = render["color"]
    a = _alpha(*c.shape[:2])
    rgba = np.concatenate([c, a], axis=2)
    atrous.write_image(tmp_path / "a.exr", rgba)
    back = atrous.read_image(tmp_path / "a.exr", alpha=True)
    np.testing.assert_array_equal(back, rgba)
    assert atrous.read_image(tmp_path / "a.exr").shape == c.shape  # alpha only when asked for
    atrous.write_image(tmp_path / "rgb.exr", c)
    assert atrous.read_image(tmp_path / "rgb.exr", alpha=True).shape == c.shape  # none: 3 channels
    # PNG: alpha as 8-bit codes.
    codes = np.clip(np.round(a * 255), 0, 255) / 255
    atrous.write_image(tmp_path / "a.png", np.concatenate([np.clip(c, 0, 1), codes.astype(np.float32)], axis=2))
    np.testing.assert_array_equal(atrous.read_image(tmp_path / "a.png", alpha=True)[..., 3:], codes.astype(np.float32))
    with pytest.raises(ValueError, match="PFM has no alpha"):
        atrous.write_image(tmp_path / "a.pfm", rgba)


def test_the_cli_and_python_keep_the_same_alpha(tmp_path, render):
    cli = atrous_cli()
    if cli is None:
        pytest.skip("no atrous CLI")
    c = render["color"]
    rgba = np.concatenate([c, _alpha(*c.shape[:2])], axis=2)
    atrous.write_image(tmp_path / "in.exr", rgba)
    subprocess.run([cli, "denoise", "--color", str(tmp_path / "in.exr"), "--out", str(tmp_path / "out.exr")],
                   check=True, capture_output=True)
    np.testing.assert_array_equal(atrous.read_image(tmp_path / "out.exr", alpha=True), atrous.denoise(rgba))


def test_ldr_is_clamped_and_matches_the_cli_bit_for_bit(tmp_path, render):
    noisy = render["color"]
    atrous.write_image(tmp_path / "noisy.png", noisy)
    ldr = atrous.read_image(tmp_path / "noisy.png")
    assert 0.0 <= ldr.min() and ldr.max() <= 1.0
    out = atrous.denoise(ldr, ldr=True)
    assert out.min() >= 0.0 and out.max() <= 1.0
    hdr = atrous.denoise(ldr)
    np.testing.assert_array_equal(out, np.clip(hdr, 0, 1))
    cli = atrous_cli()
    if cli is not None:
        # The CLI reads the same PNG as LDR by itself; its output PNG is Python's, code for code.
        r = subprocess.run([cli, "denoise", "--color", str(tmp_path / "noisy.png"), "--out", str(tmp_path / "cli.exr")],
                           check=True, capture_output=True, text=True)
        assert "LDR input" in r.stderr  # a note: the log is on stderr, the results on stdout (docs/cli.md)
        np.testing.assert_array_equal(atrous.read_image(tmp_path / "cli.exr"), out)
    with pytest.raises(ValueError, match="variance: ldr=True"):
        atrous.denoise(ldr, ldr=True, variance=render["variance"])


def test_png_codes_read_back_through_the_srgb_curve(tmp_path):
    # The reader is the writer's inverse: every 8-bit code read and written again is the same code.
    codes = np.arange(256, dtype=np.float32).reshape(16, 16, 1).repeat(3, axis=2) / 255
    atrous.write_image(tmp_path / "codes.png", codes)  # written through the sRGB curve
    linear = atrous.read_image(tmp_path / "codes.png")
    atrous.write_image(tmp_path / "again.png", linear)
    np.testing.assert_array_equal(atrous.read_image(tmp_path / "again.png"), linear)


def test_a_colour_with_no_finite_pixel_is_a_value_error():
    c = np.full((8, 8, 3), np.nan, np.float32)
    c[::2] = np.inf
    with pytest.raises(ValueError, match="color buffer has no finite pixel"):
        atrous.denoise(c)
    c[3, 3] = 0.5
    assert np.isfinite(atrous.denoise(c)).all()  # one finite pixel: denoised, the rest repaired


def test_an_unknown_keyword_gets_the_nearest_one():
    c = np.full((8, 8, 3), 0.5, np.float32)
    with pytest.raises(ValueError, match=r"unknown denoise parameter 'levles' \(did you mean 'levels'\?\)"):
        atrous.denoise(c, levles=3)
    with pytest.raises(ValueError, match=r"did you mean 'radius'"):
        atrous.temporal_window_radius({"radus": 2})
    with pytest.raises(ValueError) as e:
        atrous.denoise(c, frobnicate=1)
    assert "did you mean" not in str(e.value)


def test_read_buffers_errors_name_pythons_keywords(tmp_path):
    with pytest.raises(ValueError) as e:
        atrous.read_buffers(tmp_path / "missing")
    assert "--in" not in str(e.value) and str(e.value).startswith("path '")
    atrous.write_image(tmp_path / "plain.exr", np.ones((4, 4, 3), np.float32))
    with pytest.raises(ValueError) as e:
        atrous.read_buffers(tmp_path / "plain.exr", layer="ViewLayer")
    assert "--layer" not in str(e.value) and "layer 'ViewLayer'" in str(e.value)
    with pytest.raises(ValueError) as e:
        atrous.read_buffers(tmp_path / "plain.exr", passes={"albedo": "x"})
    assert "--pass" not in str(e.value) and "passes albedo=x" in str(e.value)
