"""atrous.read_buffers: one render's buffers as another renderer wrote them (include/atrous/io.h,
readRenderFiles), the reader `atrous denoise --in` uses. A Blender-style multilayer EXR is written
here with the OpenEXR binding (one part per pass, 'ViewLayer.<Pass>.<Channel>' names)."""
import subprocess

import numpy as np
import pytest

import atrous
from atrous_cli import atrous_cli

OpenEXR = pytest.importorskip("OpenEXR")


@pytest.fixture(scope="module")
def layered(tmp_path_factory):
    rng = np.random.default_rng(3)
    h, w = 24, 32
    b = atrous.render("cornell", width=w, height=h, spp=4, seed=9)
    parts = []
    def part(name, chans, arr):
        data = {f"ViewLayer.{name}.{c}": np.ascontiguousarray(arr[..., i], np.float32) for i, c in enumerate(chans)}
        parts.append(OpenEXR.Part({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
                                   "name": f"ViewLayer.{name}"}, data))
    rgba = np.concatenate([b["color"], np.ones((h, w, 1), np.float32)], 2)
    part("Combined", "RGBA", rgba)
    part("Denoising Albedo", "RGB", b["albedo"])
    part("Denoising Normal", "XYZ", b["normal"])
    part("Depth", "Z", b["depth"][..., :1] + 0 * rng.random((h, w, 1)))
    path = tmp_path_factory.mktemp("layered") / "render0001.exr"
    OpenEXR.File(parts).write(str(path))
    return path, b


def test_reads_the_passes_by_their_blender_names(layered):
    path, b = layered
    r = atrous.read_buffers(path)
    assert sorted(r) == ["albedo", "color", "depth", "normal"]
    assert r["color"].shape == (24, 32, 3) and r["depth"].shape == (24, 32, 1)
    np.testing.assert_array_equal(r["color"], b["color"])
    np.testing.assert_array_equal(r["albedo"], b["albedo"])
    np.testing.assert_array_equal(r["depth"][..., 0], b["depth"][..., 0])
    out = atrous.denoise(**r)
    assert out.shape == (24, 32, 3) and np.isfinite(out).all()


def test_an_explicit_pass_and_bad_input(layered, tmp_path):
    path, b = layered
    r = atrous.read_buffers(path, passes={"color": "ViewLayer.Denoising Albedo"})
    np.testing.assert_array_equal(r["color"], b["albedo"])
    with pytest.raises(ValueError, match="render0001.exr"):
        atrous.read_buffers(path, passes={"albedo": "ViewLayer.Nothing"})
    with pytest.raises(ValueError, match="layer"):
        atrous.read_buffers(path, layer="OtherLayer")
    bad = tmp_path / "bad.exr"
    bad.write_bytes(b"v/1\x01" + b"\0" * 40)
    with pytest.raises(ValueError, match="bad.exr"):
        atrous.read_buffers(bad)
    with pytest.raises(ValueError, match="missing"):
        atrous.read_buffers(tmp_path / "missing.exr")


@pytest.mark.skipif(atrous_cli() is None, reason="needs the atrous CLI (build/atrous or ATROUS_CLI)")
def test_denoise_of_what_it_reads_is_the_clis_output(layered, tmp_path):
    path, _ = layered
    subprocess.run([atrous_cli(), "denoise", "--in", str(path), "--out", str(tmp_path / "cli.exr")], check=True,
                   capture_output=True)
    np.testing.assert_array_equal(atrous.denoise(**atrous.read_buffers(path)), atrous.read_image(tmp_path / "cli.exr"))


def test_ids_of_one_two_or_three_channels():
    b = atrous.render("cornell", width=24, height=16, spp=2, seed=4)
    ids = b["ids"]  # H x W x 3: object, material, 0
    kw = dict(albedo=b["albedo"], normal=b["normal"], method="eaw")
    three = atrous.denoise(b["color"], ids=ids, **kw)
    np.testing.assert_array_equal(atrous.denoise(b["color"], ids=np.ascontiguousarray(ids[..., :2]), **kw), three)
    one = atrous.denoise(b["color"], ids=np.ascontiguousarray(ids[..., :1]), **kw)  # repeated, as H x W
    np.testing.assert_array_equal(one, atrous.denoise(b["color"], ids=np.ascontiguousarray(ids[..., 0]), **kw))
