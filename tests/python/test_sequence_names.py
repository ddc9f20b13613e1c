"""atrous.denoise_sequence (issue 49): the outputs keep their input's names or follow a pattern,
an RGBA frame's alpha comes back bit for bit, and errors name Python's keywords."""
import numpy as np
import pytest

import atrous


@pytest.fixture()
def rgba_frames(tmp_path):
    """render0001.exr .. render0003.exr: 24 x 16 noisy RGBA frames, the alpha different per pixel."""
    d = tmp_path / "renders"
    d.mkdir()
    rng = np.random.default_rng(7)
    for i in range(1, 4):
        img = rng.random((16, 24, 4), dtype=np.float32)
        atrous.write_image(d / f"render{i:04d}.exr", img)
    return d


def names(folder):
    return sorted(p.name for p in folder.iterdir() if p.name != "preview.mp4")


def test_outputs_keep_the_inputs_names(rgba_frames, tmp_path):
    r = atrous.denoise_sequence(rgba_frames, tmp_path / "clean", method="eaw", preview=False)
    assert names(tmp_path / "clean") == [f"render{i:04d}.{e}" for i in range(1, 4) for e in ("exr", "png")]
    assert [f["output"] for f in r["frames"]] == [str(tmp_path / "clean" / f"render{i:04d}.exr") for i in range(1, 4)]
    assert [(f["position"], f["count"]) for f in r["frames"]] == [(1, 3), (2, 3), (3, 3)]  # k/N


def test_a_pattern_names_the_outputs(rgba_frames, tmp_path):
    atrous.denoise_sequence(rgba_frames, tmp_path / "p" / "f_###.exr", method="eaw", pngs=False)
    assert names(tmp_path / "p") == ["f_001.exr", "f_002.exr", "f_003.exr"]
    with pytest.raises(ValueError, match="two groups"):
        atrous.denoise_sequence(rgba_frames, tmp_path / "q" / "##_##.exr", method="eaw")
    assert not (tmp_path / "q").exists()


@pytest.mark.parametrize("method", ["eaw", "temporal"])
def test_alpha_passes_through_bit_for_bit(rgba_frames, tmp_path, method):
    atrous.denoise_sequence(rgba_frames, tmp_path / method, method=method, device="cpu", preview=False)
    for i in range(1, 4):
        src = atrous.read_image(rgba_frames / f"render{i:04d}.exr", alpha=True)
        got = atrous.read_image(tmp_path / method / f"render{i:04d}.exr", alpha=True)
        assert got.shape == (16, 24, 4)
        np.testing.assert_array_equal(got[..., 3], src[..., 3])


def test_errors_name_pythons_keywords(rgba_frames, tmp_path):
    with pytest.raises(ValueError) as e:
        atrous.denoise_sequence(rgba_frames, tmp_path / "a", method="eaw", start=1, end=9)
    assert "render0004.exr is missing (end 9)" in str(e.value) and "--" not in str(e.value)
    (rgba_frames / "render0002.exr").unlink()
    with pytest.raises(ValueError) as e:
        atrous.denoise_sequence(rgba_frames, tmp_path / "a", method="eaw")
    assert "render0002.exr is missing" in str(e.value) and "start and end pick a range" in str(e.value)
    assert "--" not in str(e.value)
    with pytest.raises(ValueError, match=r"^out '"):
        atrous.denoise_sequence(rgba_frames, tmp_path / "a" / "x##y##.exr", method="eaw")
    with pytest.raises(ValueError, match=r"^step 2: "):
        atrous.denoise_sequence(rgba_frames, tmp_path / "a", method="temporal", step=2)
    assert not (tmp_path / "a").exists()
