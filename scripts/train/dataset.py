#!/usr/bin/env python3
"""The learned filter's training data (docs/learned.md, "Data"): randomised JSON scenes rendered by
atrous's own path tracer at 1, 4, 16, 64 and 256 spp with a >= 1024-spp reference (--spps: other counts;
a cached scene renders only the counts it lacks).

Scene i is a pure function of (--seed, i): its type, geometry, materials, textures, lights, camera
and render seeds. Each finished scene is one file out/train/data/<split>/scene_NNNN.npz (written
under a temporary name and renamed), so an interrupted run resumes where it stopped. The held-out
split is a scene TYPE the training split never sees (default: "studio").

  .venv-train/bin/python scripts/train/dataset.py --atrous build-learn/atrous --scenes 160
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

TYPES = ("room", "outdoor", "envmap", "studio")
SPPS = (1, 4, 16, 64, 256)  # 64 and 256: near-clean inputs, so the filter learns to leave them alone (docs/learned.md)
BUFFERS = ("color", "variance", "albedo", "normal", "depth", "emission")


def _obj_torus(path: Path, R: float, r: float, n: int = 24, m: int = 12) -> None:
    lines = []
    for i in range(n):
        for j in range(m):
            u, v = 2 * math.pi * i / n, 2 * math.pi * j / m
            x = (R + r * math.cos(v)) * math.cos(u)
            z = (R + r * math.cos(v)) * math.sin(u)
            lines.append(f"v {x:.5f} {r * math.sin(v):.5f} {z:.5f}")
    for i in range(n):
        for j in range(m):
            a, b = i * m + j + 1, ((i + 1) % n) * m + j + 1
            c, d = ((i + 1) % n) * m + (j + 1) % m + 1, i * m + (j + 1) % m + 1
            lines.append(f"f {a} {d} {c} {b}")
    path.write_text("\n".join(lines) + "\n")


def _obj_prism(path: Path, sides: int, radius: float, height: float) -> None:
    v = []
    for k in range(sides):
        t = 2 * math.pi * k / sides
        v.append((radius * math.cos(t), 0.0, radius * math.sin(t)))
    for k in range(sides):
        t = 2 * math.pi * k / sides
        v.append((radius * math.cos(t), height, radius * math.sin(t)))
    lines = [f"v {a:.5f} {b:.5f} {c:.5f}" for a, b, c in v]
    for k in range(sides):
        a, b = k + 1, (k + 1) % sides + 1
        lines.append(f"f {a} {b} {b + sides} {a + sides}")
    lines.append("f " + " ".join(str(k + 1) for k in range(sides)))
    lines.append("f " + " ".join(str(sides + k + 1) for k in reversed(range(sides))))
    path.write_text("\n".join(lines) + "\n")


def _obj_boxes(path: Path, boxes) -> None:
    """An OBJ of axis-aligned boxes, each (x0, x1, y0, y1, z0, z1), faces wound outward."""
    lines, faces = [], []
    for x0, x1, y0, y1, z0, z1 in boxes:
        b = len(lines)
        lines += [f"v {x:.5f} {y:.5f} {z:.5f}" for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
        # vertex (i, j, k) of (x, y, z) is b + 4 i + 2 j + k + 1
        v = lambda i, j, k: b + 4 * i + 2 * j + k + 1  # noqa: E731
        faces += [f"f {v(0,0,0)} {v(0,0,1)} {v(0,1,1)} {v(0,1,0)}", f"f {v(1,0,0)} {v(1,1,0)} {v(1,1,1)} {v(1,0,1)}",
                  f"f {v(0,0,0)} {v(1,0,0)} {v(1,0,1)} {v(0,0,1)}", f"f {v(0,1,0)} {v(0,1,1)} {v(1,1,1)} {v(1,1,0)}",
                  f"f {v(0,0,0)} {v(0,1,0)} {v(1,1,0)} {v(1,0,0)}", f"f {v(0,0,1)} {v(1,0,1)} {v(1,1,1)} {v(0,1,1)}"]
    path.write_text("\n".join(lines + faces) + "\n")


def _fence(rng: np.random.Generator, d: Path, name: str) -> dict:
    """Thin geometry (issue 12's fine detail; the corpus's slats and wires): a fence of n slats 0.5-2
    pixels wide at the usual camera distance, with or without rails, of unit-ish size."""
    n = int(rng.integers(8, 28))
    width = float(rng.uniform(0.012, 0.05))
    gap = float(rng.uniform(1.0, 4.0)) * width
    height = float(rng.uniform(0.5, 1.6))
    total = n * width + (n - 1) * gap
    x0 = -total / 2
    boxes = [(x0 + k * (width + gap), x0 + k * (width + gap) + width, 0.0, height, -width / 2, width / 2)
             for k in range(n)]
    if rng.random() < 0.5:  # rails across the slats
        for y in (0.3 * height, 0.85 * height):
            boxes.append((x0, x0 + total, y, y + width, -width, width))
    _obj_boxes(d / f"{name}.obj", boxes)
    return {"file": f"{name}.obj"}


def _texture(path: Path, rng: np.random.Generator) -> None:
    from PIL import Image  # matplotlib's dependency, in .venv-train

    n = 64
    y, x = np.mgrid[0:n, 0:n] / n
    f1, f2 = rng.uniform(2, 12, 2)
    pat = 0.5 + 0.5 * np.sin(2 * np.pi * (f1 * x + rng.uniform())) * np.sin(2 * np.pi * f2 * y)
    pat = (pat > rng.uniform(0.3, 0.7)).astype(np.float32) if rng.uniform() < 0.5 else pat
    c1, c2 = rng.uniform(0.05, 0.9, 3), rng.uniform(0.05, 0.9, 3)
    img = c1[None, None] * pat[..., None] + c2[None, None] * (1 - pat[..., None])
    Image.fromarray((np.clip(img, 0, 1) ** (1 / 2.2) * 255).astype(np.uint8)).save(path)


def _write_exr(path: Path, img: np.ndarray) -> None:
    import OpenEXR

    OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                 {"RGB": img.astype(np.float32)}).write(str(path))


def _envmap(path: Path, rng: np.random.Generator) -> None:
    h, w = 64, 128
    v, u = (np.mgrid[0:h, 0:w] + 0.5) / np.array([h, w])[:, None, None]
    up = np.cos(np.pi * v)  # +1 at the top row
    sky = rng.uniform(0.2, 1.0, 3) * rng.uniform(0.3, 2.0)
    ground = rng.uniform(0.05, 0.4, 3) * rng.uniform(0.2, 1.0)
    img = np.where(up[..., None] > 0, sky[None, None] * (0.4 + 0.6 * up[..., None]), ground[None, None])
    for _ in range(rng.integers(1, 4)):  # bright blobs (windows, lamps)
        cu, cv, s = rng.uniform(0, 1), rng.uniform(0.1, 0.5), rng.uniform(0.02, 0.08)
        d2 = ((u - cu) ** 2 + (v - cv) ** 2) / s**2
        img = img + np.exp(-d2)[..., None] * rng.uniform(5, 60) * rng.uniform(0.6, 1.0, 3)
    _write_exr(path, img)


def _material(rng: np.random.Generator, d: Path, name: str, allow_specular: bool = True) -> dict:
    kinds = ["diffuse", "checker", "texture", "plastic", "conductor"] + (["mirror", "glass"] if allow_specular else [])
    p = [0.3, 0.15, 0.15, 0.15, 0.1] + ([0.07, 0.08] if allow_specular else [])
    k = rng.choice(kinds, p=np.array(p) / sum(p))
    col = [round(float(c), 3) for c in rng.uniform(0.05, 0.9, 3)]
    if k == "diffuse":
        return {"type": "diffuse", "albedo": col}
    if k == "checker":
        return {"type": "diffuse", "checker": {"color1": col, "color2": [round(float(c), 3) for c in rng.uniform(0.02, 0.9, 3)],
                                               "scale": float(rng.integers(2, 16))}}
    if k == "texture":
        _texture(d / f"{name}.png", rng)
        return {"type": "diffuse", "texture": f"{name}.png"}
    if k == "plastic":
        return {"type": "plastic", "albedo": col, "roughness": round(float(rng.uniform(0.02, 0.5)), 3), "ior": 1.5}
    if k == "conductor":
        return {"type": "conductor", "albedo": [round(float(c), 3) for c in rng.uniform(0.4, 1.0, 3)],
                "roughness": round(float(rng.uniform(0.05, 0.6)), 3)}
    if k == "mirror":
        return {"type": "mirror", "albedo": [0.9, 0.9, 0.9]}
    return {"type": "dielectric", "ior": round(float(rng.uniform(1.3, 1.7)), 3)}


def make_scene(seed: int, index: int, d: Path, kind: str, extras: bool = True) -> dict:
    """The JSON scene of (seed, index, kind), its OBJ/texture/env files written into d; extras: data
    version 2's fences and windows (the training split; the held-out split stays version 1, so its
    figures compare across versions)."""
    rng = np.random.default_rng([seed, index, TYPES.index(kind)])
    mats: dict = {"ground": _material(rng, d, "ground", allow_specular=False)}
    objs: list = [{"type": "quad", "name": "ground", "corner": [-6, 0, -6], "edge1": [0, 0, 12], "edge2": [12, 0, 0],
                   "material": "ground"}]
    lights: list = []
    if kind == "room":
        mats["wall"] = _material(rng, d, "wall", allow_specular=False)
        mats["wall2"] = _material(rng, d, "wall2", allow_specular=False)
        mats["lamp"] = {"type": "emissive", "emission": [round(float(c), 2) for c in rng.uniform(6, 18, 3)]}
        H = 4.0
        objs[0] = {"type": "quad", "name": "ground", "corner": [-3, 0, -3], "edge1": [0, 0, 6], "edge2": [6, 0, 0], "material": "ground"}
        objs += [{"type": "quad", "name": "ceiling", "corner": [-3, H, -3], "edge1": [6, 0, 0], "edge2": [0, 0, 6], "material": "wall"},
                 {"type": "quad", "name": "back", "corner": [-3, 0, -3], "edge1": [6, 0, 0], "edge2": [0, H, 0], "material": "wall"},
                 {"type": "quad", "name": "left", "corner": [-3, 0, -3], "edge1": [0, H, 0], "edge2": [0, 0, 6], "material": "wall2"},
                 {"type": "quad", "name": "right", "corner": [3, 0, -3], "edge1": [0, 0, 6], "edge2": [0, H, 0], "material": "wall2"}]
        s = float(rng.uniform(0.4, 1.2))
        cx, cz = rng.uniform(-1.5, 1.5, 2)
        objs.append({"type": "quad", "name": "lamp", "corner": [float(cx) - s, H - 0.01, float(cz) - s],
                     "edge1": [2 * s, 0, 0], "edge2": [0, 0, 2 * s], "material": "lamp"})
        cam_r, cam_h, target = rng.uniform(4.0, 5.5), rng.uniform(1.0, 3.0), [0.0, 1.2, 0.0]
        cam = [float(rng.uniform(-1.5, 1.5)), float(cam_h), float(cam_r)]
    else:
        if kind == "outdoor":
            th, ph = rng.uniform(0.15, 1.2), rng.uniform(0, 2 * np.pi)
            lights.append({"type": "sky", "sunDirection": [float(np.cos(th) * np.cos(ph)), float(np.sin(th)), float(np.cos(th) * np.sin(ph))],
                           "sunRadius": round(float(rng.uniform(0.5, 3.0)), 2), "scale": round(float(rng.uniform(0.5, 1.5)), 2)})
        elif kind == "envmap":
            _envmap(d / "env.exr", rng)
            lights.append({"type": "environment", "file": "env.exr"})
        else:  # studio: point lights, an emissive panel and a dim uniform environment
            for k in range(int(rng.integers(1, 3))):
                lights.append({"type": "point", "position": [float(v) for v in rng.uniform([-4, 2, -4], [4, 6, 4])],
                               "intensity": [round(float(c), 2) for c in rng.uniform(5, 40, 3)]})
            mats["panel"] = {"type": "emissive", "emission": [round(float(c), 2) for c in rng.uniform(3, 12, 3)]}
            objs.append({"type": "quad", "name": "panel", "corner": [-1.5, 4.5, -1.5], "edge1": [3, 0, 0], "edge2": [0, 0, 3],
                         "material": "panel"})
            lights.append({"type": "environment", "color": [round(float(c), 3) for c in rng.uniform(0.02, 0.3, 3)]})
        ang = rng.uniform(0, 2 * np.pi)
        r = rng.uniform(4.5, 8.0)
        cam = [float(r * np.sin(ang)), float(rng.uniform(0.8, 3.5)), float(r * np.cos(ang))]
        target = [0.0, float(rng.uniform(0.3, 1.2)), 0.0]
    for k in range(int(rng.integers(2, 7))):
        name = f"m{k}"
        mats[name] = _material(rng, d, name)
        x, z = (float(v) for v in rng.uniform(-2.2, 2.2, 2))
        shape = rng.choice(["sphere", "sphere", "torus", "prism", "box"])
        size = float(rng.uniform(0.3, 0.9))
        if shape == "sphere":
            objs.append({"type": "sphere", "name": f"o{k}", "center": [x, size, z], "radius": size, "material": name})
        elif shape == "torus":
            _obj_torus(d / f"torus{k}.obj", 1.0, float(rng.uniform(0.2, 0.45)))
            objs.append({"type": "mesh", "name": f"o{k}", "file": f"torus{k}.obj", "material": name,
                         "transform": {"scale": size, "rotateY": float(rng.uniform(0, 180)), "translate": [x, size * 0.45, z]}})
        else:
            sides = 4 if shape == "box" else int(rng.integers(3, 9))
            _obj_prism(d / f"prism{k}.obj", sides, 1.0, float(rng.uniform(0.6, 2.0)))
            objs.append({"type": "mesh", "name": f"o{k}", "file": f"prism{k}.obj", "material": name,
                         "transform": {"scale": size, "rotateY": float(rng.uniform(0, 180)), "translate": [x, 0.0, z]}})
    if extras and _extras(np.random.default_rng([seed, index, TYPES.index(kind), 2]), d, kind, mats, objs, lights):
        # A window-lit room is closed: the camera stands inside it, objects kept off its side.
        cam = [float(v) for v in np.random.default_rng([seed, index, 3]).uniform([-1.5, 1.0, 2.2], [1.5, 2.6, 2.8])]
        objs[:] = [o for o in objs if not (o["name"].startswith("o") and _object_z(o) > 1.2)]
    return {"_comment": f"atrous training scene {index} ({kind}), seed {seed}",
            "camera": {"position": cam, "lookAt": target, "fov": round(float(rng.uniform(30, 55)), 1)},
            "materials": mats, "objects": objs, "lights": lights}


def _object_z(o: dict) -> float:
    return float(o["center"][2]) if "center" in o else float(o["transform"]["translate"][2])


def _extras(rng: np.random.Generator, d: Path, kind: str, mats: dict, objs: list, lights: list) -> bool:
    """Data version 2 (docs/learned.md, "Data"): the corpus's test stills showed the filter blurring
    what the generator never drew. A fence of thin slats (probability 0.4) and, in a room, a window
    in the right wall with the sun and sky outside it (probability 0.5; the lamp then stays on with
    probability 0.3): the sunlit patches and the mostly indirect light of an interior. Returns
    whether it closed the room (the caller then moves the camera inside)."""
    if rng.random() < 0.4:
        mats["fence"] = _material(rng, d, "fence")
        f = _fence(rng, d, "fence")
        x, z = (float(v) for v in rng.uniform(-1.8, 1.8, 2))
        objs.append({"type": "mesh", "name": "ofence", "material": "fence", **f,
                     "transform": {"scale": float(rng.uniform(0.8, 1.6)), "rotateY": float(rng.uniform(-60, 60)),
                                   "translate": [x, 0.0, z]}})
    if kind != "room" or rng.random() >= 0.5:
        return False
    H = 4.0
    za, zb = sorted(float(v) for v in rng.uniform(-2.5, 2.0, 2))
    zb = max(zb, za + 0.8)
    ya, yb = float(rng.uniform(0.6, 1.6)), float(rng.uniform(2.4, 3.6))
    right = [o for o in objs if o.get("name") == "right"][0]
    objs.remove(right)
    m = right["material"]
    objs += [{"type": "quad", "name": "right_low", "corner": [3, 0, -3], "edge1": [0, 0, 6], "edge2": [0, ya, 0], "material": m},
             {"type": "quad", "name": "right_high", "corner": [3, yb, -3], "edge1": [0, 0, 6], "edge2": [0, H - yb, 0], "material": m},
             {"type": "quad", "name": "right_a", "corner": [3, ya, -3], "edge1": [0, 0, za + 3], "edge2": [0, yb - ya, 0], "material": m},
             {"type": "quad", "name": "right_b", "corner": [3, ya, zb], "edge1": [0, 0, 3 - zb], "edge2": [0, yb - ya, 0], "material": m},
             {"type": "quad", "name": "front", "corner": [-3, 0, 3], "edge1": [0, H, 0], "edge2": [6, 0, 0], "material": "wall"}]
    th, ph = float(rng.uniform(0.25, 0.8)), float(rng.uniform(-0.6, 0.6))
    lights.append({"type": "sky", "sunDirection": [math.cos(th) * math.cos(ph), math.sin(th), math.cos(th) * math.sin(ph)],
                   "sunRadius": round(float(rng.uniform(0.5, 2.0)), 2), "scale": round(float(rng.uniform(0.5, 1.5)), 2)})
    if rng.random() >= 0.3:
        objs[:] = [o for o in objs if o.get("name") != "lamp"]
    return True


def read_exr(path: Path) -> np.ndarray:
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        return np.asarray(ch["RGB"].pixels if "RGB" in ch else next(iter(ch.values())).pixels, np.float32)


def render(atrous: str, scene: Path, spp: int, seed: int, size: int, out: Path) -> None:
    subprocess.run([atrous, "render", "--scene", str(scene), "--spp", str(spp), "--seed", str(seed),
                    "--width", str(size), "--height", str(size), "--device", "cpu", "--quiet", "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL)


def scene_kind(seed: int, index: int, held_out: str) -> str:
    kinds = [k for k in TYPES if k != held_out]
    return kinds[int(np.random.default_rng([seed, index, 99]).integers(len(kinds)))]


def build_scene(args, index: int, split: str, kind: str) -> Path:
    dest = Path(args.out) / "data" / split / f"scene_{index:04d}.npz"
    dest.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=Path(args.out)) as tmp:
        t = Path(tmp)
        scene = make_scene(args.seed, index, t, kind, extras=split == "train")
        arrays = {}
        if dest.exists():  # cached: kept while it is this generator's scene (a changed generator redraws it)
            with np.load(dest) as z:
                if "scene_json" in z.files and str(z["scene_json"]) == json.dumps(scene):
                    arrays = {k: z[k] for k in z.files}
        todo = [spp for spp in args.spps if f"color_{spp}" not in arrays]
        if arrays and not todo:
            return dest
        (t / "scene.json").write_text(json.dumps(scene, indent=1))
        for spp in todo:  # a cached scene renders only the spp it lacks
            render(args.atrous, t / "scene.json", spp, args.seed * 100003 + index * 16 + spp, args.size, t / f"s{spp}")
            for b in BUFFERS:
                arrays[f"{b}_{spp}"] = read_exr(t / f"s{spp}" / f"{b}.exr")
        if "reference" not in arrays:
            render(args.atrous, t / "scene.json", args.ref_spp, args.seed * 100003 + index * 16 + 15, args.size, t / "ref")
            arrays["reference"] = read_exr(t / "ref" / "color.exr")
        arrays["kind"] = np.array(kind)
        arrays["scene_json"] = np.array(json.dumps(scene))
        tmpname = dest.with_suffix(".tmp.npz")
        np.savez_compressed(tmpname, **arrays)
        os.replace(tmpname, dest)
    return dest


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--atrous", default="build-learn/atrous", help="the atrous CLI")
    p.add_argument("--out", default="out/train", help="cache folder (data/<split>/scene_NNNN.npz)")
    p.add_argument("--scenes", type=int, default=160, help="training scenes")
    p.add_argument("--test-scenes", type=int, default=16, help="held-out scenes (of the held-out type)")
    p.add_argument("--held-out", default="studio", choices=TYPES, help="scene type kept out of training")
    p.add_argument("--size", type=int, default=128, help="image width = height")
    p.add_argument("--ref-spp", type=int, default=1024)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--spps", type=int, nargs="+", default=list(SPPS), help=f"input sample counts (default {SPPS})")
    a = p.parse_args(argv)
    if a.ref_spp < 1024:
        print("dataset.py: --ref-spp below 1024 makes references too noisy to train on", file=sys.stderr)
        return 2
    if not shutil.which(a.atrous) and not Path(a.atrous).is_file():
        print(f"dataset.py: --atrous {a.atrous}: not found (build the CLI: cmake --build build-learn --target atrous)",
              file=sys.stderr)
        return 2
    Path(a.out).mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    jobs = [(i, "train", scene_kind(a.seed, i, a.held_out)) for i in range(a.scenes)]
    jobs += [(100000 + i, "test", a.held_out) for i in range(a.test_scenes)]
    # Interleave: a short run still has some held-out scenes.
    order = sorted(jobs, key=lambda j: (j[0] % 100000) * (1 if j[1] == "train" else a.scenes / max(a.test_scenes, 1)))
    for n, (i, split, kind) in enumerate(order):
        t1 = time.time()
        dest = Path(a.out) / "data" / split / f"scene_{i:04d}.npz"
        was = dest.stat().st_mtime if dest.exists() else None
        build_scene(a, i, split, kind)
        if was is None or dest.stat().st_mtime != was:
            print(f"[{n + 1}/{len(order)}] {split} {i} {kind}: {time.time() - t1:.1f} s (total {time.time() - t0:.0f} s)",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
