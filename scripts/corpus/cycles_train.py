"""Blender Cycles scenes of the corpus's TRAINING split (docs/corpus.md, "Training split"). Run by
render.py --train inside .venv-corpus:

    .venv-corpus/bin/python scripts/corpus/cycles_train.py --out out/corpus/train [--scenes tr_cy_00,...]

Scene tr_cy_NN is a pure function of NN (numpy Generator seeded with TRAIN_SEED_BASE + 100 + NN):
random spheres, boxes, cylinders, tori, monkeys and thin wires on a textured ground (checker,
checker x noise, bricks), materials drawn from diffuse, glass, mirror, rough metal and textured
principled, lit by sky texture + sun, an area lamp or a visible emissive panel, random camera and
pixel filter (Blackman-Harris or box). None of them is a test scene (cycles_render.py's STILLS).
Written as Blender's multilayer EXR with the test corpus's passes and settings (configure()).
"""
import math
import sys
from pathlib import Path

import numpy as np

from common import TRAIN, parse_train_args, done, exr_channels, log, merged_render_seconds, train_jobs, write_manifest  # noqa: E402
import cycles_render as cr  # noqa: E402  (its main() does not run)

bpy = cr.bpy
Vector = cr.Vector
N_SCENES = 8


def rand_material(rng, name, index):
    kind = str(rng.choice(["diffuse", "checker", "detail", "brick", "glass", "mirror", "metal", "metal"]))
    col = tuple(float(c) for c in rng.uniform(0.05, 0.9, 3))
    if kind == "diffuse":
        return kind, cr.material(name, "diffuse", color=col, rough=float(rng.uniform(0.2, 1)), index=index)
    if kind == "checker":
        return kind, cr.material(name, "diffuse", tex=cr.tex_checker(col, tuple(float(c) for c in rng.uniform(0, 0.4, 3)),
                                                                    float(rng.uniform(4, 50))), index=index)
    if kind == "detail":
        return kind, cr.material(name, "diffuse", tex=cr.tex_detail(float(rng.uniform(10, 100)), float(rng.uniform(5, 40)),
                                                                   c1=col), index=index)
    if kind == "brick":
        return kind, cr.material(name, "diffuse", tex=cr.tex_brick(float(rng.uniform(4, 16))), index=index)
    if kind == "glass":
        return kind, cr.material(name, "glass", color=(1, 1, 1), rough=float(rng.choice([0.0, 0.0, 0.1])), index=index)
    if kind == "mirror":
        return kind, cr.material(name, "metal", color=(0.97, 0.97, 0.97), rough=0.0, index=index)
    r = float(np.exp(rng.uniform(np.log(0.03), np.log(0.5))))
    return f"metal {r:.3f}", cr.material(name, "metal", color=col, rough=r, index=index)


def scene(sc, k):
    rng = np.random.default_rng(TRAIN["seed_base"] + 100 + k)
    notes = []
    gk, gm = rand_material(rng, "ground", 1)
    while gk in ("glass",):
        gk, gm = rand_material(rng, "ground", 1)
    cr.add("plane", gm, scale=(20, 20, 1))
    notes.append(f"ground {gk}")
    if rng.uniform() < 0.4:
        bk, bm = rand_material(rng, "back", 2)
        cr.add("plane", bm, loc=(0, float(rng.uniform(1.5, 3)), 1.5), rot=(math.pi / 2, 0, 0), scale=(5, 1.5, 1))
        notes.append(f"back wall {bk}")
    for i in range(int(rng.integers(3, 7))):
        kind, m = rand_material(rng, f"m{i}", 3 + i)
        x, y = float(rng.uniform(-1.4, 1.4)), float(rng.uniform(-1.0, 1.2))
        r = float(rng.uniform(0.15, 0.5))
        shape = str(rng.choice(["sphere", "sphere", "cube", "cylinder", "torus", "monkey"]))
        if shape == "sphere":
            cr.add("sphere", m, loc=(x, y, r), radius=r)
        elif shape == "cube":
            cr.add("cube", m, loc=(x, y, r), rot=(0, 0, float(rng.uniform(0, 1.5))), scale=(r, r, r))
        elif shape == "cylinder":
            cr.add("cylinder", m, loc=(x, y, r), radius=0.5 * r, depth=2 * r, vertices=48)
        elif shape == "torus":
            cr.add("torus", m, loc=(x, y, 0.3 * r + 0.05), rot=(float(rng.uniform(0, 1.2)), 0, float(rng.uniform(0, 3))),
                   major_radius=r, minor_radius=0.3 * r)
        else:
            cr.add("monkey", m, loc=(x, y, r), rot=(0.3, 0, float(rng.uniform(-0.8, 0.8))), scale=(r, r, r))
        notes.append(f"{shape} {kind}")
    if rng.uniform() < 0.4:  # thin wires (< 1 px at 128x128)
        wm = cr.material("wire", "metal" if rng.uniform() < 0.5 else "diffuse", color=(0.8, 0.8, 0.75), rough=0.3,
                         index=20)
        yf = float(rng.uniform(-1.2, -0.3))
        for i in range(int(rng.integers(6, 14))):
            x = -1.2 + 0.18 * i
            cr.wire((x, yf, 0), (x + float(rng.uniform(-0.2, 0.2)), yf, float(rng.uniform(0.4, 1.1))), 0.006, wm)
        notes.append("wires")
    light = str(rng.choice(["sky", "area", "panel"]))
    if light == "sky":
        cr.world_sky(sc, float(rng.uniform(15, 70)), float(rng.uniform(0, 360)))
    else:
        cr.world_constant(sc, tuple(float(c) for c in rng.uniform(0.0, 0.15, 3)))
        if light == "area":
            ld = bpy.data.lights.new("Key", "AREA")
            ld.energy = float(rng.uniform(150, 500))
            ld.size = float(rng.uniform(0.3, 1.5))
            key = bpy.data.objects.new("Key", ld)
            sc.collection.objects.link(key)
            key.location = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 1)), float(rng.uniform(2, 4)))
            key.rotation_mode = "QUATERNION"
            key.rotation_quaternion = (Vector((0, 0, 0.3)) - key.location).to_track_quat("-Z", "Y")
        else:  # an emissive panel, in view from most cameras (Emission pass)
            cr.add("plane", cr.material("panel", "emission", color=(1.0, 0.95, 0.85), strength=float(rng.uniform(8, 30)),
                                        index=21),
                   loc=(float(rng.uniform(-1.5, 1.5)), float(rng.uniform(0.5, 2.0)), float(rng.uniform(1.2, 2.4))),
                   rot=(math.radians(float(rng.uniform(-150, -100))), 0, float(rng.uniform(-0.6, 0.6))),
                   scale=(float(rng.uniform(0.3, 0.8)), float(rng.uniform(0.2, 0.5)), 1))
    notes.append(f"light {light}")
    ang = float(rng.uniform(-0.8, 0.8))
    dist, h = float(rng.uniform(2.8, 4.2)), float(rng.uniform(0.6, 2.2))
    cr.camera(sc, (dist * math.sin(ang), -dist * math.cos(ang), h),
              (float(rng.uniform(-0.3, 0.3)), float(rng.uniform(-0.2, 0.4)), float(rng.uniform(0.2, 0.6))),
              lens=float(rng.uniform(24, 45)))
    box = rng.uniform() < 0.4
    return ", ".join(notes), box


def main():
    root, names = parse_train_args("cycles", "tr_cy", N_SCENES)
    res = TRAIN["res"]
    for name in names:
        k = int(name[-2:])
        d = root / name
        d.mkdir(parents=True, exist_ok=True)
        files, times = {}, {}
        what = settings = None
        for spp, seed, stem in train_jobs(k):
            cr._obj_index[0] = 0
            sc = cr.reset()
            what, box = scene(sc, k)
            cr.configure(sc, res, spp, seed)
            if box:
                sc.cycles.pixel_filter_type = "BOX"
            settings = cr.settings_record(sc)
            target = d / f"{stem}.exr"
            if not done(target):
                log(f"cycles {name} {stem} ...")
                times[stem] = cr.render_to(sc, target)
                log(f"cycles {name} {stem} {times[stem]:.1f}s")
            files[stem] = {"spp": spp, "seed": seed, "file": target.name, "channels": exr_channels(target)}
        man_path = d / "manifest.json"
        write_manifest(man_path, {
            "scene": name, "split": "train", "renderer": "blender-cycles", "version": bpy.app.version_string,
            "description": what, "resolution": [res, res], "layout": "blender-multilayer-exr", "files": files,
            "reference": f"ref{TRAIN['ref_spp']:04d}", "settings": settings,
            "render_seconds": merged_render_seconds(man_path, times), "conventions": cr.CONVENTIONS,
        })


if __name__ == "__main__":
    main()
