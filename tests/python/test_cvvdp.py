"""atrous.eval.cvvdp, the atrous-cvvdp command behind `atrous compare --sequence`'s CVVDP column:
its --check says why it cannot run where cvvdp is not installed (the project's venv), and where it
is, a sequence against itself is 10 JOD and a noisy one less."""
import subprocess
import sys

import numpy as np
import pytest

import atrous
from atrous.eval import cvvdp


def _frames(seed, noise):
    rng = np.random.default_rng(seed)
    base = np.linspace(0.0, 2.0, 48 * 40 * 3, dtype=np.float32).reshape(40, 48, 3)
    return [np.maximum(base + rng.normal(0, noise, base.shape).astype(np.float32), 0) for _ in range(4)]


def test_check_and_mismatched_sequences():
    r = subprocess.run([sys.executable, "-m", "atrous.eval.cvvdp", "--check"], capture_output=True, text=True)
    if cvvdp.unavailable():
        assert r.returncode == 3 and "pip install cvvdp" in r.stdout
    else:
        assert r.returncode == 0 and "ready" in r.stdout
    with pytest.raises(ValueError, match="3 test frames against 4"):
        cvvdp.jod(_frames(1, 0.1)[:3], _frames(2, 0.0))


def test_tonemap_is_the_metrics_tonemap():
    x = np.array([[[0.0, 1.0, 3.0], [-1.0, 1e9, 0.25]]], np.float32)
    want = np.clip((np.maximum(x, 0) / (1 + np.maximum(x, 0))) ** (1 / 2.2), 0, 1)
    np.testing.assert_allclose(atrous.tonemap(x), want, rtol=1e-6, atol=1e-7)


@pytest.mark.skipif(cvvdp.unavailable() is not None, reason="cvvdp is not installed (pip install cvvdp)")
def test_jod_of_a_sequence_where_installed(tmp_path):
    ref = _frames(0, 0.0)
    assert cvvdp.jod(ref, ref) == pytest.approx(10.0, abs=1e-3)
    noisy = cvvdp.jod(_frames(3, 0.2), ref)
    assert 0.0 < noisy < 9.9
    lines = []
    for i, (r, t) in enumerate(zip(ref, _frames(3, 0.2))):
        atrous.write_image(tmp_path / f"r{i}.exr", r)
        atrous.write_image(tmp_path / f"t{i}.exr", t)
        lines.append(f"{tmp_path / f'r{i}.exr'}\t{tmp_path / f't{i}.exr'}")
    (tmp_path / "pairs.txt").write_text("\n".join(lines) + "\n")
    out = subprocess.run([sys.executable, "-m", "atrous.eval.cvvdp", "--pairs", str(tmp_path / "pairs.txt")],
                         capture_output=True, text=True, check=True).stdout
    assert float(out.split("JOD:")[1]) == pytest.approx(noisy, abs=0.05)  # EXR round trip
