"""The library's vocabulary from Python: the buffer table (include/atrous/buffers.h), the metrics
every evaluation reports (atrous.relmse, atrous.temporal_metrics) and the weights resource."""
import numpy as np
import pytest

import atrous


def test_buffers_are_the_library_table():
    rows = atrous.buffers()
    names = [r["name"] for r in rows]
    assert names == ["color", "variance", "albedo", "normal", "position", "depth", "object_id",
                     "material_id", "emission", "motion"]
    by = {r["name"]: r for r in rows}
    assert by["depth"]["channels"] == 1 and by["motion"]["channels"] == 2 and by["normal"]["channels"] == 3
    assert not by["normal"]["takes_grey"] and not by["motion"]["takes_grey"] and by["albedo"]["takes_grey"]
    assert "previous" in by["motion"]["meaning"]  # the sign convention is stated


def test_relmse_and_temporal_metrics_are_the_documented_formulas():
    rng = np.random.default_rng(3)
    ref = rng.uniform(0.1, 2.0, (12, 10, 3)).astype(np.float32)
    prev_ref = rng.uniform(0.1, 2.0, (12, 10, 3)).astype(np.float32)
    img = (ref + rng.normal(0, 0.1, ref.shape)).astype(np.float32)
    prev = (prev_ref + rng.normal(0, 0.1, ref.shape)).astype(np.float32)
    r64, i64 = ref.astype(np.float64), img.astype(np.float64)
    want = np.mean((i64 - r64) ** 2 / (r64 ** 2 + 0.01))
    # 1e-9 relative: the library sums the same float64 terms in another order.
    assert atrous.relmse(img, ref) == pytest.approx(want, rel=1e-9)
    d, d_ref = i64 - prev.astype(np.float64), r64 - prev_ref.astype(np.float64)
    want_t = np.mean((d - d_ref) ** 2 / (r64 ** 2 + 0.01))
    t = atrous.temporal_metrics(img, prev, ref, prev_ref)
    assert t["relmse"] == pytest.approx(want_t, rel=1e-9)
    assert atrous.temporal_metrics(ref, prev_ref, ref, prev_ref)["relmse"] == 0.0
    with pytest.raises(ValueError):
        atrous.temporal_metrics(img, prev[:5], ref, prev_ref)


def test_a_weights_object_is_a_resource():
    w = atrous.load_weights  # a bad path is named in the error
    with pytest.raises(ValueError, match="no_such_weights.bin"):
        w("no_such_weights.bin")
