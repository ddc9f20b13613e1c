"""The third-party corpus's training split (scripts/corpus, docs/corpus.md "Training split"): its
seeds never meet the test corpus's, and train_export.py turns a render into dataset.py's npz
format through `atrous inspect --export` (the CLI's reader and conventions)."""
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
import common  # noqa: E402  (scripts/corpus: pytest's pythonpath, pyproject.toml)
from atrous_cli import atrous_cli  # noqa: E402


def test_training_seeds_are_distinct_and_never_the_test_corpus_seeds():
    train = [seed for k in range(100) for _, seed, _ in common.train_jobs(k)]
    assert len(train) == len(set(train)), "two training renders share a seed"
    test = set(common.SEED_NOISY.values()) | {common.SEED_REF}
    for mode in common.MODES.values():
        test |= {common.SEED_SEQ + f for f in range(mode["seq_frames"])}
        test |= {common.SEED_SEQ_REF + f for f in range(mode["seq_frames"])}
    assert not test & set(train)
    # each scene: the noisy spp of dataset.py and a reference of >= 1024 spp (dataset.py's rule)
    spps = [spp for spp, _, _ in common.train_jobs(3)]
    assert spps[:-1] == [1, 4, 16] and spps[-1] >= 1024


def test_train_export_writes_dataset_format_from_what_atrous_reads(tmp_path):
    atrous = pytest.importorskip("atrous")
    vpy = ROOT / ".venv-corpus" / "bin" / "python"  # OpenEXR lives there (docs/corpus.md)
    cli = atrous_cli()
    if not vpy.exists() or cli is None:
        pytest.skip("needs .venv-corpus (scripts/corpus/setup.sh) and the atrous CLI (build/atrous or ATROUS_CLI)")
    h, w = 6, 7
    rng = np.random.default_rng(1)
    scene = tmp_path / "corpus" / "mitsuba" / "tr_mi_00"
    files = {}
    for spp, seed, stem in common.train_jobs(0):
        d = scene / stem
        d.mkdir(parents=True)
        color = rng.uniform(0, 2, (h, w, 3)).astype(np.float32)
        albedo = rng.uniform(0, 1.5, (h, w, 3)).astype(np.float32)  # above 1: clipped by the reader
        normal = np.zeros((h, w, 3), np.float32)
        normal[..., 2] = 2.0  # length 2: normalised by the reader
        depth = np.full((h, w, 3), 3.0, np.float32)
        depth[0, 0] = 0.0  # Mitsuba's background: 1e30 after the reader
        for name, a in (("color", color), ("albedo", albedo), ("normal", normal), ("depth", depth)):
            atrous.write_image(str(d / f"{name}.exr"), a)
        files[stem] = {"spp": spp, "seed": seed, "folder": stem, "color": color}
    man = {"scene": "tr_mi_00", "renderer": "mitsuba", "layout": "separate", "reference": "ref1024",
           "render_seconds": {"ref1024": 1.0},
           "files": {k: {kk: vv for kk, vv in v.items() if kk != "color"} for k, v in files.items()}}
    (scene / "manifest.json").write_text(json.dumps(man))
    out = tmp_path / "npz"
    r = subprocess.run([str(vpy), str(ROOT / "scripts" / "corpus" / "train_export.py"), "--atrous", cli,
                        "--corpus", str(tmp_path / "corpus"), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    z = np.load(out / "scene_tr_mi_00.npz")
    for spp in (1, 4, 16):
        for k in ("color", "albedo", "normal", "depth", "emission"):
            assert z[f"{k}_{spp}"].shape == (h, w, 3) and z[f"{k}_{spp}"].dtype == np.float32, (k, spp)
        assert f"variance_{spp}" not in z.files
        np.testing.assert_array_equal(z[f"color_{spp}"], files[f"spp{spp:04d}"]["color"])  # float32 exact
        assert z[f"albedo_{spp}"].max() <= 1.0
        np.testing.assert_allclose(z[f"normal_{spp}"][..., 2], 1.0, rtol=0, atol=1e-6)
        assert z[f"depth_{spp}"][0, 0, 0] == np.float32(1e30) and z[f"depth_{spp}"][1, 1, 0] == 3.0
        assert not z[f"emission_{spp}"].any()  # Mitsuba writes none
    np.testing.assert_array_equal(z["reference"], files["ref1024"]["color"])
    assert str(z["kind"]) == "mitsuba" and json.loads(str(z["scene_json"]))["scene"] == "tr_mi_00"
    # idempotent: a second run skips the scene (npz newer than the manifest)
    before = (out / "scene_tr_mi_00.npz").stat().st_mtime_ns
    r = subprocess.run([str(vpy), str(ROOT / "scripts" / "corpus" / "train_export.py"), "--atrous", cli,
                        "--corpus", str(tmp_path / "corpus"), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0 and (out / "scene_tr_mi_00.npz").stat().st_mtime_ns == before
