"""Mitsuba 3 scenes of the corpus's TRAINING split (docs/corpus.md, "Training split"). Run by
render.py --train inside .venv-corpus:

    .venv-corpus/bin/python scripts/corpus/mitsuba_train.py --out out/corpus/train [--scenes tr_mi_00,...]

Scene tr_mi_NN is a pure function of NN (numpy Generator seeded with TRAIN_SEED_BASE + NN): a
random arrangement of spheres, boxes and wires on a textured ground, with materials drawn from
diffuse (plain, checker, fine bitmap), glass, mirror, rough metal and rough plastic, lit by sun +
sky, an area panel (sometimes in view) or a sphere lamp, seen by a random camera. None of them is
a test scene (mitsuba_render.py's STILLS): the learned filter trains on these and is measured on
those. Written in Mitsuba's own layouts (aov EXR; two scenes as separate files), like the test
corpus, so that conversion goes through the same reader (`atrous inspect --export`).
"""
import sys
from pathlib import Path

import numpy as np

from common import TRAIN, parse_train_args, merged_render_seconds, train_jobs, write_manifest  # noqa: E402
import mitsuba_render as mr  # noqa: E402  (sets the variant; its main() does not run)

T = mr.T
N_SCENES = 8
SEP = {3, 6}  # scenes written as separate files (mi_mirror_thin's layout)


def rand_material(rng, k):
    kind = rng.choice(["diffuse", "checker", "bitmap", "glass", "mirror", "metal", "metal", "plastic"])
    col = list(rng.uniform(0.05, 0.9, 3))
    if kind == "diffuse":
        return kind, mr.diffuse(col)
    if kind == "checker":
        return kind, mr.diffuse(mr.checker(col, list(rng.uniform(0.02, 0.5, 3)), float(rng.uniform(4, 40))))
    if kind == "bitmap":
        return kind, {"type": "diffuse", "reflectance": {"type": "bitmap", "bitmap": mr.fine_texture(256, seed=100 + k),
                                                          "filter_type": "bilinear",
                                                          "to_uv": T().scale([float(rng.uniform(1, 4))] * 2 + [1])}}
    if kind == "glass":
        return kind, mr.glass()
    if kind == "mirror":
        return kind, mr.mirror()
    if kind == "metal":
        m = str(rng.choice(["Au", "Cu", "Al", "Ag", "Cr"]))
        a = float(np.exp(rng.uniform(np.log(0.02), np.log(0.5))))
        return f"metal {m} {a:.3f}", mr.rough_metal(m, a)
    return kind, {"type": "roughplastic", "diffuse_reflectance": mr.rgb(col), "alpha": float(rng.uniform(0.05, 0.4))}


def scene(k):
    rng = np.random.default_rng(TRAIN["seed_base"] + k)
    notes = []
    gkind = rng.choice(["checker", "bitmap", "plain"])
    if gkind == "checker":
        gb = mr.diffuse(mr.checker(list(rng.uniform(0.3, 0.8, 3)), list(rng.uniform(0.02, 0.3, 3)),
                                   float(rng.uniform(4, 80))))
    elif gkind == "bitmap":
        gb = {"type": "diffuse", "reflectance": {"type": "bitmap", "bitmap": mr.fine_texture(512, seed=200 + k),
                                                  "filter_type": "bilinear",
                                                  "to_uv": T().scale([float(rng.uniform(1, 5))] * 2 + [1])}}
    else:
        gb = mr.diffuse(list(rng.uniform(0.2, 0.7, 3)))
    o = {"ground": mr.floor(20, gb)}
    notes.append(f"ground {gkind}")
    if rng.uniform() < 0.5:
        o["back"] = mr.rect(T().translate([0, 2, float(-rng.uniform(1.5, 3))]).scale([6, 2, 1]),
                            rand_material(rng, 50 + k)[1])
        notes.append("back wall")
    for i in range(int(rng.integers(3, 7))):
        kind, bsdf = rand_material(rng, 10 * k + i)
        x, z = rng.uniform(-1.4, 1.4), rng.uniform(-1.2, 1.0)
        shape = rng.choice(["sphere", "sphere", "cube", "cylinder"])
        r = float(rng.uniform(0.15, 0.5))
        if shape == "sphere":
            o[f"o{i}"] = mr.sphere([x, r, z], r, bsdf)
        elif shape == "cube":
            o[f"o{i}"] = mr.cube(T().translate([x, r, z]).rotate([0, 1, 0], float(rng.uniform(0, 90))).scale(r), bsdf)
        else:
            o[f"o{i}"] = mr.cylinder([x, 0, z], [x, 2 * r, z], r * 0.5, bsdf)
        notes.append(f"{shape} {kind}")
    if rng.uniform() < 0.4:  # thin wires (a few px or less at 128x128)
        wb = mr.rough_metal("Al", 0.2) if rng.uniform() < 0.5 else mr.diffuse([0.9, 0.9, 0.85])
        zf = float(rng.uniform(0.3, 1.2))
        for i in range(int(rng.integers(5, 12))):
            x = -1.0 + 0.2 * i
            o[f"w{i:02d}"] = mr.cylinder([x, 0, zf], [x, float(rng.uniform(0.5, 1.2)), zf], 0.008, wb)
        notes.append("wires")
    light = rng.choice(["sunsky", "panel", "lamp"])
    if light == "sunsky":
        el, az = np.radians(rng.uniform(15, 70)), rng.uniform(0, 2 * np.pi)
        o["sky"] = mr.sunsky([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])
    elif light == "panel":
        h = float(rng.uniform(1.5, 2.8))
        tilt = float(rng.uniform(40, 90))
        o["panel"] = mr.rect(T().translate([float(rng.uniform(-1, 1)), h, float(rng.uniform(-2, 0.5))])
                             .rotate([1, 0, 0], tilt).scale([float(rng.uniform(0.3, 1.0)), float(rng.uniform(0.2, 0.6)), 1]),
                             mr.diffuse([0, 0, 0]), mr.area(list(rng.uniform(5, 15) * rng.uniform(0.8, 1.0, 3))))
        o["env"] = {"type": "constant", "radiance": mr.rgb(list(rng.uniform(0.0, 0.15, 3)))}
    else:
        o["lamp"] = mr.sphere([float(rng.uniform(-1.5, 1.5)), float(rng.uniform(1.5, 3)), float(rng.uniform(-1, 2))],
                              float(rng.uniform(0.1, 0.3)), mr.diffuse([0, 0, 0]),
                              mr.area(list(rng.uniform(20, 60) * rng.uniform(0.8, 1.0, 3))))
        o["env"] = {"type": "constant", "radiance": mr.rgb(list(rng.uniform(0.0, 0.1, 3)))}
    notes.append(f"light {light}")
    ang = rng.uniform(-0.8, 0.8)
    dist, height = rng.uniform(2.6, 4.2), rng.uniform(0.5, 2.2)
    cam = dict(origin=[float(dist * np.sin(ang)), float(height), float(dist * np.cos(ang))],
               target=[float(rng.uniform(-0.3, 0.3)), float(rng.uniform(0.2, 0.6)), 0.0], up=[0, 1, 0],
               fov=float(rng.uniform(35, 60)))
    rfilter = "box" if rng.uniform() < 0.5 else "gaussian"
    return o, cam, rfilter, ", ".join(notes)


def main():
    root, names = parse_train_args("mitsuba", "tr_mi", N_SCENES)
    res = TRAIN["res"]
    for name in names:
        k = int(name[-2:])
        objects, cam, rfilter, what = scene(k)
        layout = "separate" if k in SEP else "aov"
        d = root / name
        files, times = mr.render_still(name, layout, objects, cam, res, rfilter, train_jobs(k), d)
        man_path = d / "manifest.json"
        write_manifest(man_path, {
            "scene": name, "split": "train", "renderer": "mitsuba", "version": mr.mi.__version__, "variant": mr.VARIANT,
            "description": what, "resolution": [res, res], "pixel_filter": rfilter, "layout": layout,
            "integrator": f"aov(path max_depth={mr.MAX_DEPTH})" if layout == "aov" else f"path max_depth={mr.MAX_DEPTH} + aov",
            "aovs": mr.AOVS, "files": files, "reference": f"ref{TRAIN['ref_spp']:04d}",
            "render_seconds": merged_render_seconds(man_path, times), "conventions": mr.CONVENTIONS, "camera": cam,
        })


if __name__ == "__main__":
    main()
