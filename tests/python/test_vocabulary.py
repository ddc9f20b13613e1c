"""The library's vocabulary from Python: the buffer table (include/atrous/buffers.h), the metrics
every evaluation reports (atrous.relmse, atrous.temporal_metrics) and the weights resource."""
import ast
import io
import re
import sys
import tokenize
from pathlib import Path

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


# ------------------------------------------------------------------ no method name as a literal

# apps/ and python/atrous name no method: the names come from the registries (atrous.METHODS,
# atrous.denoise_methods(), atrous.SEQUENCE_METHODS, atrous.names for code about one method; the
# C++ front-ends: denoiseMethods(), denoiseMethodName(...)). Files allowed to spell them: the
# registries' own (in src/, outside what is scanned) and help text generated from them: none here.
_ALLOWED_FILES: set = set()
# Words a method shares with another vocabulary, allowed where the line is about that vocabulary:
# "auto" is also a device (--device auto), a camera path (--camera-path auto) and the farm's Ray
# address; "temporal" is also the temporal error metric of bench/svgf_sequence_tool, which the SVGF
# study (eval/sequences.py) reads and writes under that key.
_SHARED_WORDS = (
    ("auto", None, re.compile(r"device|camera|address|ray start", re.IGNORECASE)),
    ("temporal", "python/atrous/eval/sequences.py", re.compile(r".")),
)
_ROOT = Path(__file__).resolve().parents[2]


def _builtin_method_names() -> set:
    still = {str(r["name"]) for r in atrous.denoise_methods() if not r["registered"]}
    seq = {str(r["name"]) for r in atrous.sequence_methods() if not r["registered"]}
    return still | seq


def _python_literals(path: Path):
    """(line number, line, value) of every plain string literal of a Python file (tokenize: a
    docstring is one literal, so a method named inside prose is not one; f-strings are skipped)."""
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type != tokenize.STRING:
            continue
        try:
            value = ast.literal_eval(tok.string)
        except (ValueError, SyntaxError):
            continue  # an f-string
        if isinstance(value, str):
            yield tok.start[0], lines[tok.start[0] - 1], value


_CPP_TOKEN = re.compile(r'"(?:[^"\\\n]|\\.)*"|//.*')


def _cpp_literals(path: Path):
    """(line number, line, value) of every string literal of a C++ file outside // comments."""
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        for m in _CPP_TOKEN.finditer(line):
            if m.group(0).startswith('"'):
                yield n, line, m.group(0)[1:-1]


def _method_literals(names: set):
    found = []
    files = [(p, _python_literals) for p in sorted((_ROOT / "python" / "atrous").rglob("*.py"))]
    files += [(p, _cpp_literals) for p in sorted((_ROOT / "apps").rglob("*")) if p.suffix in (".cpp", ".h", ".cu")]
    for path, literals in files:
        rel = path.relative_to(_ROOT).as_posix()
        if rel in _ALLOWED_FILES:
            continue
        for n, line, value in literals(path):
            if value not in names:
                continue
            if any(value == w and (f is None or f == rel) and ctx.search(line) for w, f, ctx in _SHARED_WORDS):
                continue
            found.append(f"{rel}:{n}: {line.strip()}")
    return found


def test_no_method_name_is_a_string_literal_in_the_front_ends():
    names = _builtin_method_names()
    # The registries give the names this test looks for: the still and the sequence methods.
    assert set(atrous.names.__all__) and {atrous.names.EAW, atrous.names.SVGF, atrous.names.DEFAULT} <= names
    found = _method_literals(names)
    assert not found, "method names spelled as string literals (read them from the registry):\n" + "\n".join(found)


def test_the_literal_check_finds_one(tmp_path, monkeypatch):
    # The check is not vacuous: a file with a method name as a value is reported, one with it in a
    # docstring, a comment or as the device word is not.
    (tmp_path / "python" / "atrous").mkdir(parents=True)
    (tmp_path / "apps").mkdir()
    name = atrous.names.EAW
    (tmp_path / "python" / "atrous" / "bad.py").write_text(
        f'"""Runs {name!r} by default."""\nDEFAULT = {name!r}\ndevice = "auto"\n')
    (tmp_path / "apps" / "bad.cpp").write_text(f'std::string m = "{name}";  // "{atrous.names.SURE}"\n'
                                               f'// "{atrous.names.SURE}" in a comment\n')
    monkeypatch.setattr(sys.modules[__name__], "_ROOT", tmp_path)
    found = _method_literals(_builtin_method_names())
    assert found == [f"python/atrous/bad.py:2: DEFAULT = {name!r}", f'apps/bad.cpp:1: std::string m = "{name}";  // "{atrous.names.SURE}"']
