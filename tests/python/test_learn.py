"""The learned filter's training side (python/atrous/learn, docs/learned.md): the JAX forward pass
still gives tests/learned_fixture.bin's output (the file tests/learned_test.cpp holds the C++
inference to), and the weight file round-trips and rejects corruption. Skipped without jax
(it lives in .venv-train: scripts/train/setup.sh)."""
import struct
import sys
from pathlib import Path

import numpy as np
import pytest

jax = pytest.importorskip("jax")
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python" / "atrous"))
sys.path.insert(0, str(ROOT / "scripts" / "train"))
from learn import weights  # noqa: E402

import make_fixture  # noqa: E402


def test_jax_forward_equals_fixture():
    data = (ROOT / "tests" / "learned_fixture.bin").read_bytes()
    w, h, n = struct.unpack("<3I", data[4:16])
    params = weights.from_bytes(data[16:16 + n], "fixture")
    planes = np.frombuffer(data[16 + n:], "<f4").reshape(7, 3, h, w).transpose(0, 2, 3, 1)
    inputs = dict(zip(make_fixture.INPUTS, planes[:6]))
    out = make_fixture.forward_np({k: jax.numpy.asarray(v) for k, v in params.items()}, inputs)
    # Same code, same float32 inputs: only XLA's reduction order may differ between versions/CPUs.
    np.testing.assert_allclose(out, planes[6], rtol=1e-5, atol=1e-5)


def test_weight_file_round_trip_and_errors():
    params = make_fixture.fixture_params()
    b = weights.to_bytes(params)
    back = weights.from_bytes(b)
    for k, v in params.items():
        np.testing.assert_array_equal(np.asarray(v), back[k])
    bad = bytearray(b)
    bad[40] ^= 1
    with pytest.raises(ValueError, match="w.bin: truncated or corrupt"):
        weights.from_bytes(bytes(bad), "w.bin")
    with pytest.raises(ValueError, match="no ATRL header"):
        weights.from_bytes(b"XXXX" + b[4:], "w.bin")
