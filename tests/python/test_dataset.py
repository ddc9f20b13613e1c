"""The learned filter's training scenes (scripts/train/dataset.py, docs/learned.md "Data"): a scene is
a pure function of (seed, index, kind); data version 2's extras (a fence of thin slats, a window-lit
room) are drawn from their own stream, so a scene without them is version 1's scene; a window room is
closed with the camera inside it; the held-out split never gets the extras; the CLI renders every kind
of scene; a cached scene that the generator no longer draws is redrawn."""
import json
import types
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
import dataset  # noqa: E402  (scripts/train: pytest's pythonpath, pyproject.toml)
from atrous_cli import atrous_cli  # noqa: E402


@pytest.fixture(autouse=True)
def _exr_through_the_library(monkeypatch):
    # dataset.py reads and writes EXR with OpenEXR (.venv-train); here the library's own I/O does it.
    atrous = pytest.importorskip("atrous")
    monkeypatch.setattr(dataset, "_write_exr", lambda path, img: atrous.write_image(str(path), img.astype(np.float32)))
    monkeypatch.setattr(dataset, "read_exr", lambda path: np.asarray(atrous.read_image(str(path)), np.float32))


def _names(scene):
    return {o["name"] for o in scene["objects"]}


def _scene(tmp_path, i, kind=None, extras=True):
    kind = kind or dataset.scene_kind(1, i, "studio")
    d = tmp_path / f"s{i}_{extras}"
    d.mkdir(exist_ok=True)
    return d, dataset.make_scene(1, i, d, kind, extras=extras)


def test_scenes_are_pure_and_extras_only_add(tmp_path):
    fences = windows = 0
    for i in range(40):
        _, a = _scene(tmp_path, i)
        (tmp_path / "again").mkdir(exist_ok=True)
        _, b = _scene(tmp_path / "again", i)
        assert json.dumps(a) == json.dumps(b), f"scene {i} is not a pure function of (seed, index)"
        _, v1 = _scene(tmp_path, i, extras=False)
        names = _names(a)
        fences += "ofence" in names
        windows += "front" in names
        if not {"ofence", "front"} & names:
            assert json.dumps(a) == json.dumps(v1), f"scene {i} without extras differs from version 1"
        else:
            assert all(a["materials"][k] == m for k, m in v1["materials"].items())  # version 1's kept
    # the extras' probabilities (0.4 fence; 0.5 window of the ~1/3 rooms) give both in 40 scenes
    assert fences >= 5 and windows >= 2


def test_window_room_is_closed_with_the_camera_inside(tmp_path):
    rooms = [i for i in range(60) if dataset.scene_kind(1, i, "studio") == "room"]
    seen = 0
    for i in rooms:
        _, s = _scene(tmp_path, i, "room")
        names = _names(s)
        if "front" not in names:
            continue
        seen += 1
        assert "right" not in names and {"right_low", "right_high", "right_a", "right_b"} <= names
        assert any(light["type"] == "sky" for light in s["lights"])
        x, y, z = s["camera"]["position"]
        assert -3 < x < 3 and 0 < y < 4 and -3 < z < 3, f"scene {i}: camera outside the closed room"
        for o in s["objects"]:
            if o["name"].startswith("o") and o["name"] != "ofence":
                assert dataset._object_z(o) <= 1.2, f"scene {i}: object {o['name']} next to the camera"
    assert seen >= 2


def test_held_out_split_has_no_extras(tmp_path):
    for i in range(16):
        _, s = _scene(tmp_path, 100000 + i, "studio", extras=False)
        assert not {"ofence", "front"} & _names(s)


def test_fence_obj_is_closed_boxes(tmp_path):
    rng = np.random.default_rng(5)
    f = dataset._fence(rng, tmp_path, "fence")
    lines = (tmp_path / f["file"]).read_text().splitlines()
    v = [line for line in lines if line.startswith("v ")]
    faces = [line for line in lines if line.startswith("f ")]
    assert len(v) % 8 == 0 and len(faces) == 6 * len(v) // 8
    assert max(int(k) for line in faces for k in line.split()[1:]) == len(v)


@pytest.mark.skipif(atrous_cli() is None, reason="needs the atrous CLI (build/atrous or ATROUS_CLI)")
def test_cli_renders_every_kind_and_a_changed_scene_is_redrawn(tmp_path):
    picks = {}
    for i in range(60):
        kind = dataset.scene_kind(1, i, "studio")
        _, s = _scene(tmp_path, i, kind)
        tag = (kind, "front" in _names(s), "ofence" in _names(s))
        picks.setdefault(tag, i)
    assert len(picks) >= 5
    args = types.SimpleNamespace(out=str(tmp_path / "cache"), atrous=atrous_cli(), seed=1, size=16, ref_spp=1024,
                                 spps=list(dataset.SPPS))
    for (kind, _, _), i in picks.items():
        dest = dataset.build_scene(args, i, "train", kind)
        with np.load(dest) as z:
            assert np.isfinite(z["reference"]).all() and z["reference"].shape == (16, 16, 3)
    # A cached scene the generator no longer draws (here: the held-out split's rule) is redrawn;
    # an unchanged one is kept.
    (kind, _, _), i = next(((t, i) for t, i in picks.items() if t[1] or t[2]))
    dest = Path(args.out) / "data" / "train" / f"scene_{i:04d}.npz"
    held = Path(args.out) / "data" / "test" / f"scene_{i:04d}.npz"
    held.parent.mkdir(parents=True, exist_ok=True)
    held.write_bytes(dest.read_bytes())  # the train version 2 scene, filed under the held-out split
    before = held.stat().st_mtime_ns
    dataset.build_scene(args, i, "test", kind)
    with np.load(held) as z:
        assert not {"ofence", "front"} & _names(json.loads(str(z["scene_json"])))
    assert held.stat().st_mtime_ns != before
    kept = dest.stat().st_mtime_ns
    dataset.build_scene(args, i, "train", kind)
    assert dest.stat().st_mtime_ns == kept


@pytest.mark.skipif(atrous_cli() is None, reason="needs the atrous CLI (build/atrous or ATROUS_CLI)")
def test_a_cached_scene_renders_only_the_sample_counts_it_lacks(tmp_path):
    # A cache made before the 64 and 256 spp inputs were drawn keeps its renders and its reference;
    # only the missing counts are rendered and added.
    args = types.SimpleNamespace(out=str(tmp_path / "cache"), atrous=atrous_cli(), seed=1, size=16, ref_spp=1024,
                                 spps=[1, 4])
    dest = dataset.build_scene(args, 3, "train", dataset.scene_kind(1, 3, "studio"))
    with np.load(dest) as z:
        before = {k: z[k] for k in z.files}
    assert "color_1" in before and "color_64" not in before
    args.spps = [1, 4, 64]
    dataset.build_scene(args, 3, "train", dataset.scene_kind(1, 3, "studio"))
    with np.load(dest) as z:
        assert "color_64" in z.files and np.isfinite(z["color_64"]).all()
        for k in ("color_1", "color_4", "reference"):
            assert np.array_equal(z[k], before[k]), k
