#!/usr/bin/env python3
"""The corpus's LuxCoreRender test stills (docs/corpus.md, "LuxCore stills"): four scenes rendered
with LuxCoreRender (pyluxcore, PATHCPU, its default Blackman-Harris pixel filter) in LuxCore's own
layout, one folder per render holding RGB.exr, ALBEDO.exr, AVG_SHADING_NORMAL.exr, POSITION.exr
and DEPTH.exr (the film outputs OIDN's LuxCore plugin reads; the albedo and the normal follow
glass and mirrors, so they are noisy there). A third renderer beside Mitsuba and Cycles; these
scenes are never trained on (the training split's LuxCore scenes are luxcore_train.py's).

    python -m venv /tmp/luxvenv && /tmp/luxvenv/bin/pip install pyluxcore numpy   # Python 3.11 wheel
    /tmp/luxvenv/bin/python scripts/corpus/luxcore_stills.py out/corpus/full/luxcore

writes OUT/<scene>/{spp0004,spp0016,ref2048}/ and OUT/<scene>/manifest.json (the corpus's manifest
fields; layout "luxcore"). A render already on disk is kept. About 4 minutes per scene at 256² on 2
cores (the 2048-spp reference). Not part of `make test`: pyluxcore is not a project dependency.

  lx_glass    a glass sphere and a glossy-coated (glossy2) red sphere on a grey floor, an area lamp
              in view, a dim sky
  lx_pergola  a white wall and floor under a pergola of thin slats, sun and sky: striped shadows
              that only the colour marks
  lx_metal    a rough gold sphere and a rough copper box on a checker floor, an area lamp, a sky
  lx_room     a closed room lit by the sun through a window in its back wall, a table and a glass block
"""
import argparse
import json
import math
import os
import time

import pyluxcore

from common import SEED_NOISY, SEED_REF  # the seeds of the other renderers' stills (scripts/corpus/common.py)

pyluxcore.Init(lambda s: None)

SIZE = 256
REF_SPP = 2048
OUTPUTS = ("RGB", "ALBEDO", "AVG_SHADING_NORMAL", "POSITION", "DEPTH")


def box(cx, cy, cz, sx, sy, sz):
    v = [(cx + sx * x, cy + sy * y, cz + sz * z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    f = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6),
         (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return v, f


def sphere(cx, cy, cz, r, n=32):
    v, f = [], []
    for i in range(n + 1):
        th = math.pi * i / n
        for j in range(2 * n):
            ph = 2 * math.pi * j / (2 * n)
            v.append((cx + r * math.sin(th) * math.cos(ph), cy + r * math.cos(th), cz + r * math.sin(th) * math.sin(ph)))
    for i in range(n):
        for j in range(2 * n):
            a, b = i * 2 * n + j, i * 2 * n + (j + 1) % (2 * n)
            f += [(a, a + 2 * n, b), (b, a + 2 * n, b + 2 * n)]
    return v, f


def scene_glass():
    mats = {"floor": ("matte", {"kd": [0.45, 0.45, 0.45]}), "glass": ("glass", {"kr": [1, 1, 1], "kt": [1, 1, 1],
            "interiorior": 1.5}), "coat": ("glossy2", {"kd": [0.6, 0.08, 0.05], "ks": [0.05, 0.05, 0.05],
            "uroughness": 0.05, "vroughness": 0.05}), "back": ("matte", {"kd": [0.2, 0.3, 0.5]}),
            "light": ("matte", {"kd": [0, 0, 0], "emission": [14, 13, 12]})}
    shapes = {"floor": (box(0, -0.05, 0, 6, 0.05, 6), "floor"), "back": (box(0, 2, -2.5, 6, 2, 0.1), "back"),
              "ball": (sphere(-0.7, 0.75, 0.3, 0.75), "glass"), "coat": (sphere(0.9, 0.6, -0.4, 0.6), "coat"),
              "lamp": (box(0.2, 3.2, -1.2, 1.2, 0.02, 0.5), "light")}
    lights = {"sky": ("constantinfinite", {"color": [0.1, 0.12, 0.16]})}
    return mats, shapes, lights, ((0.3, 1.6, 4.6), (0, 0.6, 0), 40)


def scene_pergola():
    mats = {"white": ("matte", {"kd": [0.75, 0.75, 0.72]}), "wood": ("matte", {"kd": [0.35, 0.22, 0.12]})}
    shapes = {"floor": (box(0, -0.05, 0, 6, 0.05, 6), "white"), "wall": (box(0, 1.6, -1.5, 4, 1.6, 0.1), "white")}
    for k in range(12):  # slats above, 0.06 wide, 0.25 apart
        shapes[f"slat{k}"] = (box(-1.6 + 0.28 * k, 2.6, 0.4, 0.03, 0.04, 2.0), "wood")
    shapes["beam0"] = (box(0, 2.68, -1.3, 2.0, 0.04, 0.04), "wood")
    shapes["beam1"] = (box(0, 2.68, 2.2, 2.0, 0.04, 0.04), "wood")
    lights = {"sun": ("sun", {"dir": [0.35, 0.9, 0.55], "turbidity": 2.5, "gain": [0.0001, 0.0001, 0.0001]}),
              "sky": ("sky2", {"dir": [0.35, 0.9, 0.55], "turbidity": 2.5, "gain": [0.0001, 0.0001, 0.0001]})}
    return mats, shapes, lights, ((1.2, 1.3, 4.2), (0, 1.0, -1.2), 50)


def scene_metal():
    mats = {"check": ("matte", {"kd": "checks"}), "gold": ("metal2", {"preset": "gold", "uroughness": 0.15,
            "vroughness": 0.15}), "copper": ("metal2", {"preset": "copper", "uroughness": 0.3, "vroughness": 0.3}),
            "light": ("matte", {"kd": [0, 0, 0], "emission": [10, 10, 10]})}
    shapes = {"floor": (box(0, -0.05, 0, 6, 0.05, 6), "check"), "gold": (sphere(-0.6, 0.7, 0, 0.7), "gold"),
              "copper": (box(1.0, 0.45, -0.5, 0.45, 0.45, 0.45), "copper"),
              "lamp": (box(-1.5, 3.0, 1.0, 0.8, 0.02, 0.8), "light")}
    lights = {"sky": ("constantinfinite", {"color": [0.25, 0.27, 0.3]})}
    tex = {"checks": ("checkerboard3d", {"texture1": [0.8, 0.8, 0.8], "texture2": [0.1, 0.1, 0.12],
                                         "mapping.type": "globalmapping3d",
                                         "mapping.transformation": [4, 0, 0, 0, 0, 4, 0, 0, 0, 0, 4, 0, 0, 0, 0, 1]})}
    return mats, shapes, lights, ((0.5, 1.8, 4.0), (0, 0.5, 0), 42), tex


def scene_room():
    mats = {"white": ("matte", {"kd": [0.7, 0.68, 0.64]}), "blue": ("matte", {"kd": [0.15, 0.25, 0.55]}),
            "wood": ("matte", {"kd": [0.45, 0.3, 0.18]}), "glass": ("glass", {"kr": [1, 1, 1], "kt": [0.9, 0.95, 1],
            "interiorior": 1.5})}
    shapes = {"floor": (box(0, -0.05, 0, 3, 0.05, 3), "wood"), "ceil": (box(0, 2.55, 0, 3, 0.05, 3), "white"),
              "left": (box(-3, 1.25, 0, 0.05, 1.3, 3), "blue"), "right": (box(3, 1.25, 0, 0.05, 1.3, 3), "white"),
              "front": (box(0, 1.25, 3.05, 3, 1.3, 0.05), "white"),
              # the back wall with a window (1.6 x 1.0 opening, x -0.8..0.8, y 0.9..1.9): four pieces
              "b_lo": (box(0, 0.45, -3, 3, 0.45, 0.05), "white"), "b_hi": (box(0, 2.2, -3, 3, 0.35, 0.05), "white"),
              "b_l": (box(-1.9, 1.4, -3, 1.1, 0.5, 0.05), "white"), "b_r": (box(1.9, 1.4, -3, 1.1, 0.5, 0.05), "white"),
              "table": (box(0.9, 0.55, 0.2, 0.9, 0.04, 0.5), "wood"), "block": (box(0.7, 0.79, 0.2, 0.2, 0.2, 0.2), "glass")}
    lights = {"sun": ("sun", {"dir": [0.25, 0.45, -0.85], "turbidity": 2.2, "gain": [0.003, 0.003, 0.003]}),
              "sky": ("sky2", {"dir": [0.25, 0.45, -0.85], "turbidity": 2.2, "gain": [0.003, 0.003, 0.003]})}
    return mats, shapes, lights, ((-0.6, 1.5, 2.7), (0.2, 0.7, -1.0), 62)


SCENES = {"lx_glass": (scene_glass, "glass sphere and a glossy-coated sphere, area lamp in view, dim sky"),
          "lx_pergola": (scene_pergola, "white wall under a pergola of thin slats, sun and sky: striped shadows"),
          "lx_metal": (scene_metal, "rough gold sphere and rough copper box on a checker floor, area lamp, sky"),
          "lx_room": (scene_room, "closed room lit by the sun through a window, a table and a glass block")}


def typed(p, kind, items):
    """scene.<kind>.<name>.type and its properties, for {name: (type, {property: value})}."""
    for n, (ty, kv) in items.items():
        p.Set(pyluxcore.Property(f"scene.{kind}.{n}.type", ty))
        for k, v in kv.items():
            p.Set(pyluxcore.Property(f"scene.{kind}.{n}.{k}", v))


def render(build, out, spp, seed, size=SIZE, pixel_filter="BLACKMANHARRIS"):
    parts = build()
    mats, shapes, lights, (orig, target, fov) = parts[:4]
    tex = parts[4] if len(parts) > 4 else {}
    scene = pyluxcore.Scene()
    p = pyluxcore.Properties()
    p.Set(pyluxcore.Property("scene.camera.type", "perspective"))
    p.Set(pyluxcore.Property("scene.camera.lookat.orig", list(orig)))
    p.Set(pyluxcore.Property("scene.camera.lookat.target", list(target)))
    p.Set(pyluxcore.Property("scene.camera.up", [0, 1, 0]))
    p.Set(pyluxcore.Property("scene.camera.fieldofview", fov))
    typed(p, "textures", tex)
    typed(p, "materials", mats)
    scene.Parse(p)
    p = pyluxcore.Properties()
    for n, ((v, f), m) in shapes.items():
        scene.DefineMesh(n + "_m", v, f, None, None, None, None)
        p.Set(pyluxcore.Property(f"scene.objects.{n}.shape", n + "_m"))
        p.Set(pyluxcore.Property(f"scene.objects.{n}.material", m))
    typed(p, "lights", lights)
    scene.Parse(p)
    c = pyluxcore.Properties()
    for k, v in {"renderengine.type": "PATHCPU", "sampler.type": "RANDOM", "batch.haltspp": spp, "film.width": size,
                 "film.height": size, "path.pathdepth.total": 8, "film.filter.type": pixel_filter,
                 "native.threads.count": 2, "renderengine.seed": seed, "film.imagepipelines.0.0.type": "NOP"}.items():
        c.Set(pyluxcore.Property(k, v))
    tmp = out + ".tmp"
    os.makedirs(tmp, exist_ok=True)
    for i, t in enumerate(OUTPUTS):
        c.Set(pyluxcore.Property(f"film.outputs.{i}.type", t))
        c.Set(pyluxcore.Property(f"film.outputs.{i}.filename", os.path.join(tmp, t + ".exr")))
    t0 = time.time()
    s = pyluxcore.RenderSession(pyluxcore.RenderConfig(c, scene))
    s.Start()
    while not s.HasDone():
        time.sleep(0.05)
        s.UpdateStats()
    s.Stop()
    s.GetFilm().SaveOutputs()
    os.replace(tmp, out)  # a folder on disk is a finished render
    return time.time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--size", type=int, default=SIZE)
    ap.add_argument("--ref-spp", type=int, default=REF_SPP)
    ap.add_argument("--spp", default="4,16", help="the noisy sample counts (1, 4, 16; issue 47's low-spp set: 1,4,16)")
    a = ap.parse_args()
    for name in a.scenes.split(","):
        build, desc = SCENES[name]
        sd = os.path.join(a.out, name)
        os.makedirs(sd, exist_ok=True)
        ref = f"ref{a.ref_spp:04d}"
        files, times = {}, {}
        for spp, seed, stem in [(s, SEED_NOISY[s], f"spp{s:04d}") for s in map(int, a.spp.split(","))] + [(a.ref_spp, SEED_REF, ref)]:
            files[stem] = {"spp": spp, "seed": seed, "folder": stem, "files": [t + ".exr" for t in OUTPUTS]}
            if not os.path.exists(os.path.join(sd, stem, "RGB.exr")):
                times[stem] = round(render(build, os.path.join(sd, stem), spp, seed, a.size), 1)
                print(f"{name} {stem}: {times[stem]} s", flush=True)
        man = {"scene": name, "renderer": "luxcore", "version": pyluxcore.Version(), "description": desc,
               "resolution": [a.size, a.size], "pixel_filter": "blackman-harris", "integrator": "PATHCPU depth 8",
               "layout": "luxcore", "files": files, "reference": ref, "split": "test", "render_seconds": times}
        with open(os.path.join(sd, "manifest.json"), "w") as f:
            json.dump(man, f, indent=2)
    os._exit(0)  # pyluxcore's log callback crashes at interpreter shutdown


if __name__ == "__main__":
    main()
