"""The fuzz harness's Python-binding cases (tests/fuzz/fuzz_python.py, docs/reliability.md): seeded
calls of render, render_sequence, denoise, read_image and write_image with out-of-range values,
special floats and odd paths, and of every file reader (read_image on layered, damaged,
huge-window, offset, deep and tiled EXRs; denoise/Svgf with bad learned-weight files;
atrous.learn.weights.from_bytes), each in a forked child of one driver interpreter (a crash there
is a finding, not the end of this run). None may crash, hang, raise anything but
ValueError/TypeError (naming the file, for the file readers), return NaN/Inf, accept a value
outside its documented range, or peak above 300 MB."""
import os
import random
import sys

import fuzz  # noqa: E402  (tests/fuzz: pytest's pythonpath, pyproject.toml)


def test_python_binding_cases(tmp_path):
    os.makedirs(tmp_path / "seeds")
    fuzz.write_pfm(str(tmp_path / "seeds" / "env.pfm"), 8, 4, [0.5] * 96)
    fuzz.write_png(str(tmp_path / "seeds" / "tex.png"), 8, 8, [100] * 192)
    cases = fuzz.python_cases(random.Random(14), 60, str(tmp_path))  # synthetic buffers: no CLI needed
    res = fuzz.run_python_cases(sys.executable, cases, 120)
    bad = [(c["note"], c["args"], res[c["id"]]) for c in cases if res[c["id"]][0] in fuzz.FAILURES]
    assert not bad, bad
