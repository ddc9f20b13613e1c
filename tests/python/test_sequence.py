"""atrous.denoise_sequence: a sequence from its files to files, the library's session that
`atrous denoise --sequence` and the Blender add-on run (include/atrous/sequence.h)."""
import subprocess
from pathlib import Path

import numpy as np
import pytest

import atrous
from atrous_cli import atrous_cli


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    """Five 2-spp frames of cornell-moving in atrous's layout (colour, albedo, normal, depth, motion)."""
    d = tmp_path_factory.mktemp("seq")
    for i, f in enumerate(atrous.render_sequence("cornell-moving", 5, width=40, height=32, spp=2, seed=5)):
        fd = d / f"frame_{i:04d}"
        fd.mkdir()
        for name in ("color", "albedo", "normal", "depth", "motion"):
            atrous.write_image(fd / f"{name}.exr", f[name])
    return d


def test_every_frame_written_and_reported(sequence, tmp_path):
    seen = []
    r = atrous.denoise_sequence(sequence, tmp_path / "out", method="temporal", spatial="eaw", preview=False,
                                on_frame=seen.append)
    assert (r["width"], r["height"]) == (40, 32)
    assert r["buffers"] == ["color", "albedo", "normal", "depth", "motion"]
    assert [f["index"] for f in r["frames"]] == [0, 1, 2, 3, 4] and seen == r["frames"]
    for f in r["frames"]:
        assert f["method_used"] == "eaw" and f["line"].startswith(f"frame_{f['index']:04d}: temporal")
        img = atrous.read_image(f["output"])
        assert img.shape == (32, 40, 3) and np.isfinite(img).all()
        assert Path(f["output"]).with_suffix(".png").is_file()
    assert r["preview"] is None


def test_radius_zero_is_the_still_method_per_frame(sequence, tmp_path):
    atrous.denoise_sequence(sequence, tmp_path / "t", temporal={"radius": 0}, spatial="sure", preview=False)
    atrous.denoise_sequence(sequence, tmp_path / "s", method="sure", preview=False, pngs=False)
    for i in range(5):
        a = atrous.read_image(tmp_path / "t" / f"frame_{i:04d}.exr")
        b = atrous.read_image(tmp_path / "s" / f"frame_{i:04d}.exr")
        np.testing.assert_array_equal(a, b)
    assert not (tmp_path / "s" / "frame_0000.png").exists()


@pytest.mark.skipif(atrous_cli() is None, reason="needs the atrous CLI (build/atrous or ATROUS_CLI)")
def test_the_same_files_as_the_cli(sequence, tmp_path):
    atrous.denoise_sequence(sequence, tmp_path / "py", preview=False, start=1, end=3)
    subprocess.run([atrous_cli(), "denoise", "--sequence", str(sequence), "--out", str(tmp_path / "cli"),
                    "--start", "1", "--end", "3"], check=True, capture_output=True)
    names = sorted(p.name for p in (tmp_path / "py").iterdir())
    assert names == ["frame_0001.exr", "frame_0001.png", "frame_0002.exr", "frame_0002.png", "frame_0003.exr",
                     "frame_0003.png"]
    for n in names:
        if n.endswith(".exr"):
            np.testing.assert_array_equal(atrous.read_image(tmp_path / "py" / n), atrous.read_image(tmp_path / "cli" / n))


def test_the_static_window_needs_the_renderers_motion(tmp_path):
    # Positions but no motion vectors (LuxCore's layout, in atrous's files): the motion is fitted
    # to the Position pass and sees the moving sphere as still, so the static window is off.
    d = tmp_path / "seq"
    for i, f in enumerate(atrous.render_sequence("cornell-moving", 5, width=40, height=32, spp=2, seed=5)):
        fd = d / f"frame_{i:04d}"
        fd.mkdir(parents=True)
        for name in ("color", "albedo", "normal", "depth", "position"):
            atrous.write_image(fd / f"{name}.exr", f[name])
    atrous.denoise_sequence(d, tmp_path / "a", preview=False)
    atrous.denoise_sequence(d, tmp_path / "b", preview=False, temporal={"static_radius": 0})
    for n in ("frame_0000.exr", "frame_0002.exr", "frame_0004.exr"):
        np.testing.assert_array_equal(atrous.read_image(tmp_path / "a" / n), atrous.read_image(tmp_path / "b" / n))


def test_bad_input_raises_and_writes_nothing(sequence, tmp_path):
    out = tmp_path / "out"
    with pytest.raises(ValueError, match="cannot denoise a sequence"):
        atrous.denoise_sequence(sequence, out, method="median")
    with pytest.raises(ValueError, match="not a directory"):
        atrous.denoise_sequence(tmp_path / "missing", out)
    with pytest.raises(ValueError, match="radius"):
        atrous.denoise_sequence(sequence, out, temporal={"radius": -1})
    with pytest.raises(ValueError, match="temporal method averages"):
        atrous.denoise_sequence(sequence, out, step=2)
    bad = tmp_path / "bad"
    bad.mkdir()
    for fd in sorted(sequence.iterdir()):
        (bad / fd.name).mkdir()
        for p in fd.iterdir():
            (bad / fd.name / p.name).write_bytes(p.read_bytes())
    (bad / "frame_0003" / "color.exr").write_bytes(b"not an exr")
    with pytest.raises(ValueError, match="frame_0003"):
        atrous.denoise_sequence(bad, out)
    assert not out.exists()


def test_runs_of_one_process_do_not_share_a_stage(sequence, tmp_path):
    # The library releases the GIL: two threads denoising into the same folder stage apart, both
    # finish, and the folder holds one run's frames.
    import threading

    errors = []

    def run():
        try:
            atrous.denoise_sequence(sequence, tmp_path / "out", method="eaw", preview=False, pngs=False)
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=run) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [f"frame_{i:04d}.exr" for i in range(5)]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.partial")]


def test_a_weight_file_is_read_only_by_the_methods_that_use_it(sequence, tmp_path):
    atrous.denoise_sequence(sequence, tmp_path / "eaw", method="eaw", learned_weights=tmp_path / "missing.bin",
                            preview=False)
    with pytest.raises(ValueError, match="missing.bin"):
        atrous.denoise_sequence(sequence, tmp_path / "blend", method="blend", learned_weights=tmp_path / "missing.bin",
                                preview=False)
    assert not (tmp_path / "blend").exists()


def test_a_frame_that_fails_to_decode_mid_run_leaves_nothing(sequence, tmp_path):
    # frame 3's colour cut short: its header passes the up-front check, its pixels do not decode,
    # after frames 0..2 were denoised and staged. Nothing reaches `out`, no staging folder stays.
    bad = tmp_path / "seq"
    for fd in sorted(sequence.iterdir()):
        (bad / fd.name).mkdir(parents=True)
        for p in fd.iterdir():
            (bad / fd.name / p.name).write_bytes(p.read_bytes())
    color = bad / "frame_0003" / "color.exr"
    color.write_bytes(color.read_bytes()[: color.stat().st_size * 2 // 3])
    for method in ("temporal", "eaw"):
        out = tmp_path / f"out_{method}"
        with pytest.raises(ValueError, match="frame_0003"):
            atrous.denoise_sequence(bad, out, method=method, preview=False)
        assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["seq"]
