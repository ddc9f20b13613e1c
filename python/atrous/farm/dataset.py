"""Randomised scenes for a training set (the `render` job's dataset spec).

A spec is a JSON object (a file for the CLI, a dict for the Python API):

    {"count": 100, "seed": 7, "width": 128, "height": 128, "spp": [1, 4, 16],
     "reference_spp": 1024, "max_depth": 8}

or, with training targets that need no reference render (issue 47):

    {"count": 1000, "spp": [1, 4, 16], "target": "oidn", "target_spp": 256, "reference_every": 20}

"target": "reference" (the default) writes reference.exr, a reference_spp render; "oidn" writes
target.exr instead: a target_spp render (a third seed) denoised by OIDN at quality high (pyoidn,
colour + albedo + normal, HDR), with target.json saying so, at a small part of a reference's cost;
with reference_every N > 0, every Nth scene (index 0, N, 2N, ...) also gets reference.exr, so that
the targets' own error can be measured (python -m atrous.farm.target_error DIR).

Scene i is drawn from random.Random(f"{seed}:{i}") (Python's documented, version-stable seeding
of a string), so the same spec gives the same scenes on every machine and any subset of them can
be re-rendered alone. A scene is a room (floor, back and side walls of random colours) with 2-6
spheres of random materials (diffuse, plastic, rough metal, mirror, glass), lit by a ceiling area
light, a point light or both, seen by a camera at a random place near the open side; only
quads and spheres, so a scene.json needs no other file.
"""
from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any, Dict, List, Union

from .items import FarmInputError, int_list, positive_int

__all__ = ["DEFAULT_SPEC", "check_spec", "load_spec", "random_scene"]

DEFAULT_SPEC: Dict[str, Any] = {"count": 16, "seed": 1, "width": 128, "height": 128, "spp": [4],
                                "reference_spp": 1024, "max_depth": 8, "target": "reference", "target_spp": 256,
                                "reference_every": 0}
TARGETS = ("reference", "oidn")
_KEYS = set(DEFAULT_SPEC)


def check_spec(spec: Dict[str, Any], where: str = "dataset spec") -> Dict[str, Any]:
    if not isinstance(spec, dict):
        raise FarmInputError(f"{where}: expected a JSON object, got {type(spec).__name__}")
    unknown = sorted(set(spec) - _KEYS)
    if unknown:
        raise FarmInputError(f"{where}: unknown key '{unknown[0]}' (expected {', '.join(sorted(_KEYS))})")
    s = dict(DEFAULT_SPEC, **spec)
    out = {
        "count": positive_int(s["count"], f"{where}: count", 1, 1_000_000),
        "seed": positive_int(s["seed"], f"{where}: seed", 0, 2 ** 32 - 1),
        "width": positive_int(s["width"], f"{where}: width", 1, 16384),
        "height": positive_int(s["height"], f"{where}: height", 1, 16384),
        "spp": int_list(s["spp"], f"{where}: spp", 1, 1 << 20),
        "reference_spp": positive_int(s["reference_spp"], f"{where}: reference_spp", 1, 1 << 20),
        "max_depth": positive_int(s["max_depth"], f"{where}: max_depth", 1, 1000),
        "target_spp": positive_int(s["target_spp"], f"{where}: target_spp", 1, 1 << 20),
        "reference_every": positive_int(s["reference_every"], f"{where}: reference_every", 0, 1_000_000),
    }
    if s["target"] not in TARGETS:
        raise FarmInputError(f"{where}: target must be one of {', '.join(TARGETS)}, got {s['target']!r}")
    out["target"] = s["target"]
    return out


def load_spec(path: Union[str, Path]) -> Dict[str, Any]:
    p = Path(path)
    try:
        text = p.read_text()
    except OSError as e:
        raise FarmInputError(f"{p}: cannot read the dataset spec ({e.strerror or e})")
    try:
        spec = json.loads(text)
    except json.JSONDecodeError as e:
        raise FarmInputError(f"{p}: not valid JSON (line {e.lineno}, column {e.colno}: {e.msg})")
    return check_spec(spec, str(p))


def _rgb(r: random.Random, lo: float, hi: float) -> List[float]:
    return [round(r.uniform(lo, hi), 4) for _ in range(3)]


def _material(r: random.Random) -> Dict[str, Any]:
    kind = r.choices(["diffuse", "plastic", "conductor", "mirror", "dielectric"], [4, 2, 2, 1, 1])[0]
    if kind == "diffuse":
        return {"type": "diffuse", "albedo": _rgb(r, 0.05, 0.9)}
    if kind == "plastic":
        return {"type": "plastic", "albedo": _rgb(r, 0.05, 0.9), "roughness": round(r.uniform(0.02, 0.5), 3),
                "ior": 1.5}
    if kind == "conductor":
        return {"type": "conductor", "albedo": _rgb(r, 0.5, 1.0), "roughness": round(r.uniform(0.05, 0.6), 3)}
    if kind == "mirror":
        return {"type": "mirror", "albedo": _rgb(r, 0.8, 0.98)}
    return {"type": "dielectric", "ior": round(r.uniform(1.3, 1.7), 3)}


def random_scene(seed: int, index: int) -> Dict[str, Any]:
    """Scene `index` of a dataset with this seed, as the JSON dict of a scene file (docs/scenes.md)."""
    r = random.Random(f"{seed}:{index}")
    W, D, H = r.uniform(4, 7), r.uniform(4, 7), r.uniform(3, 4.5)  # room: x in [-W/2, W/2], z in [-D, 0]
    mats: Dict[str, Any] = {
        "floor": ({"type": "diffuse", "checker": {"color1": _rgb(r, 0.4, 0.9), "color2": _rgb(r, 0.05, 0.4),
                                                  "scale": r.choice([4, 6, 8, 12])}}
                  if r.random() < 0.5 else {"type": "diffuse", "albedo": _rgb(r, 0.2, 0.9)}),
        "back": {"type": "diffuse", "albedo": _rgb(r, 0.2, 0.9)},
        "left": {"type": "diffuse", "albedo": _rgb(r, 0.05, 0.9)},
        "right": {"type": "diffuse", "albedo": _rgb(r, 0.05, 0.9)},
        "ceiling": {"type": "diffuse", "albedo": _rgb(r, 0.5, 0.9)},
    }
    x0, x1 = -W / 2, W / 2
    def wall(name: str, corner: List[float], e1: List[float], e2: List[float]) -> Dict[str, Any]:
        return {"type": "quad", "name": name, "corner": corner, "edge1": e1, "edge2": e2, "material": name}

    objects: List[Dict[str, Any]] = [
        wall("floor", [x0, 0, -D], [0, 0, D], [W, 0, 0]),
        wall("ceiling", [x0, H, -D], [W, 0, 0], [0, 0, D]),
        wall("back", [x0, 0, -D], [W, 0, 0], [0, H, 0]),
        wall("left", [x0, 0, -D], [0, H, 0], [0, 0, D]),
        wall("right", [x1, 0, -D], [0, 0, D], [0, H, 0]),
    ]
    for k in range(r.randint(2, 6)):
        rad = r.uniform(0.25, 0.9)
        mats[f"m{k}"] = _material(r)
        objects.append({"type": "sphere", "name": f"sphere{k}", "material": f"m{k}", "radius": round(rad, 3),
                        "center": [round(r.uniform(x0 + rad, x1 - rad), 3), round(rad if r.random() < 0.8 else
                                   r.uniform(rad, H - rad - 0.3), 3), round(r.uniform(-D + rad, -0.8 - rad), 3)]})
    lights: List[Dict[str, Any]] = []
    style = r.choice(["area", "point", "both"])
    if style in ("area", "both"):
        s = r.uniform(0.6, 1.4)
        cx, cz = r.uniform(x0 / 2, x1 / 2), r.uniform(-D * 0.7, -D * 0.3)
        power = r.uniform(8, 25)
        mats["lamp"] = {"type": "emissive", "emission": [round(power * c, 3) for c in _rgb(r, 0.7, 1.0)]}
        objects.append({"type": "quad", "name": "lamp", "corner": [cx - s / 2, H - 0.01, cz - s / 2],
                        "edge1": [s, 0, 0], "edge2": [0, 0, s], "material": "lamp"})
    if style in ("point", "both"):
        lights.append({"type": "point", "position": [round(r.uniform(x0 * 0.7, x1 * 0.7), 3),
                                                     round(r.uniform(H * 0.6, H - 0.3), 3),
                                                     round(r.uniform(-D * 0.8, -D * 0.2), 3)],
                       "intensity": [round(r.uniform(5, 25) * c, 3) for c in _rgb(r, 0.7, 1.0)]})
    cam = [round(r.uniform(x0 * 0.4, x1 * 0.4), 3), round(r.uniform(0.8, H * 0.8), 3), round(r.uniform(1.5, 4), 3)]
    target = [round(r.uniform(x0 * 0.3, x1 * 0.3), 3), round(r.uniform(0.4, 1.5), 3),
              round(-D * r.uniform(0.4, 0.7), 3)]
    return {"camera": {"position": cam, "lookAt": target, "up": [0, 1, 0], "fov": round(r.uniform(35, 60), 2)},
            "materials": mats, "objects": objects, "lights": lights}
