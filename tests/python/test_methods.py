"""A still method added from Python is one registry row plus its policy (issue 31): the toy of
toy_plugin.py registered with atrous.register_method is in atrous.methods(), METHODS and the
evaluation's and farm's method lists, and denoise(method="pytoy") is its cascade on the prepared
planes, then the remodulation. The farm's workers load it with --plugin (test_farm.py). Errors:
a taken name, a non-callable, a cascade that raises or writes where it may not."""
import numpy as np
import pytest

import atrous
import toy_plugin
from atrous.eval import all_methods
from atrous.farm.items import denoise_choices, eval_choices


def _render():
    return atrous.render("cornell", width=24, height=20, spp=4, seed=3, max_depth=3)


def test_the_toy_is_in_every_list():
    rows = {r["name"]: r for r in atrous.methods()}
    assert rows["pytoy"]["kind"] == "still" and rows["pytoy"]["registered"]
    assert rows["eaw"]["registered"] is False and rows["svgf"]["kind"] == "sequence"
    assert [r["name"] for r in atrous.methods()][:5] == ["eaw", "sure", "learned", "blend", "auto"]
    assert "pytoy" in atrous.METHODS and "pytoy" not in atrous.WEIGHTED_METHODS
    assert "pytoy" in all_methods() and "pytoy" in denoise_choices() and "pytoy" in eval_choices()
    # Each row names its parameter table, which Python can read: the still methods share denoise's,
    # a sequence method has its own (sequence_params; svgf_params and temporal_params are the same).
    for r in atrous.methods():
        if r["kind"] == "still":
            assert callable(getattr(atrous, r["params"] + "_params")), r
        else:
            assert [p["name"] for p in atrous.sequence_params(r["name"])], r
    assert atrous.sequence_params("svgf") == atrous.svgf_params()
    assert atrous.sequence_params("temporal") == atrous.temporal_params()
    assert rows["pytoy"]["params"] == "denoise" and rows["svgf"]["params"] == "svgf"
    assert rows["temporal"]["params"] == "temporal"
    seq = {r["name"]: r for r in atrous.sequence_methods()}
    known = {b["name"] for b in atrous.buffers()}
    assert set(seq["svgf"]["reads"]) <= known and "motion" in seq["svgf"]["reads"]
    # SVGF reads the variance (and position) for its safety net's still filter only
    assert "variance" in seq["svgf"]["reads"] and "variance" in seq["temporal"]["reads"]
    assert "position" in seq["svgf"]["reads"]


def test_denoise_is_the_cascade_on_the_prepared_planes_then_remodulation():
    b = _render()
    for albedo in (b["albedo"], None):
        got = atrous.denoise(b["color"], albedo=albedo, normal=b["normal"], variance=b["variance"],
                             emission=b["emission"], method="pytoy")
        p = atrous.prepared_planes(b["color"], variance=b["variance"], albedo=albedo, normal=b["normal"],
                                  emission=b["emission"])
        f = np.empty_like(p["color"])
        toy_plugin.toy_cascade({"color": p["color"], "albedo": p.get("albedo")}, f)
        want = f * p["modulation"] + p["emission"]
        # The library's remodulation is one float32 multiply-add per sample, as numpy's here.
        np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-7)
        assert not np.array_equal(got, b["color"])


def test_planes_are_views_of_the_right_shape_and_read_only():
    b = _render()
    seen = {}

    def spy(planes, out):
        seen.update({k: (None if v is None else (v.shape, v.flags.writeable)) for k, v in planes.items()})
        seen["out"] = (out.shape, out.flags.writeable)
        out[...] = planes["color"]

    atrous.register_method("spy", spy)
    got = atrous.denoise(b["color"], albedo=b["albedo"], normal=b["normal"], depth=b["depth"], ids=b["ids"],
                         method="spy", firefly=False)
    assert seen["color"] == ((20, 24, 3), False) and seen["variance"] == ((20, 24, 3), False)
    assert seen["depth"] == ((20, 24, 1), False) and seen["ids"] == ((20, 24, 2), False)
    assert seen["position"] is None and seen["out"] == ((20, 24, 3), True)
    assert np.isfinite(got).all()


def test_bad_registrations_and_cascades():
    with pytest.raises(ValueError, match="already a method 'pytoy'"):
        atrous.register_method("pytoy", toy_plugin.toy_cascade)
    with pytest.raises(ValueError, match="already a method 'sure'"):
        atrous.register_method("sure", toy_plugin.toy_cascade)
    with pytest.raises(ValueError, match="not a method name"):
        atrous.register_method("no good", toy_plugin.toy_cascade)
    with pytest.raises(ValueError, match="callable"):
        atrous.register_method("notcallable", 3)
    b = _render()

    def boom(planes, out):
        raise KeyError("nope")

    def writes_input(planes, out):
        planes["color"][0, 0, 0] = 1.0

    atrous.register_method("boom", boom)
    atrous.register_method("writes-input", writes_input)
    with pytest.raises(RuntimeError, match="method .boom.: its cascade raised KeyError"):
        atrous.denoise(b["color"], method="boom")
    with pytest.raises(RuntimeError, match="read-only"):
        atrous.denoise(b["color"], method="writes-input")


def test_reads_says_which_planes_the_cascade_gets():
    b = _render()
    seen = {}

    def spy(planes, out):
        seen.update({k: v is not None for k, v in planes.items()})
        out[...] = planes["color"]

    atrous.register_method("normal-only", spy, reads=("normal",))
    atrous.denoise(b["color"], albedo=b["albedo"], normal=b["normal"], position=b["position"], depth=b["depth"],
                   ids=b["ids"], method="normal-only")
    assert seen == {"color": True, "variance": True, "normal": True, "albedo": False, "position": False,
                    "depth": False, "ids": False}
    with pytest.raises(ValueError, match="unknown buffer 'motion'"):
        atrous.register_method("bad-reads", spy, reads=("motion",))
    assert "bad-reads" not in atrous.METHODS


def test_a_cascade_that_leaves_nan_or_inf_never_reaches_the_output():
    b = _render()

    def holes(planes, out):
        out[...] = planes["color"]
        out[::3, ::2, 0] = np.nan
        out[1::4, :, 2] = np.inf

    atrous.register_method("holes", holes)
    got = atrous.denoise(b["color"], albedo=b["albedo"], normal=b["normal"], method="holes")
    assert np.isfinite(got).all()
    # Where the cascade was finite its value is kept (an identity cascade: the prepared colour,
    # remodulated; the replaced samples are the prepared colour too, so the whole is that).
    p = atrous.prepared_planes(b["color"], albedo=b["albedo"], normal=b["normal"])
    np.testing.assert_allclose(got, p["color"] * p["modulation"] + p["emission"], rtol=1e-6, atol=1e-7)


def test_the_evaluation_takes_a_plugins_method(tmp_path):
    """python -m atrous.eval --plugin FILE --methods ...,pytoy scores the plugin's method beside the
    built-in ones; a plugin that cannot be loaded is one line and exit 2, nothing written."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    plugin = str(Path(__file__).with_name("toy_plugin.py"))
    small = ["--scenes", "cornell", "--spp", "4", "--size", "24", "--ref-spp", "16", "--runs", "1",
             "--resolutions", "0", "--no-equal-time"]
    out = tmp_path / "ev"
    r = subprocess.run([sys.executable, "-m", "atrous.eval", *small, "--methods", "noisy,eaw,pytoy", "--plugin", plugin,
                        "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    rows = json.loads((out / "results.json").read_text())["results"]
    by = {x["method"]: x["relmse"] for x in rows}
    assert set(by) == {"noisy", "eaw", "pytoy"} and by["pytoy"] < by["noisy"]
    bad = tmp_path / "bad"
    r = subprocess.run([sys.executable, "-m", "atrous.eval", *small, "--plugin", str(tmp_path / "nope.py"),
                        "--out", str(bad)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "nope.py" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not bad.exists()


def test_the_cpp_toy_plugin_is_one_method_for_the_cli_and_python(tmp_path):
    """tests/toy_method.cpp built as a plugin: `atrous --plugin` lists and runs it, and in another
    Python process atrous.load_plugin puts the same row in atrous.methods(); both give the same
    image from the same files (the farm runs it too: test_farm.py)."""
    import subprocess
    import sys

    from atrous_cli import atrous_cli, toy_plugin_so

    so, cli = toy_plugin_so(), atrous_cli()
    if so is None or cli is None:
        pytest.skip("no C++ build with the toy plugin")
    b = _render()
    d = tmp_path / "in"
    d.mkdir()
    for name in ("color", "albedo", "normal"):
        atrous.write_image(d / f"{name}.exr", b[name])
    r = subprocess.run([cli, "--plugin", so, "denoise", "--in", str(d), "--method", "toy", "--out",
                        str(tmp_path / "cli.exr")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    code = ("import sys, atrous; atrous.load_plugin(sys.argv[1]); "
            "rows = {m['name']: m for m in atrous.methods()}; assert rows['toy']['registered']; "
            "bufs = atrous.read_buffers(sys.argv[2]); "
            "atrous.write_image(sys.argv[3], atrous.denoise(method='toy', device='cpu', **bufs))")
    r = subprocess.run([sys.executable, "-c", code, so, str(d), str(tmp_path / "py.exr")], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    np.testing.assert_array_equal(atrous.read_image(tmp_path / "py.exr"), atrous.read_image(tmp_path / "cli.exr"))
    with pytest.raises(ValueError, match="no such plugin file"):
        atrous.load_plugin(tmp_path / "nope.so")


def test_the_cpp_toy_sequence_method_is_one_method_for_the_cli_and_python(tmp_path):
    """tests/toy_sequence_method.cpp, registered by the same plugin's entry point: in another Python
    process atrous.load_plugin puts "toyseq" in SEQUENCE_METHODS and sequence_methods() with its
    table; denoise_sequence writes the CLI's bytes (`atrous --plugin ... denoise --sequence
    --method toyseq`), and a SequenceDenoiser over the same frames gives the same images."""
    import subprocess
    import sys

    from atrous_cli import atrous_cli, toy_plugin_so

    so, cli = toy_plugin_so(), atrous_cli()
    if so is None or cli is None:
        pytest.skip("no C++ build with the toy plugin")
    seq = tmp_path / "seq"
    r = subprocess.run([cli, "render", "--scene", "cornell-moving", "--frames", "3", "--spp", "1", "--width", "24",
                        "--height", "16", "--quiet", "--out", str(seq)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    r = subprocess.run([cli, "--plugin", so, "denoise", "--sequence", str(seq), "--method", "toyseq", "--toyseq-alpha",
                        "0.5", "--out", str(tmp_path / "cli")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    code = ("import sys, atrous\n"
            "from atrous.eval.sequence import list_frames, load_frame\n"
            "atrous.load_plugin(sys.argv[1])\n"
            "assert 'toyseq' in atrous.SEQUENCE_METHODS and 'toyseq' not in atrous.METHODS\n"
            "row = {r['name']: r for r in atrous.sequence_methods()}['toyseq']\n"
            "assert row['registered'] and row['causal'] and row['history'] and row['params'] == 'toyseq', row\n"
            "assert [p['name'] for p in atrous.sequence_params('toyseq')] == ['alpha']\n"
            "rep = atrous.denoise_sequence(sys.argv[2], sys.argv[3], method='toyseq', toyseq={'alpha': 0.5}, "
            "preview=False)\n"
            "assert [f['method_used'] for f in rep['frames']] == ['toyseq'] * 3, rep\n"
            "d = atrous.SequenceDenoiser('toyseq', params={'alpha': 0.5}, device='cpu')\n"
            "for i, p in enumerate(list_frames(sys.argv[2])):\n"
            "    d.push({k: v for k, v in load_frame(p).items() if k != 'reference'})\n"
            "    assert d.ready\n"
            "    atrous.write_image(f'{sys.argv[4]}/{i}.exr', d.next())\n")
    (tmp_path / "stream").mkdir()
    r = subprocess.run([sys.executable, "-c", code, so, str(seq), str(tmp_path / "py"), str(tmp_path / "stream")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    for i in range(3):
        name = f"frame_{i:04d}.exr"
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
        np.testing.assert_array_equal(atrous.read_image(tmp_path / "stream" / f"{i}.exr"),
                                      atrous.read_image(tmp_path / "cli" / name))


def test_sequence_denoiser_is_the_one_interface(tmp_path):
    """svgf through SequenceDenoiser is Svgf; temporal's stream gives denoise_temporal's frames bit
    for bit (each window the same, each frame prepared once); a frame comes out once the frames
    after it that it reads are in; bad names and keywords are ValueErrors."""
    frames = list(atrous.render_sequence("cornell-moving", 4, width=24, height=16, spp=1, seed=4))
    s, g = atrous.Svgf(device="cpu", levels=3), atrous.SequenceDenoiser("svgf", device="cpu", params={"levels": 3})
    assert g.lookahead == 0 and g.lookbehind == 0
    for f in frames:
        a = s.denoise_frame(f["color"], albedo=f["albedo"], normal=f["normal"], depth=f["depth"], ids=f["ids"],
                            motion=f["motion"], emission=f["emission"], position=f["position"],
                            variance=f["variance"])
        g.push(f)
        assert g.ready
        np.testing.assert_array_equal(g.next(), a)
        assert g.method_used == "svgf"
    t = atrous.SequenceDenoiser("temporal", spatial="eaw", device="cpu", params={"radius": 1, "static_radius": 0})
    assert t.lookahead == 1 and t.lookbehind == 1
    outs = []
    for f in frames:
        t.push(f)
        while t.ready:
            outs.append(t.next())
    assert len(outs) == 3 and not t.ready
    t.finish()
    outs.append(t.next())
    for i in range(4):
        lo, hi = max(0, i - 1), min(3, i + 1)
        want = atrous.denoise_temporal(frames[lo:hi + 1], i - lo, method="eaw", device="cpu",
                                       temporal={"radius": 1, "static_radius": 0})
        np.testing.assert_array_equal(outs[i], want)
    with pytest.raises(ValueError, match="unknown method 'median'"):
        atrous.SequenceDenoiser("median")
    with pytest.raises(ValueError, match="unknown SVGF parameter 'sigma_q'"):
        atrous.SequenceDenoiser("svgf", params={"sigma_q": 1})
    with pytest.raises(ValueError, match="still method"):
        atrous.SequenceDenoiser("eaw", params={"radius": 1})
    with pytest.raises(ValueError, match="no frame is ready"):
        atrous.SequenceDenoiser("temporal").next()


def test_names_the_front_ends_use_are_taken_and_reads_takes_one_name():
    for name in ("temporal", "svgf", "none", "noisy", "oidn"):
        with pytest.raises(ValueError, match="a name the front-ends use"):
            atrous.register_method(name, toy_plugin.toy_cascade)
    seen = {}

    def spy(planes, out):
        seen.update({k: v is not None for k, v in planes.items()})
        out[...] = planes["color"]

    atrous.register_method("normal-only-2", spy, reads="normal")
    b = _render()
    atrous.denoise(method="normal-only-2", **b)
    assert seen["normal"] and not seen["albedo"] and not seen["position"]


def test_a_plugins_errors_name_its_file(tmp_path):
    """The toy plugin under a second name: its registration fails (the name 'toy' is taken) with
    an error naming that file; a folder is not a plugin."""
    import shutil
    import subprocess
    import sys

    from atrous_cli import toy_plugin_so

    so = toy_plugin_so()
    if so is None:
        pytest.skip("no C++ build with the toy plugin")
    copy = tmp_path / "second.so"
    shutil.copy(so, copy)
    code = ("import sys, atrous\natrous.load_plugin(sys.argv[1])\n"
            "try:\n    atrous.load_plugin(sys.argv[2])\nexcept ValueError as e:\n    print('ValueError', e)\n"
            "try:\n    atrous.load_plugin(sys.argv[3])\nexcept ValueError as e:\n    print('ValueError', e)\n")
    r = subprocess.run([sys.executable, "-c", code, so, str(copy), str(tmp_path)], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.strip().splitlines()
    assert "second.so" in lines[0] and "already a method 'toy'" in lines[0], lines
    assert "is not a file" in lines[1], lines
