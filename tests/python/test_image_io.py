"""atrous.read_image / atrous.write_image: the library's OpenEXR/PFM/PNG code seen from Python."""
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

import atrous
from atrous_cli import atrous_cli


def _random_image(h=7, w=5, seed=0):
    # Signed values over many octaves (and a denormal-free tiny one): a float32 image that any
    # lossy or half-float path would change.
    rng = np.random.default_rng(seed)
    img = (rng.normal(size=(h, w, 3)) * 10.0 ** rng.integers(-6, 6, size=(h, w, 3))).astype(np.float32)
    img[0, 0] = (1e-30, -3.5e30, 0.0)
    return img


@pytest.mark.parametrize("ext", [".exr", ".pfm"])
def test_float32_round_trip_is_exact(tmp_path, ext):
    img = _random_image()
    path = tmp_path / f"a{ext}"
    atrous.write_image(path, img)
    back = atrous.read_image(path)
    assert back.dtype == np.float32 and back.shape == img.shape and back.flags.c_contiguous
    np.testing.assert_array_equal(back, img)  # both formats store 32-bit floats: bit-exact
    # str paths work the same as pathlib ones.
    np.testing.assert_array_equal(atrous.read_image(str(path)), img)


def test_write_accepts_strided_views_other_floats_and_grey(tmp_path):
    img = _random_image(h=12, w=10)
    view = img[::-2, 1::3]  # negative and non-unit strides
    atrous.write_image(tmp_path / "v.exr", view)
    np.testing.assert_array_equal(atrous.read_image(tmp_path / "v.exr"), view)
    # float64 is converted to float32 (the array rule), so the result equals the float32 cast.
    d = np.linspace(-2.0, 2.0, 4 * 6 * 3).reshape(4, 6, 3) / 3.0
    atrous.write_image(tmp_path / "d.exr", d)
    np.testing.assert_array_equal(atrous.read_image(tmp_path / "d.exr"), d.astype(np.float32))
    # Grey (H x W and H x W x 1) comes back repeated into R, G, B.
    g = np.arange(20, dtype=np.float32).reshape(4, 5) - 7.5
    for name, arr in (("g2.exr", g), ("g3.exr", g[:, :, None]), ("g.pfm", g)):
        atrous.write_image(tmp_path / name, arr)
        back = atrous.read_image(tmp_path / name)
        assert back.shape == (4, 5, 3), name
        for c in range(3):
            np.testing.assert_array_equal(back[:, :, c], g, err_msg=name)


def test_png_is_an_srgb_preview(tmp_path):
    # PNG stores 8-bit sRGB of the clamped value. 0 and 1 are exact codes; 0.5 is code 188, which
    # the reader turns back into linear through the same sRGB curve: 0.5029, within half a code's
    # step there (0.0023; with stb's former plain 2.2 gamma it was 0.511).
    img = np.zeros((2, 3, 3), np.float32)
    img[0] = [0.0, 1.0, 0.5]
    img[1] = [-5.0, 7.0, 0.5]  # clamped to 0 and 1
    atrous.write_image(tmp_path / "p.png", img)
    back = atrous.read_image(tmp_path / "p.png")
    assert back.shape == (2, 3, 3)
    expect = np.clip(img, 0.0, 1.0)
    np.testing.assert_array_equal(back[..., :2], expect[..., :2])
    np.testing.assert_allclose(back[..., 2], expect[..., 2], atol=0.003)


def test_rendered_buffers_round_trip_with_their_shape(tmp_path):
    bufs = atrous.render("cornell", width=24, height=16, spp=2, seed=5)
    for name, arr in bufs.items():
        atrous.write_image(tmp_path / f"{name}.exr", arr)
        back = atrous.read_image(tmp_path / f"{name}.exr")
        assert back.shape == (16, 24, 3), name
        np.testing.assert_array_equal(back, arr, err_msg=name)


def test_reads_what_atrous_render_writes(tmp_path):
    # The pip build has no CLI (ATROUS_BUILD_CLI=OFF); the C++ build's build/atrous (or
    # $ATROUS_CLI) is used when it is there.
    cli = atrous_cli()
    if cli is None:
        pytest.skip("no atrous CLI (set ATROUS_CLI or build build/atrous)")
    out = tmp_path / "r"
    res = subprocess.run([cli, "render", "--scene", "cornell", "--width", "20", "--height", "12", "--spp", "2",
                          "--device", "cpu", "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    names = ("color", "variance", "albedo", "normal", "position", "depth", "ids", "emission")
    imgs = {n: atrous.read_image(out / f"{n}.exr") for n in names}
    for n, img in imgs.items():
        assert img.shape == (12, 20, 3) and img.dtype == np.float32, n
        assert np.isfinite(img).all(), n
    assert imgs["color"].max() > 0  # the Cornell box is lit
    # Single-valued buffers are written with the value repeated in R, G, B.
    np.testing.assert_array_equal(imgs["depth"][:, :, 0], imgs["depth"][:, :, 1])


def _uncompressed_exr(path, channels, planes, h, w):
    """A minimal scanline EXR (NONE compression, FLOAT channels) built by hand, so that the reader
    is also tested on a file its own writer did not make (different channel set, no ZIP)."""
    def attr(n, t, v):
        return n.encode() + b"\0" + t.encode() + b"\0" + struct.pack("<i", len(v)) + v
    names = sorted(channels)  # EXR stores channels in alphabetical order
    chl = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in names) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    hdr = struct.pack("<ii", 20000630, 2) + attr("channels", "chlist", chl)
    hdr += attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box)
    hdr += attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0")
    hdr += attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    hdr += attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
    hdr += attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0"
    row = 4 * w * len(names)
    first = len(hdr) + 8 * h
    offsets = struct.pack(f"<{h}Q", *[first + y * (8 + row) for y in range(h)])
    lines = b"".join(struct.pack("<ii", y, row) + b"".join(planes[c][y].astype("<f4").tobytes() for c in names)
                     for y in range(h))
    Path(path).write_bytes(hdr + offsets + lines)


def test_reads_a_foreign_grey_exr(tmp_path):
    h, w = 3, 4
    y = np.arange(h * w, dtype=np.float32).reshape(h, w) * 0.25 - 1
    _uncompressed_exr(tmp_path / "y.exr", ["Y"], {"Y": y}, h, w)
    back = atrous.read_image(tmp_path / "y.exr")
    assert back.shape == (h, w, 3)
    for c in range(3):
        np.testing.assert_array_equal(back[:, :, c], y)
    # R, G without B is not an RGB image: rejected, naming the file and the channels found.
    _uncompressed_exr(tmp_path / "rg.exr", ["R", "G"], {"R": y, "G": y}, h, w)
    with pytest.raises(ValueError, match=r"rg\.exr.*R,G"):
        atrous.read_image(tmp_path / "rg.exr")


def test_bad_files_raise_value_error_naming_the_file(tmp_path):
    with pytest.raises(ValueError, match=r"missing\.exr: file not found"):
        atrous.read_image(tmp_path / "missing.exr")
    (tmp_path / "text.exr").write_bytes(b"this is not an EXR file at all\n" * 4)
    with pytest.raises(ValueError, match=r"text\.exr"):
        atrous.read_image(tmp_path / "text.exr")
    # A real EXR cut short.
    atrous.write_image(tmp_path / "full.exr", _random_image(h=40, w=30))
    data = (tmp_path / "full.exr").read_bytes()
    (tmp_path / "cut.exr").write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match=r"cut\.exr"):
        atrous.read_image(tmp_path / "cut.exr")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(ValueError, match=r"notes\.txt: unsupported image format"):
        atrous.read_image(tmp_path / "notes.txt")
    with pytest.raises(ValueError, match="is a directory"):
        atrous.read_image(tmp_path)


@pytest.mark.parametrize("shape", [(4, 5, 5), (4, 5, 2), (20,), (2, 4, 5, 3), (0, 5, 3)])  # (4, 5, 4): RGBA, written
def test_write_rejects_wrong_shapes_and_writes_nothing(tmp_path, shape):
    with pytest.raises(ValueError, match=r"out\.exr"):
        atrous.write_image(tmp_path / "out.exr", np.zeros(shape, np.float32))
    assert list(tmp_path.iterdir()) == []


def test_write_rejects_bad_dtypes_paths_and_formats(tmp_path):
    with pytest.raises(ValueError, match=r"i\.exr.*dtype"):
        atrous.write_image(tmp_path / "i.exr", np.zeros((4, 5, 3), np.uint8))
    with pytest.raises(ValueError, match=r"img\.tif.*unsupported output format"):
        atrous.write_image(tmp_path / "img.tif", np.zeros((4, 5, 3), np.float32))
    with pytest.raises(ValueError, match=r"nodir"):
        atrous.write_image(tmp_path / "nodir" / "a.exr", np.zeros((4, 5, 3), np.float32))
    assert list(tmp_path.iterdir()) == []  # no partial or temporary files left behind
