"""atrous.farm on a real Ray cluster: a head and two worker nodes on 127.0.0.1, started by this
module with `ray start` (farm_cluster.py) and shared by its tests."""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import atrous
from atrous.eval import score
from atrous.farm.dataset import random_scene

from farm_cluster import LocalCluster
from atrous_cli import atrous_cli, toy_plugin_so


@pytest.fixture(scope="module")
def cluster():
    c = LocalCluster(workers=2, cpus_per_worker=1)
    yield c
    c.stop()


def _alive(pid: int) -> bool:
    """Whether the process still runs (a zombie waiting for its parent counts as dead)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False


def farm(args, env=None, **kw):
    return subprocess.run([sys.executable, "-m", "atrous.farm", *args], capture_output=True, text=True,
                          env=env, timeout=300, **kw)


def manifest(out):
    return json.loads((Path(out) / "manifest.json").read_text())


def files_of(d: Path):
    return sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())


def no_partial_left(out: Path):
    assert not (out / ".partial").exists()
    assert not [p for p in out.rglob("*") if ".tmp" in p.name or p.name.endswith(".partial")]


def test_twelve_renders_equal_the_cli_bit_for_bit(cluster, tmp_path):
    cli = atrous_cli()
    if cli is None:
        pytest.skip("no atrous CLI (set ATROUS_CLI or build build/atrous)")
    out = tmp_path / "farm"
    r = farm(["render", "--scenes", "cornell,cornell-point,cornell-spheres", "--spp", "1,2,4,8", "--width", "24",
              "--height", "16", "--seeds", "7", "--denoise", "sure", "--address", cluster.address, "--out", str(out)],
             env=cluster.env)
    assert r.returncode == 0, r.stderr
    m = manifest(out)
    assert len(m["items"]) == 12 and all(e["status"] == "done" for e in m["items"])
    assert m["runs"][-1]["nodes"] == 3 and m["runs"][-1]["cluster_cpus"] == 2
    assert "12 done" in r.stdout
    for e in m["items"]:
        p = e["params"]
        ref = tmp_path / "cli" / e["id"]
        c = subprocess.run([cli, "render", "--scene", p["scene"], "--spp", str(p["spp"]), "--width", "24",
                            "--height", "16", "--seed", "7", "--denoise", "sure", "--device", "cpu", "--quiet",
                            "--out", str(ref)], capture_output=True, text=True, timeout=120)
        assert c.returncode == 0, c.stderr
        got = out / e["id"]
        assert files_of(got) == files_of(ref), e["id"]
        assert "denoised_sure.exr" in files_of(got)
        for f in files_of(ref):
            assert (got / f).read_bytes() == (ref / f).read_bytes(), f"{e['id']}/{f}"
    no_partial_left(out)


def test_frames_and_svgf_equal_the_cli(cluster, tmp_path):
    cli = atrous_cli()
    if cli is None:
        pytest.skip("no atrous CLI (set ATROUS_CLI or build build/atrous)")
    out, seq = tmp_path / "farm", tmp_path / "cli"
    r = farm(["render", "--scenes", "cornell-moving", "--spp", "1", "--frames", "3", "--reference-spp", "4",
              "--width", "24", "--height", "16", "--address", cluster.address, "--out", str(out), "--quiet"],
             env=cluster.env)
    assert r.returncode == 0, r.stderr
    assert len(manifest(out)["items"]) == 3
    c = subprocess.run([cli, "render", "--scene", "cornell-moving", "--spp", "1", "--frames", "3", "--reference-spp",
                        "4", "--width", "24", "--height", "16", "--quiet", "--out", str(seq)],
                       capture_output=True, text=True, timeout=120)
    assert c.returncode == 0, c.stderr
    got = out / "cornell-moving_spp1"
    assert files_of(got) == files_of(seq) and "frame_0002/reference.exr" in files_of(seq)
    for f in files_of(seq):
        assert (got / f).read_bytes() == (seq / f).read_bytes(), f
    dn = tmp_path / "svgf"
    r = farm(["denoise", "--in", str(got), "--method", "svgf", "--address", cluster.address, "--out", str(dn),
              "--quiet"], env=cluster.env)
    assert r.returncode == 0, r.stderr
    c = subprocess.run([cli, "denoise", "--sequence", str(seq), "--method", "svgf", "--device", "cpu",
                        "--out", str(tmp_path / "cli-svgf")], capture_output=True, text=True, timeout=120)
    assert c.returncode == 0, c.stderr
    for f in range(3):
        name = f"frame_{f:04d}.exr"
        assert (dn / "cornell-moving_spp1" / name).read_bytes() == (tmp_path / "cli-svgf" / name).read_bytes()
    # The temporal method: one item per frame, each reading its neighbours; what the CLI writes.
    dt = tmp_path / "temporal"
    r = farm(["denoise", "--in", str(got), "--method", "temporal", "--param", "temporal_radius=1", "--param",
              "spatial=eaw", "--address", cluster.address, "--out", str(dt), "--quiet"], env=cluster.env)
    assert r.returncode == 0, r.stderr
    assert len(manifest(dt)["items"]) == 3
    c = subprocess.run([cli, "denoise", "--sequence", str(seq), "--temporal-radius", "1", "--spatial", "eaw",
                        "--device", "cpu", "--out", str(tmp_path / "cli-temporal")], capture_output=True, text=True,
                       timeout=120)
    assert c.returncode == 0, c.stderr
    for f in range(3):
        name = f"frame_{f:04d}.exr"
        assert (dt / "cornell-moving_spp1" / name).read_bytes() == (tmp_path / "cli-temporal" / name).read_bytes()
    # A plugin's sequence method (tests/toy_sequence_method.cpp in the C++ toy plugin): loaded in
    # every worker, one item per sequence (it carries history), what the CLI with the plugin writes.
    so = toy_plugin_so()
    if so is not None:
        dq = tmp_path / "toyseq"
        r = farm(["denoise", "--in", str(got), "--method", "toyseq", "--param", "alpha=0.5", "--plugin", so,
                  "--address", cluster.address, "--out", str(dq), "--quiet"], env=cluster.env)
        assert r.returncode == 0, r.stderr
        assert len(manifest(dq)["items"]) == 1
        c = subprocess.run([cli, "--plugin", so, "denoise", "--sequence", str(seq), "--method", "toyseq",
                            "--toyseq-alpha", "0.5", "--device", "cpu", "--out", str(tmp_path / "cli-toyseq")],
                           capture_output=True, text=True, timeout=120)
        assert c.returncode == 0, c.stderr
        for f in range(3):
            name = f"frame_{f:04d}.exr"
            assert (dq / "cornell-moving_spp1" / name).read_bytes() == (tmp_path / "cli-toyseq" / name).read_bytes()


def test_a_killed_worker_costs_a_retry_not_the_job(cluster, tmp_path):
    out = tmp_path / "farm"
    args = ["render", "--scenes", "cornell", "--spp", "512", "--seeds", "1,2,3,4,5,6", "--width", "64", "--height",
            "64", "--address", cluster.address, "--out", str(out), "--quiet"]
    job = subprocess.Popen([sys.executable, "-m", "atrous.farm", *args], env=cluster.env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    killed = hit = None
    misses = 0
    t0 = time.time()
    while hit is None and misses < 4 and time.time() - t0 < 120 and job.poll() is None:
        # An item in progress: its staging directory OUT/.partial/<item>.<pid>.<random>, made by the worker
        # process itself after the task has reported its start to the tracker (tasks.py), so a kill from
        # then on is counted as an attempt (a fixed sleep was not enough on a loaded machine). Ray reuses a
        # worker for several items, and the item may finish between the look and the kill: the kill hit
        # it only if its staging directory is still there once the worker is dead.
        staged = sorted((out / ".partial").glob("*.*.*"))  # none while the directory does not exist
        if not staged:
            time.sleep(0.01)
            continue
        item, pid, _ = staged[0].name.rsplit(".", 2)
        try:
            os.kill(int(pid), signal.SIGKILL)
        except ProcessLookupError:
            continue
        killed = int(pid)
        t1 = time.time()
        while _alive(killed) and time.time() - t1 < 10:
            time.sleep(0.01)
        if staged[0].exists():
            hit = item
        else:
            misses += 1
    stdout, stderr = job.communicate(timeout=240)
    assert killed is not None, "no worker was seen running an item"
    assert hit is not None, ("no kill landed inside an item", misses)
    assert job.returncode == 0, stderr
    m = manifest(out)
    ids = [e["id"] for e in m["items"]]
    assert sorted(ids) == sorted(f"cornell_spp512_seed{k}" for k in range(1, 7))  # each once
    assert all(e["status"] == "done" for e in m["items"])
    by_id = {e["id"]: e for e in m["items"]}
    assert by_id[hit]["attempts"] >= 2 and by_id[hit]["pid"] != killed, (
        "the item the kill hit should have been started again and finished by a live worker", hit, killed,
        [(e["id"], e["attempts"], e["pid"]) for e in m["items"]])
    no_partial_left(out)
    names = ["albedo.exr", "color.exr", "color.png", "depth.exr", "emission.exr", "ids.exr", "normal.exr",
             "position.exr", "variance.exr"]
    for e in m["items"]:
        assert files_of(out / e["id"]) == names
    # The retried item's pixels are the ones a single process renders.
    e = by_id[hit]
    want = atrous.render("cornell", width=64, height=64, spp=512, seed=e["params"]["seed"])["color"]
    np.testing.assert_array_equal(atrous.read_image(out / e["id"] / "color.exr"), want)


def test_a_resumed_job_skips_the_items_done(cluster, tmp_path, monkeypatch):
    import atrous.farm

    for k, v in cluster.env.items():
        if k.startswith("RAY_"):
            monkeypatch.setenv(k, v)
    out = tmp_path / "farm"
    kw = dict(width=16, height=16, address=cluster.address, progress=False)
    first = atrous.farm.render(out, ["cornell", "cornell-point"], [2, 4], **kw)
    assert first.ok and len(first.done) == 4 and not first.skipped
    stamp = {p: p.stat().st_mtime_ns for p in out.rglob("*.exr")}
    # An interrupted run: the driver died after cornell_spp4 was submitted, not yet done, and a
    # killed attempt left its staging directory.
    m = manifest(out)
    for e in m["items"]:
        if e["id"] == "cornell_spp4":
            e["status"] = "pending"
    (out / "manifest.json").write_text(json.dumps(m))
    shutil.rmtree(out / "cornell_spp4")
    (out / ".partial" / "cornell_spp4.1.deadbeef").mkdir(parents=True)
    (out / ".partial" / "cornell_spp4.1.deadbeef" / "color.exr").write_bytes(b"half")
    again = atrous.farm.render(out, ["cornell", "cornell-point"], [2, 4, 8], **kw)
    assert again.ok
    assert sorted(again.skipped) == ["cornell-point_spp2", "cornell-point_spp4", "cornell_spp2"]
    assert sorted(set(again.done) - set(again.skipped)) == ["cornell-point_spp8", "cornell_spp4", "cornell_spp8"]
    for p, t in stamp.items():
        if "cornell_spp4" not in str(p):
            assert p.stat().st_mtime_ns == t, f"{p} was written again"
    want = atrous.render("cornell", width=16, height=16, spp=4, seed=1)["color"]
    np.testing.assert_array_equal(atrous.read_image(out / "cornell_spp4" / "color.exr"), want)
    no_partial_left(out)
    m = manifest(out)
    assert len(m["runs"]) == 2 and m["runs"][1]["skipped"] == 3
    # A third run has nothing to do and does not start Ray at all.
    third = atrous.farm.render(out, ["cornell", "cornell-point"], [2, 4, 8], **kw)
    assert len(third.skipped) == 6 and "nodes" not in third.run


def test_a_bad_scene_file_fails_its_item_only(cluster, tmp_path):
    bad = tmp_path / "broken.json"
    bad.write_text('{"camera": {"position": [0, 1, 5], "lookAt": [0, 1, 0]}, "objects": [{"type": "sphere", ')
    out = tmp_path / "farm"
    r = farm(["render", "--scenes", f"cornell,{bad}", "--spp", "2,4", "--width", "16", "--height", "16",
              "--address", cluster.address, "--out", str(out)], env=cluster.env)
    assert r.returncode == 2, r.stderr
    err = [ln for ln in r.stderr.splitlines() if ln.startswith("atrous-farm:")]
    assert len(err) == 2 and all("broken.json" in ln for ln in err), r.stderr
    m = {e["id"]: e for e in manifest(out)["items"]}
    assert m["cornell_spp2"]["status"] == m["cornell_spp4"]["status"] == "done"
    for k in ("broken_spp2", "broken_spp4"):
        assert m[k]["status"] == "failed" and m[k]["error_kind"] == "input"
        assert str(bad) in m[k]["error"]
        assert not (out / k).exists()
    assert m["broken_spp2"]["attempts"] == 1  # bad input is not retried
    assert len(files_of(out / "cornell_spp2")) == 9
    no_partial_left(out)
    # In an evaluation the broken scene's reference fails, and with it that scene's items only.
    ev = tmp_path / "eval"
    r = farm(["evaluate", "--scenes", f"cornell,{bad}", "--spp", "2", "--methods", "noisy,eaw", "--width", "16",
              "--height", "16", "--ref-spp", "16", "--runs", "1", "--address", cluster.address, "--out", str(ev),
              "--quiet"], env=cluster.env)
    assert r.returncode == 2, r.stderr
    m = {e["id"]: e for e in manifest(ev)["items"]}
    assert [k for k, e in m.items() if e["status"] == "done"] == ["references/cornell", "cornell/spp2/noisy",
                                                                   "cornell/spp2/eaw"]
    assert str(bad) in m["references/broken"]["error"]
    assert m["broken/spp2/eaw"]["error"].startswith("needs references/broken, which failed: ")
    res = json.loads((ev / "results.json").read_text())
    assert [(x["scene"], x["method"]) for x in res["results"]] == [("cornell", "noisy"), ("cornell", "eaw")]
    assert sorted(f["id"] for f in res["failed"]) == ["broken/spp2/eaw", "broken/spp2/noisy", "references/broken"]


def test_evaluate_sweep_dataset_and_denoise_jobs(cluster, tmp_path):
    env = cluster.env
    ev = tmp_path / "eval"
    r = farm(["evaluate", "--scenes", "cornell,cornell-point", "--spp", "4", "--methods", "noisy,sure,oidn",
              "--width", "24", "--height", "24", "--ref-spp", "64", "--runs", "1", "--address", cluster.address,
              "--out", str(ev), "--quiet"], env=env)
    assert r.returncode == 0, r.stderr
    res = json.loads((ev / "results.json").read_text())
    rows = {(x["scene"], x["method"]): x for x in res["results"]}
    assert sorted(rows) == sorted((s, m) for s in ("cornell", "cornell-point") for m in ("noisy", "sure", "oidn"))
    # The same measurement as atrous.eval's, in one process: same seeds, same numbers.
    ref = atrous.render("cornell-point", width=24, height=24, spp=64, seed=1000003)["color"]
    b = atrous.render("cornell-point", width=24, height=24, spp=4, seed=1)
    assert rows[("cornell-point", "noisy")]["relmse"] == score(b["color"], ref)["relmse"]
    sure = atrous.denoise(b["color"], albedo=b["albedo"], normal=b["normal"], position=b["position"],
                          depth=b["depth"], variance=b["variance"], ids=b["ids"], emission=b["emission"],
                          method="sure")
    assert rows[("cornell-point", "sure")]["relmse"] == score(sure, ref)["relmse"]
    for s in ("cornell", "cornell-point"):
        assert rows[(s, "oidn")]["relmse"] < rows[(s, "noisy")]["relmse"]
    assert "| cornell | 4 | sure |" in (ev / "results.md").read_text()

    sw = tmp_path / "sweep"
    r = farm(["sweep", "--method", "eaw", "--grid", "levels=1,5", "--scenes", "cornell", "--spp", "2",
              "--width", "24", "--height", "24", "--ref-spp", "64", "--address", cluster.address,
              "--out", str(sw), "--quiet"], env=env)
    assert r.returncode == 0, r.stderr
    res = json.loads((sw / "results.json").read_text())
    by = {x["params"]["levels"]: x["relmse"] for x in res["results"]}
    assert sorted(by) == [1, 5] and by[1] != by[5]
    assert res["best_overall"]["params"] == {"levels": min(by, key=by.get)}

    ds, spec = tmp_path / "ds", tmp_path / "spec.json"
    spec.write_text(json.dumps({"count": 2, "seed": 9, "width": 16, "height": 12, "spp": [1, 2],
                                "reference_spp": 8}))
    r = farm(["render", "--dataset", str(spec), "--address", cluster.address, "--out", str(ds), "--quiet"], env=env)
    assert r.returncode == 0, r.stderr
    for i in range(2):
        d = ds / f"scene_{i:06d}"
        assert json.loads((d / "scene.json").read_text()) == random_scene(9, i)
        assert sorted(p.name for p in d.iterdir()) == ["reference.exr", "scene.json", "spp_1", "spp_2"]
        got = atrous.read_image(d / "spp_2" / "color.exr")
        np.testing.assert_array_equal(got, atrous.render(str(d / "scene.json"), width=16, height=12, spp=2,
                                                         seed=9 + i)["color"])
    assert random_scene(9, 0) != random_scene(9, 1)

    # Training targets without a reference render (issue 47): OIDN high on a 64-spp render, a true
    # reference for every second scene only; the target is far closer to it than the 1-spp input.
    tg, tspec = tmp_path / "tg", tmp_path / "tspec.json"
    tspec.write_text(json.dumps({"count": 2, "seed": 9, "width": 32, "height": 32, "spp": [1],
                                 "reference_spp": 256, "target": "oidn", "target_spp": 64, "reference_every": 2}))
    r = farm(["render", "--dataset", str(tspec), "--address", cluster.address, "--out", str(tg), "--quiet"], env=env)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tg / "scene_000000").iterdir()) == ["reference.exr", "scene.json", "spp_1",
                                                                       "target.exr", "target.json",
                                                                       "target_input.exr"]
    assert sorted(p.name for p in (tg / "scene_000001").iterdir()) == ["scene.json", "spp_1", "target.exr",
                                                                       "target.json", "target_input.exr"]
    meta = json.loads((tg / "scene_000001" / "target.json").read_text())
    assert meta["kind"] == "oidn-high" and meta["spp"] == 64
    from atrous.farm.target_error import target_error
    err = target_error(tg)
    assert [x["scene"] for x in err["scenes"]] == ["scene_000000"]
    assert err["geomean_relmse"]["target"] < 0.25 * err["geomean_relmse"]["spp_1"]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"count": 1, "target": "oidn-high"}))
    r = farm(["render", "--dataset", str(bad), "--out", str(tmp_path / "y")], env=env)
    assert r.returncode == 2 and "target must be one of reference, oidn" in r.stderr

    dn = tmp_path / "dn"
    r = farm(["denoise", "--in", str(ds), "--method", "eaw", "--param", "levels=3",
              "--address", cluster.address, "--out", str(dn), "--quiet"], env=env)
    assert r.returncode == 0, r.stderr
    cli = atrous_cli()
    if cli is not None:
        c = subprocess.run([cli, "denoise", "--in", str(ds / "scene_000000" / "spp_2"), "--method", "eaw",
                            "--levels", "3", "--device", "cpu", "--out", str(tmp_path / "cli.exr")],
                           capture_output=True, text=True, timeout=60)
        assert c.returncode == 0, c.stderr
        got = (dn / "scene_000000" / "spp_2" / "denoised_eaw.exr").read_bytes()
        assert got == (tmp_path / "cli.exr").read_bytes()
    want = [f"scene_00000{i}/spp_{n}/denoised_eaw.{ext}" for i in (0, 1) for n in (1, 2) for ext in ("exr", "png")]
    assert files_of(dn) == [".farm.lock", "manifest.json"] + want

    # A method a plugin registers (tests/python/toy_plugin.py, atrous.register_method): the driver
    # and every worker load it, and the workers' output is the library's in this process.
    tn = tmp_path / "toy"
    plugin = Path(__file__).with_name("toy_plugin.py")
    r = farm(["denoise", "--in", str(ds / "scene_000000" / "spp_2"), "--method", "pytoy", "--plugin", str(plugin),
              "--address", cluster.address, "--out", str(tn), "--quiet"], env=env)
    assert r.returncode == 0, r.stderr
    import toy_plugin  # noqa: F401 (registers toy here too)
    from atrous.farm.tasks import denoise_buffers, read_buffers

    want_toy = denoise_buffers(read_buffers(ds / "scene_000000" / "spp_2"), "pytoy", {}, "cpu")
    np.testing.assert_array_equal(atrous.read_image(tn / "spp_2" / "denoised_pytoy.exr"), want_toy)
    assert manifest(tn)["spec"]["plugins"] == [str(plugin.resolve())]
    # The C++ toy (tests/toy_method.cpp) as a plugin library: the same bytes as the CLI with it.
    so = toy_plugin_so()
    if so is not None and cli is not None:
        cn = tmp_path / "toy_cpp"
        r = farm(["denoise", "--in", str(ds / "scene_000000" / "spp_2"), "--method", "toy", "--plugin", so,
                  "--address", cluster.address, "--out", str(cn), "--quiet"], env=env)
        assert r.returncode == 0, r.stderr
        c = subprocess.run([cli, "--plugin", so, "denoise", "--in", str(ds / "scene_000000" / "spp_2"), "--method",
                            "toy", "--device", "cpu", "--out", str(tmp_path / "cli_toy.exr")],
                           capture_output=True, text=True, timeout=60)
        assert c.returncode == 0, c.stderr
        assert (cn / "spp_2" / "denoised_toy.exr").read_bytes() == (tmp_path / "cli_toy.exr").read_bytes()


@pytest.mark.parametrize("args,needle", [
    (["render", "--scenes", "no-such-scene", "--spp", "2"], "no-such-scene"),
    (["render", "--scenes", "cornell", "--spp", "2,x"], "--spp"),
    (["render", "--scenes", "cornell", "--width", "0"], "width"),
    (["render", "--scenes", "cornell", "--address", "nowhere"], "--address"),
    (["render", "--scenes", "cornell", "--cpus-per-task", "0"], "--cpus-per-task"),
    (["render", "--scenes", "cornell", "--address", "127.0.0.1:1"], "no Ray head answers"),
    (["render", "--dataset", "SPEC"], "SPEC"),
    (["denoise", "--in", "IN", "--method", "bilateral"], "bilateral"),
    (["denoise", "--in", "IN", "--method", "pytoy", "--plugin", "no_such_plugin.py"], "no_such_plugin.py"),
    (["denoise", "--in", "IN", "--plugin", "no_such_plugin.so"], "no_such_plugin.so"),
    (["denoise", "--in", "IN", "--plugin", "no_such_module_xyz"], "no_such_module_xyz"),
    (["denoise", "--in", "IN", "--param", "sigma_colour=1"], "sigma_colour"),
    (["denoise", "--in", "IN", "--method", "temporal", "--param", "temporal_radios=1"], "radios"),
    (["denoise", "--in", "IN", "--method", "temporal", "--param", "spatial=nope"], "nope"),
    (["denoise", "--in", "IN", "--method", "temporal"], "frame sequences"),
    (["sweep", "--grid", "levels=0,3"], "levels"),
    (["evaluate", "--methods", "noisy,nlm"], "nlm"),
    (["render", "--scenes", "cornell", "--bogus"], "--bogus"),
])
def test_bad_input_is_one_line_and_exit_2_and_nothing_written(tmp_path, args, needle):
    spec = tmp_path / "spec.json"
    spec.write_text('{"count": 2, "sped": 3}')
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "color.exr").write_bytes(b"")
    args = [str(spec) if a == "SPEC" else str(tmp_path / "in") if a == "IN" else a for a in args]
    needle = str(spec) if needle == "SPEC" else needle
    out = tmp_path / "out"
    r = farm([*args, "--out", str(out)])
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("atrous-farm: error:") and needle in lines[0], r.stderr
    assert not out.exists()
