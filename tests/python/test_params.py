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
    assert svgf["depth_tolerance"]["flag"] == "--svgf-depth-tolerance"
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


# ---- the render table (RenderSettings): Python's keywords and errors come from it ----------------

def test_render_params_are_the_tables_rows():
    rows = {r["name"]: r for r in atrous.render_params()}
    assert set(rows) == {"width", "height", "spp", "seed", "first_sample", "max_depth", "threads",
                         "light_sampling"}
    assert rows["width"]["default"] == 512 and rows["max_depth"]["default"] == 8
    assert rows["seed"]["kind"] == "uint" and rows["light_sampling"]["aliases"] == ["no_light_sampling"]
    assert rows["max_depth"]["flag"] == "--max-depth" and rows["first_sample"]["flag"] == ""
    for name in rows:
        assert name in atrous.render.__doc__, name


def test_render_errors_name_the_keyword():
    for kw, msg in (({"width": 0}, "parameter width must be in 1..16384 (got 0)"),
                    ({"max_depth": -3}, "parameter max_depth must be in 0..1024 (got -3)"),
                    ({"threads": 100000}, "parameter threads must be in 0..4096 (got 100000)"),
                    ({"seed": -1}, "parameter seed must be in 0..4294967295 (got -1)")):
        with pytest.raises(ValueError) as e:
            atrous.render("cornell", **dict(dict(width=8, height=8, spp=1), **kw))
        assert str(e.value) == msg
    with pytest.raises(ValueError, match="unknown render parameter 'bounces'"):
        atrous.render("cornell", width=8, height=8, spp=1, bounces=2)
    with pytest.raises(ValueError, match="width must be an integer"):
        atrous.render("cornell", width=8.0, height=8, spp=1)


def test_render_keywords_reach_the_renderer():
    base = atrous.render("cornell", width=16, height=16, spp=2, seed=3)
    again = atrous.render("cornell", width=16, height=16, spp=2, seed=3, threads=1)
    assert np.array_equal(base["color"], again["color"])  # same seed, any thread count
    assert not np.array_equal(base["color"], atrous.render("cornell", width=16, height=16, spp=2, seed=4)["color"])
    direct = atrous.render("cornell", width=16, height=16, spp=2, seed=3, max_depth=1)
    assert not np.array_equal(base["color"], direct["color"])
    bsdf = atrous.render("cornell", width=16, height=16, spp=2, seed=3, no_light_sampling=True)
    assert not np.array_equal(base["color"], bsdf["color"])
    seq = next(atrous.render_sequence("cornell-moving", 2, width=8, height=8, seed=5))
    assert seq["color"].shape == (8, 8, 3) and "motion" not in seq or seq["motion"].shape[:2] == (8, 8)
