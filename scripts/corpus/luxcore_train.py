#!/usr/bin/env python3
"""LuxCoreRender scenes of the corpus's TRAINING split (docs/corpus.md, "Training split"): the third
renderer's share, beside mitsuba_train.py and cycles_train.py.

    /tmp/luxvenv/bin/python scripts/corpus/luxcore_train.py --out out/corpus/train [--scenes tr_lx_00,...]

(the venv of luxcore_stills.py: `python -m venv /tmp/luxvenv && /tmp/luxvenv/bin/pip install
pyluxcore numpy`.) Scene tr_lx_NN is a pure function of NN (numpy Generator seeded with
TRAIN["seed_base"] + 500 + NN, a stream of its own): a random arrangement of spheres and boxes on a
ground, sometimes a back wall and a row of thin posts, materials drawn from LuxCore's matte
(plain, 3D checks at several scales, bricks), glossy2 coats, glass, rough glass, mirror and rough
metal2 presets, lit by sun + sky, an area panel (sometimes in view) or a sphere lamp, seen by a
random camera, with LuxCore's Blackman-Harris pixel filter or a Gaussian or box one. None is a
test scene: the four test stills (luxcore_stills.py: the glass and coat spheres, the pergola,
the gold and copper, the window-lit room) are never rendered here, and no room or pergola is drawn.
Written in LuxCore's own layout (a folder of RGB.exr, ALBEDO.exr, ... per render, as the test
stills), so train_export.py reads it through the same reader as `atrous denoise --in DIR`.
About a minute per scene at 128² on 2 cores (the 1024-spp reference).
"""
import os
import time

import numpy as np

from common import TRAIN, merged_render_seconds, parse_train_args, train_jobs, write_manifest  # noqa: E402
import luxcore_stills as ls  # noqa: E402  (pyluxcore.Init; its main() does not run)

N_SCENES = 16
PRESETS = ("gold", "copper", "silver", "aluminium")


def sphere(cx, cy, cz, r, n):
    """luxcore_stills.sphere with its triangles turned outward (its winding faces in: a lamp's
    one-sided emission would face the inside, and glass would be entered the wrong way)."""
    v, f = ls.sphere(cx, cy, cz, r, n)
    return v, [(a, c, b) for a, b, c in f]


def col(rng, lo=0.05, hi=0.85):
    return [float(x) for x in rng.uniform(lo, hi, 3)]


def material(rng, tex, key):
    """(kind, LuxCore material) for a random surface; textures it needs go into `tex`."""
    kind = str(rng.choice(["matte", "checks", "bricks", "coat", "glass", "roughglass", "mirror", "metal", "metal"]))
    if kind == "matte":
        return kind, ("matte", {"kd": col(rng)})
    if kind == "checks":
        s = float(np.exp(rng.uniform(np.log(2), np.log(40))))
        tex[key] = ("checkerboard3d", {"texture1": col(rng, 0.3, 0.9), "texture2": col(rng, 0.02, 0.3),
                                       "mapping.type": "globalmapping3d",
                                       "mapping.transformation": [s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, 0, 0, 0, 1]})
        return f"checks {s:.0f}", ("matte", {"kd": key})
    if kind == "bricks":
        s = float(rng.uniform(2, 8))
        tex[key] = ("brick", {"brickbond": "running", "brickwidth": 0.3, "brickheight": 0.1, "brickdepth": 0.15,
                              "mortarsize": 0.02, "bricktex": col(rng, 0.3, 0.8), "mortartex": col(rng, 0.6, 0.9),
                              "brickmodtex": 1.0, "mapping.type": "globalmapping3d",
                              "mapping.transformation": [s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, 0, 0, 0, 1]})
        return f"bricks {s:.1f}", ("matte", {"kd": key})
    if kind == "coat":
        r = float(np.exp(rng.uniform(np.log(0.01), np.log(0.3))))
        return f"coat {r:.3f}", ("glossy2", {"kd": col(rng), "ks": [0.05, 0.05, 0.05], "uroughness": r, "vroughness": r})
    if kind == "glass":
        return kind, ("glass", {"kr": [1, 1, 1], "kt": col(rng, 0.7, 1.0), "interiorior": 1.5})
    if kind == "roughglass":
        r = float(rng.uniform(0.02, 0.2))
        return f"roughglass {r:.2f}", ("roughglass", {"kr": [1, 1, 1], "kt": col(rng, 0.7, 1.0), "interiorior": 1.5,
                                                      "uroughness": r, "vroughness": r})
    if kind == "mirror":
        return kind, ("mirror", {"kr": col(rng, 0.7, 0.95)})
    p = str(rng.choice(PRESETS))
    r = float(np.exp(rng.uniform(np.log(0.02), np.log(0.4))))
    return f"metal {p} {r:.3f}", ("metal2", {"preset": p, "uroughness": r, "vroughness": r})


def build(k):
    """The scene-building function luxcore_stills.render() takes, and a description."""
    rng = np.random.default_rng(TRAIN["seed_base"] + 500 + k)
    mats, shapes, lights, tex, notes = {}, {}, {}, {}, []
    gk, mats["ground"] = material(rng, tex, "t_ground")
    while gk.startswith(("glass", "roughglass", "mirror")):  # a ground one can stand on
        gk, mats["ground"] = material(rng, tex, "t_ground")
    shapes["ground"] = (ls.box(0, -0.05, 0, 8, 0.05, 8), "ground")
    notes.append(f"ground {gk}")
    if rng.uniform() < 0.5:
        wk, mats["wall"] = material(rng, tex, "t_wall")
        shapes["wall"] = (ls.box(0, 2, float(-rng.uniform(1.5, 3)), 6, 2, 0.1), "wall")
        notes.append(f"back wall {wk}")
    for i in range(int(rng.integers(3, 7))):
        kind, mats[f"m{i}"] = material(rng, tex, f"t{i}")
        x, z, r = float(rng.uniform(-1.4, 1.4)), float(rng.uniform(-1.2, 1.0)), float(rng.uniform(0.15, 0.5))
        if rng.uniform() < 0.6:
            shapes[f"o{i}"] = (sphere(x, r, z, r, 24), f"m{i}")
            notes.append(f"sphere {kind}")
        else:
            shapes[f"o{i}"] = (ls.box(x, r, z, r, r * float(rng.uniform(0.5, 1.5)), r), f"m{i}")
            notes.append(f"box {kind}")
    if rng.uniform() < 0.35:  # a row of thin posts (1-3 px at 128²): thin geometry and its shadows
        mats["post"] = ("matte", {"kd": col(rng, 0.1, 0.8)})
        zf, n = float(rng.uniform(0.3, 1.2)), int(rng.integers(6, 14))
        for i in range(n):
            shapes[f"post{i:02d}"] = (ls.box(-1.2 + 2.4 * i / (n - 1), 0.6, zf, 0.012, 0.6, 0.012), "post")
        notes.append("posts")
    light = str(rng.choice(["sunsky", "panel", "lamp"]))
    if light == "sunsky":
        el, az = np.radians(rng.uniform(15, 70)), rng.uniform(0, 2 * np.pi)
        d = [float(np.cos(el) * np.sin(az)), float(np.sin(el)), float(np.cos(el) * np.cos(az))]
        g = float(1e-4 * np.exp(rng.uniform(np.log(0.5), np.log(3))))
        t = float(rng.uniform(2, 5))
        lights["sun"] = ("sun", {"dir": d, "turbidity": t, "gain": [g, g, g]})
        lights["sky"] = ("sky2", {"dir": d, "turbidity": t, "gain": [g, g, g]})
    else:
        e = float(rng.uniform(5, 15) if light == "panel" else rng.uniform(20, 60))
        mats["light"] = ("matte", {"kd": [0, 0, 0], "emission": [e * float(c) for c in rng.uniform(0.8, 1.0, 3)]})
        if light == "panel":
            shapes["light"] = (ls.box(float(rng.uniform(-1, 1)), float(rng.uniform(1.5, 2.8)),
                                      float(rng.uniform(-2, 0.5)), float(rng.uniform(0.3, 1.0)), 0.02,
                                      float(rng.uniform(0.2, 0.6))), "light")
        else:
            shapes["light"] = (sphere(float(rng.uniform(-1.5, 1.5)), float(rng.uniform(1.5, 3)),
                                         float(rng.uniform(-1, 2)), float(rng.uniform(0.1, 0.3)), 16), "light")
        lights["env"] = ("constantinfinite", {"color": col(rng, 0.0, 0.15)})
    notes.append(f"light {light}")
    ang = rng.uniform(-0.8, 0.8)
    dist, height = rng.uniform(2.6, 4.2), rng.uniform(0.5, 2.2)
    cam = ((float(dist * np.sin(ang)), float(height), float(dist * np.cos(ang))),
           (float(rng.uniform(-0.3, 0.3)), float(rng.uniform(0.2, 0.6)), 0.0), float(rng.uniform(35, 60)))
    pf = str(rng.choice(["BLACKMANHARRIS", "BLACKMANHARRIS", "GAUSSIAN", "BOX"]))
    return (lambda: (mats, shapes, lights, cam, tex)), pf, ", ".join(notes)


def main():
    root, names = parse_train_args("luxcore", "tr_lx", N_SCENES)
    res = TRAIN["res"]
    for name in names:
        k = int(name[-2:])
        scene, pf, what = build(k)
        d = root / name
        d.mkdir(parents=True, exist_ok=True)
        man_path = d / "manifest.json"
        files, times = {}, {}
        for spp, seed, stem in train_jobs(k):
            files[stem] = {"spp": spp, "seed": seed, "folder": stem, "files": [t + ".exr" for t in ls.OUTPUTS]}
            if not (d / stem / "RGB.exr").exists():
                times[stem] = ls.render(scene, str(d / stem), spp, seed, res, pf)
                print(f"{time.strftime('%H:%M:%S')} luxcore {name} {stem}: {times[stem]:.1f} s ({what})", flush=True)
        write_manifest(man_path, {
            "scene": name, "split": "train", "renderer": "luxcore", "version": ls.pyluxcore.Version(),
            "description": what, "resolution": [res, res], "pixel_filter": pf.lower(),
            "integrator": "PATHCPU depth 8", "layout": "luxcore", "files": files,
            "reference": f"ref{TRAIN['ref_spp']:04d}", "render_seconds": merged_render_seconds(man_path, times)})
    os._exit(0)  # pyluxcore's log callback crashes at interpreter shutdown


if __name__ == "__main__":
    main()
