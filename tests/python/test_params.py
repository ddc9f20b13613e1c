"""The parameter tables as Python sees them (include/atrous/params.h; tests/params_test.cpp checks
the C++ side): every row is a keyword that sets its field and nothing else, out-of-range values
raise ValueError naming the keyword, and the docstrings list every keyword."""
import math

import numpy as np
import pytest

import atrous
from atrous import _core

TABLES = [("denoise", atrous.denoise_params, _core.resolve_denoise_params),
          ("svgf", atrous.svgf_params, _core.resolve_svgf_params)]


def f32(x):
    return float(np.float32(x))


def allowed(row, v):
    if not math.isfinite(v):
        return False
    if row["zero"] and v == 0:
        return True
    return (row["min"] < v if row["min_open"] else row["min"] <= v) and v <= row["max"]


def other_value(row):
    d = row["default"]
    k = row["kind"]
    if k == "bool":
        return not d
    if k == "choice":
        return next(c for c in row["choices"] if c != d)
    if k == "float_list":
        return [0.0, 0.5]
    if k == "int":
        return next(v for v in (d + 1, d - 1) if allowed(row, v))
    return next(f32(v) for v in (d * 2, d * 0.5, 0.75, 0.5) if f32(v) != d and allowed(row, v))


def bad_value(row):
    if row["kind"] == "float_list":
        return [0.0, 2.0]
    for v in (row["min"] - 1, row["max"] + 1, -1.0, 1e30):
        if math.isfinite(v) and not allowed(row, v):
            return int(v) if row["kind"] == "int" else v
    return float("nan")


@pytest.mark.parametrize("name, rows, resolve", TABLES)
def test_every_keyword_sets_its_field_and_only_it(name, rows, resolve):
    defaults = resolve({})
    assert [r["name"] for r in rows()] == list(defaults)
    for row in rows():
        assert defaults[row["name"]] == row["default"], row["name"]
        v = other_value(row)
        got = resolve({row["name"]: v})
        assert got[row["name"]] == v, row["name"]
        assert {k: x for k, x in got.items() if k != row["name"]} == \
               {k: x for k, x in defaults.items() if k != row["name"]}, row["name"]
        for alias in row["aliases"]:  # the CLI's negative switch: no_firefly=True is firefly=False
            assert resolve({alias: True})[row["name"]] is (not row["default"]), alias


def test_the_table_keeps_the_known_keywords_and_flags():
    rows = {r["name"]: r for r in atrous.denoise_params()}
    assert rows["sure_window"]["flag"] == "--sure-window"
    assert rows["firefly"]["aliases"] == ["no_firefly"] and rows["firefly"]["flag"] == "--no-firefly"
    assert rows["use_ids"]["aliases"] == ["no_ids"]
    assert rows["sure_mode"]["choices"] == ["discrete", "james-stein"]
    assert _core.resolve_denoise_params({"sure_mode": "james_stein"})["sure_mode"] == "james-stein"
    svgf = {r["name"]: r for r in atrous.svgf_params()}
    assert svgf["reproject_depth_tolerance"]["flag"] == "--svgf-depth-tolerance"
    assert svgf["taa"]["flag"] == "--taa" and svgf["sigma_l"]["flag"] == "--svgf-sigma-l"


def test_out_of_range_values_name_the_keyword():
    c = np.full((8, 8, 3), 0.5, np.float32)
    tried = 0
    for row in atrous.denoise_params():
        if row["kind"] in ("bool", "choice"):
            continue
        tried += 1
        with pytest.raises(ValueError) as e:
            atrous.denoise(c, method="eaw", **{row["name"]: bad_value(row)})
        assert f"{row['name']} must" in str(e.value) and "--" not in str(e.value), str(e.value)
    for row in atrous.svgf_params():
        if row["kind"] in ("bool", "choice"):
            continue
        tried += 1
        with pytest.raises(ValueError) as e:
            atrous.Svgf(device="cpu", **{row["name"]: bad_value(row)})
        assert f"{row['name']} must" in str(e.value) and "--" not in str(e.value), str(e.value)
    assert tried >= 30
    with pytest.raises(ValueError, match="unknown SVGF parameter 'sigma_x'"):
        atrous.Svgf(device="cpu", sigma_x=1.0)
    with pytest.raises(ValueError, match="sure_mode must be discrete or james-stein"):
        atrous.denoise(c, sure_mode="stein")


def test_docstrings_list_every_keyword():
    doc = " ".join(atrous.denoise.__doc__.split())
    for row in atrous.denoise_params():
        assert row["name"] in doc
        for a in row["aliases"]:
            assert a in doc
    doc = " ".join(atrous.Svgf.__doc__.split())
    for row in atrous.svgf_params():
        assert row["name"] in doc
    assert "{params}" not in atrous.denoise.__doc__
