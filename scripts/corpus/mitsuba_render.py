"""Mitsuba 3 part of the third-party corpus. Run by render.py inside .venv-corpus:

    .venv-corpus/bin/python scripts/corpus/mitsuba_render.py --mode quick|full --out out/corpus/quick

Scenes are built as Python dicts (mi.load_dict), nothing is downloaded. Layouts written, as a
Mitsuba user has them:
  - "aov": the `aov` integrator wrapping `path`; hdrfilm writes ONE multichannel EXR per render
    (top-level R,G,B, then integrator.R/G/B/A, albedo.R/G/B, nn.X/Y/Z, pos.X/Y/Z, dd.T, si.I ...).
  - "separate": color.exr from the `path` integrator, and one EXR per feature (albedo.exr,
    normal.exr, position.exr, depth.exr) cut out of an `aov`-only render with the same spp/seed.
Sequences: aov layout per frame plus <frame>_motion.exr computed here from pos.* and the previous
frame's camera (Mitsuba has no motion AOV).
"""
import math
import os
import shutil
import sys
import time
from pathlib import Path

import numpy as np

from common import (SEED_SEQ, SEED_SEQ_REF, SEED_SEQ_SPP, seq_spp_folder, done, exr_channels, merged_render_seconds,  # noqa: E402
                    log, parse_render_args, still_jobs, write_manifest)

import mitsuba as mi  # noqa: E402

VARIANT = os.environ.get("CORPUS_MI_VARIANT", "llvm_ad_rgb")
try:
    mi.set_variant(VARIANT)
except Exception as e:  # no usable libLLVM: fall back to the scalar CPU variant
    print(f"mitsuba: variant {VARIANT} unavailable ({e}); using scalar_rgb", file=sys.stderr)
    VARIANT = "scalar_rgb"
    mi.set_variant(VARIANT)

T = mi.ScalarTransform4f
AOVS = "albedo:albedo,nn:sh_normal,pos:position,dd:depth,si:shape_index"
MAX_DEPTH = 8


# ---------------------------------------------------------------- procedural textures
def _value_noise(n, cells, rng):
    g = rng.random((cells + 1, cells + 1)).astype(np.float32)
    x = np.linspace(0, cells, n, endpoint=False)
    i = x.astype(int)
    f = x - i
    f = f * f * (3 - 2 * f)
    a = g[i][:, i]
    b = g[i][:, i + 1]
    c = g[i + 1][:, i]
    d = g[i + 1][:, i + 1]
    fx, fy = f[None, :], f[:, None]
    return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy


def fine_texture(n=512, seed=7):
    """High-frequency detail: thin stripes + multi-octave value noise, in colour (linear)."""
    rng = np.random.default_rng(seed)
    noise = sum(_value_noise(n, c, rng) / (k + 1) for k, c in enumerate((8, 32, 128))) / 1.83
    x = np.arange(n)[None, :]
    y = np.arange(n)[:, None]
    stripes = ((x // 3 + y // 3) % 2).astype(np.float32)  # 3-texel checker: aliasing-prone detail
    base = 0.15 + 0.7 * noise
    rgb = np.stack([base * (0.6 + 0.4 * stripes), base * 0.8, base * (1.0 - 0.5 * stripes)], -1)
    return mi.Bitmap(np.ascontiguousarray(rgb.astype(np.float32)))


def rgb(v):
    return {"type": "rgb", "value": list(v)}


def diffuse(v):
    return {"type": "diffuse", "reflectance": rgb(v) if isinstance(v, (list, tuple)) else v}


def checker(c0, c1, scale):
    return {"type": "checkerboard", "color0": rgb(c0), "color1": rgb(c1),
            "to_uv": T().scale([scale, scale, 1])}


def rect(to_world, bsdf, emitter=None):
    d = {"type": "rectangle", "to_world": to_world, "bsdf": bsdf}
    if emitter is not None:
        d["emitter"] = emitter
    return d


def area(v):
    return {"type": "area", "radiance": rgb(v)}


def floor(size, bsdf, y=0.0):
    return rect(T().translate([0, y, 0]).rotate([1, 0, 0], -90).scale([size, size, 1]), bsdf)


def sphere(c, r, bsdf, emitter=None):
    d = {"type": "sphere", "center": list(c), "radius": r, "bsdf": bsdf}
    if emitter is not None:
        d["emitter"] = emitter
    return d


def cube(t, bsdf):
    return {"type": "cube", "to_world": t, "bsdf": bsdf}


def cylinder(p0, p1, r, bsdf):
    return {"type": "cylinder", "p0": list(p0), "p1": list(p1), "radius": r, "bsdf": bsdf}


def glass():
    return {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}


def mirror():
    return {"type": "conductor", "material": "none"}


def rough_metal(material, alpha):
    return {"type": "roughconductor", "material": material, "alpha": alpha, "distribution": "ggx"}


def sunsky(direction, sun_scale=1.0, sky_scale=1.0):
    d = np.array(direction, float)
    d /= np.linalg.norm(d)
    # sunsky's sky dome is z-up in its local frame (measured: looking down -z sees 0); our world is
    # y up, so rotate it. sun_direction stays in world coordinates (the sun is found there either way).
    return {"type": "sunsky", "sun_direction": list(d), "turbidity": 3.0, "albedo": 0.3,
            "sun_scale": sun_scale, "sky_scale": sky_scale, "to_world": T().rotate([1, 0, 0], -90)}


# ---------------------------------------------------------------- scenes
# Each returns (objects dict, camera dict(origin, target, up, fov), notes, background note).
def scene_glass():
    o = {
        "floor": floor(6, diffuse(checker([0.75, 0.75, 0.7], [0.1, 0.1, 0.12], 8))),
        "back": rect(T().translate([0, 3, -2.5]).scale([6, 3, 1]), diffuse([0.6, 0.55, 0.5])),
        "glass": sphere([-0.55, 0.5, 0.2], 0.5, glass()),
        "gold": sphere([0.6, 0.45, -0.4], 0.45, rough_metal("Au", 0.15)),
        # the visible area light: a tilted panel at the back, seen by the camera
        "panel": rect(T().translate([0.2, 1.9, -2.0]).rotate([1, 0, 0], 50).scale([0.9, 0.35, 1]),
                      diffuse([0, 0, 0]), area([9, 8.5, 8])),
    }
    cam = dict(origin=[0, 1.3, 3.4], target=[0, 0.6, 0], up=[0, 1, 0], fov=42)
    return o, cam, "glass sphere with caustic, rough gold, checker floor, visible area light", \
        "no environment: background (only beyond the floor edge, if at all) is 0"


def scene_mirror_thin():
    tex = {"type": "bitmap", "bitmap": fine_texture(), "filter_type": "bilinear"}
    o = {
        "floor": rect(T().rotate([1, 0, 0], -90).scale([3, 3, 1]), {"type": "diffuse", "reflectance": tex}),
        "mirror": rect(T().translate([0, 1.0, -1.2]).rotate([0, 1, 0], 20).scale([1.3, 1.0, 1]), mirror()),
        "frame": cube(T().translate([0, 1.0, -1.26]).rotate([0, 1, 0], 20).scale([1.38, 1.08, 0.04]),
                      diffuse([0.2, 0.12, 0.08])),
        "ball": sphere([0.45, 0.35, 0.3], 0.35, {"type": "roughplastic", "diffuse_reflectance": rgb([0.7, 0.1, 0.1]),
                                                  "alpha": 0.1}),
        "env": {"type": "constant", "radiance": rgb([0.08, 0.09, 0.11])},
        "lamp": sphere([-1.2, 2.2, 1.2], 0.25, diffuse([0, 0, 0]), area([40, 38, 34])),
    }
    # thin geometry: a fence of 0.008-radius wires in front, and one diagonal wire
    for i in range(15):
        x = -1.05 + 0.15 * i
        o[f"wire{i:02d}"] = cylinder([x, 0, 0.9], [x, 1.0, 0.9], 0.008, rough_metal("Al", 0.2))
    o["wire_top"] = cylinder([-1.1, 1.0, 0.9], [1.1, 1.0, 0.9], 0.008, rough_metal("Al", 0.2))
    o["wire_diag"] = cylinder([-1.1, 0.05, 1.0], [1.1, 0.95, 0.6], 0.005, diffuse([0.9, 0.9, 0.9]))
    cam = dict(origin=[0.3, 1.1, 2.9], target=[0, 0.6, 0], up=[0, 1, 0], fov=45)
    return o, cam, "mirror (perfect conductor) with frame, fence of thin wires, fine-detail bitmap floor", \
        "constant environment radiance (0.08, 0.09, 0.11) where nothing is hit"


def scene_sunsky():
    o = {
        "ground": floor(40, diffuse(checker([0.45, 0.42, 0.38], [0.25, 0.27, 0.22], 60))),
        "sky": sunsky([0.5, 0.45, 0.35], sun_scale=1.0, sky_scale=1.0),
        "cu": sphere([-0.9, 0.4, 0.0], 0.4, rough_metal("Cu", 0.05)),
        "al": sphere([0.0, 0.4, -0.6], 0.4, rough_metal("Al", 0.3)),
        "cr": cube(T().translate([0.9, 0.35, 0.1]).rotate([0, 1, 0], 30).scale(0.35), rough_metal("Cr", 0.12)),
        "glass": cube(T().translate([-0.2, 0.2, 0.8]).rotate([0, 1, 0], -20).scale(0.2), glass()),
    }
    cam = dict(origin=[0.2, 1.0, 3.6], target=[0, 0.4, 0], up=[0, 1, 0], fov=40)
    return o, cam, "sun + sky (sunsky emitter), rough copper/aluminium/chrome, glass cube, checker ground", \
        "sky radiance (sunsky) where nothing is hit"


def scene_interior():
    wall = diffuse([0.7, 0.68, 0.62])
    W, H, D = 2.0, 1.4, 2.0  # half width, height, half depth; window in the right wall (x = +W)
    o = {
        "floor": rect(T().rotate([1, 0, 0], -90).scale([W, D, 1]), diffuse(checker([0.55, 0.4, 0.3], [0.35, 0.25, 0.18], 6))),
        "ceil": rect(T().translate([0, 2 * H, 0]).rotate([1, 0, 0], 90).scale([W, D, 1]), wall),
        "back": rect(T().translate([0, H, -D]).scale([W, H, 1]), wall),
        "front": rect(T().translate([0, H, D]).rotate([0, 1, 0], 180).scale([W, H, 1]), wall),
        "left": rect(T().translate([-W, H, 0]).rotate([0, 1, 0], 90).scale([D, H, 1]), diffuse([0.3, 0.45, 0.6])),
        "sky": sunsky([0.8, 0.55, -0.25], sun_scale=1.0, sky_scale=1.0),
        "sofa": cube(T().translate([-1.3, 0.3, -1.2]).scale([0.6, 0.3, 0.5]), diffuse([0.6, 0.15, 0.1])),
        "ball": sphere([-0.2, 0.35, -0.5], 0.35, rough_metal("Cu", 0.25)),
        "table": cube(T().translate([0.6, 0.4, 0.3]).scale([0.35, 0.4, 0.35]), diffuse([0.8, 0.8, 0.75])),
    }
    # right wall with a window: x in the wall's local frame runs along z (depth)
    wy0, wy1, wz0, wz1 = 0.7, 2.1, -1.1, 0.5

    def rwall(z0, z1, y0, y1, name):
        o[name] = rect(T().translate([W, (y0 + y1) / 2, (z0 + z1) / 2]).rotate([0, 1, 0], -90)
                       .scale([(z1 - z0) / 2, (y1 - y0) / 2, 1]), wall)
    rwall(-D, wz0, 0, 2 * H, "r_back")
    rwall(wz1, D, 0, 2 * H, "r_front")
    rwall(wz0, wz1, 0, wy0, "r_below")
    rwall(wz0, wz1, wy1, 2 * H, "r_above")
    cam = dict(origin=[-1.5, 1.3, 1.85], target=[0.4, 0.8, -0.9], up=[0, 1, 0], fov=62)
    return o, cam, "closed room lit by sun + sky through a window in the right wall (mostly indirect)", \
        "sky radiance seen through the window"


def scene_roughmetal():
    tex = {"type": "bitmap", "bitmap": fine_texture(512, seed=11), "filter_type": "bilinear",
           "to_uv": T().scale([3, 3, 1])}
    o = {
        "floor": floor(4, {"type": "roughplastic", "diffuse_reflectance": tex, "alpha": 0.3}),
        "back": rect(T().translate([0, 2, -1.5]).scale([4, 2, 1]), diffuse(checker([0.5, 0.5, 0.5], [0.2, 0.2, 0.2], 16))),
        "disk_light": {"type": "disk", "to_world": T().translate([0.9, 1.25, -1.0]).rotate([0, 1, 0], -30).scale(0.3),
                       "emitter": area([14, 12, 10])},
        "top_light": rect(T().translate([-0.5, 3.0, 1.0]).rotate([1, 0, 0], 90).scale([0.8, 0.5, 1]),
                          diffuse([0, 0, 0]), area([6, 6.5, 7])),
        "env": {"type": "constant", "radiance": rgb([0.03, 0.03, 0.035])},
    }
    for i, (m, a) in enumerate([("Ag", 0.01), ("Au", 0.05), ("Cu", 0.12), ("Al", 0.25), ("Cr", 0.5)]):
        o[f"s{i}"] = sphere([-1.2 + 0.6 * i, 0.27, 0.15 * (i % 2)], 0.27, rough_metal(m, a))
    cam = dict(origin=[0, 1.0, 3.0], target=[0, 0.35, 0], up=[0, 1, 0], fov=40)
    return o, cam, "five metals from mirror-like (alpha 0.01) to rough (0.5), fine-detail rough-plastic floor, " \
        "visible disk light", "constant environment radiance (0.03, 0.03, 0.035)"


def scene_orbit_objects():
    o = {
        "floor": floor(5, diffuse(checker([0.7, 0.7, 0.7], [0.15, 0.15, 0.18], 10))),
        "glass": sphere([-0.5, 0.45, 0.0], 0.45, glass()),
        "metal": sphere([0.55, 0.4, -0.3], 0.4, rough_metal("Cu", 0.1)),
        "box": cube(T().translate([0.2, 0.25, 0.7]).rotate([0, 1, 0], 25).scale(0.25), diffuse([0.2, 0.5, 0.8])),
        "panel": rect(T().translate([0, 2.6, 0]).rotate([1, 0, 0], 90).scale([0.8, 0.8, 1]),
                      diffuse([0, 0, 0]), area([7, 7, 6.5])),
        "env": {"type": "constant", "radiance": rgb([0.05, 0.05, 0.06])},
    }
    return o, "glass + copper spheres, box, checker floor, overhead area light", \
        "constant environment radiance (0.05, 0.05, 0.06)"


def orbit_camera(f, n):
    ang = math.radians(-30 + 60 * f / max(1, n - 1))
    r, h = 3.3, 1.4
    return dict(origin=[r * math.sin(ang), h, r * math.cos(ang)], target=[0, 0.4, 0], up=[0, 1, 0], fov=45)


STILLS = {
    "mi_glass": (scene_glass, "aov", "gaussian"),
    "mi_mirror_thin": (scene_mirror_thin, "separate", "box"),
    "mi_sunsky": (scene_sunsky, "aov", "box"),
    "mi_interior": (scene_interior, "aov", "gaussian"),
    "mi_roughmetal": (scene_roughmetal, "aov", "gaussian"),
    # mi_glass again with the box filter: the same samples' noise, uncorrelated between pixels
    # (OIDN barely denoises the gaussian-filtered mi_glass)
    "mi_glass_box": (scene_glass, "aov", "box"),
}
QUICK = ["mi_glass", "mi_mirror_thin"]
SEQ_NAME = "mi_orbit"


# ---------------------------------------------------------------- rendering
def build(objects, cam, res, rfilter, integrator):
    d = {"type": "scene", "integrator": integrator,
         "sensor": {"type": "perspective", "fov": cam["fov"], "fov_axis": "x",
                    "to_world": T().look_at(origin=cam["origin"], target=cam["target"], up=cam["up"]),
                    "sampler": {"type": "independent"},
                    "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": rfilter}}}}
    d.update(objects)
    return mi.load_dict(d)


def aov_integrator(with_color=True):
    d = {"type": "aov", "aovs": AOVS}
    if with_color:
        d["integrator"] = {"type": "path", "max_depth": MAX_DEPTH}
    return d


def render_aov(objects, cam, res, rfilter, spp, seed, path):
    t = time.time()
    scene = build(objects, cam, res, rfilter, aov_integrator())
    mi.render(scene, spp=spp, seed=seed)
    scene.sensors()[0].film().write(str(path))
    return time.time() - t


def render_separate(objects, cam, res, rfilter, spp, seed, folder):
    """color.exr from `path`; albedo/normal/position/depth.exr from an aov-only render (same spp, seed)."""
    t = time.time()
    folder.mkdir(parents=True, exist_ok=True)
    scene = build(objects, cam, res, rfilter, {"type": "path", "max_depth": MAX_DEPTH})
    img = mi.render(scene, spp=spp, seed=seed)
    mi.Bitmap(img).write(str(folder / "color.exr"))
    scene = build(objects, cam, res, rfilter, aov_integrator(with_color=False))
    a = np.array(mi.render(scene, spp=spp, seed=seed))  # no colour: albedo3, nn3, pos3, dd1, si1
    assert a.shape[-1] == 11, a.shape
    parts = {"albedo": a[..., 0:3], "normal": a[..., 3:6], "position": a[..., 6:9], "depth": a[..., 9:10],
             "shape_index": a[..., 10:11]}
    for name, arr in parts.items():
        names = ["Y"] if arr.shape[-1] == 1 else None
        bmp = mi.Bitmap(np.ascontiguousarray(arr.astype(np.float32)),
                        pixel_format=mi.Bitmap.PixelFormat.Y if names else mi.Bitmap.PixelFormat.RGB)
        bmp.write(str(folder / f"{name}.exr"))
    (folder / "DONE").write_text("ok\n")
    return time.time() - t


def camera_matrices(cam, res):
    """World->camera (Mitsuba look_at: +z forward, +x LEFT, +y up) and the projection to pixels."""
    m = np.array(T().look_at(origin=cam["origin"], target=cam["target"], up=cam["up"]).matrix, dtype=np.float64)
    return np.linalg.inv(m), math.tan(math.radians(cam["fov"]) / 2)


def project(pos, cam, res):
    """World positions (H, W, 3) -> continuous pixel coordinates (x right, y down, pixel centre at +0.5)."""
    w2c, t = camera_matrices(cam, res)
    p = pos.reshape(-1, 3) @ w2c[:3, :3].T + w2c[:3, 3]
    z = np.maximum(p[:, 2], 1e-6)
    px = (0.5 - 0.5 * p[:, 0] / (z * t)) * res  # +x is left in Mitsuba's camera frame
    py = (0.5 - 0.5 * p[:, 1] / (z * t)) * res  # square image: same tan for y
    return np.stack([px, py], -1).reshape(pos.shape[:-1] + (2,))


def read_pos(path):
    import OpenEXR
    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.parts[0].channels
        return np.stack([ch[f"pos.{c}"].pixels for c in "XYZ"], -1).astype(np.float64), ch["si.I"].pixels


def write_motion(path, motion):
    import OpenEXR
    h, w, _ = motion.shape
    hdr = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    chans = {"motion.X": np.ascontiguousarray(motion[..., 0].astype(np.float32)),
             "motion.Y": np.ascontiguousarray(motion[..., 1].astype(np.float32))}
    with OpenEXR.File(hdr, chans) as f:
        f.write(str(path))


def render_still(name, layout, objects, cam, res, rfilter, jobs, d):
    """Every (spp, seed, stem) job of one still into folder d, in the scene's layout ("aov": one
    EXR per job; else a folder of separate EXRs), skipping what is done. Returns the manifest's
    `files` entries and the seconds of the renders run now."""
    d.mkdir(parents=True, exist_ok=True)
    times, files = {}, {}
    for spp, seed, stem in jobs:
        if layout == "aov":
            target = d / f"{stem}.exr"
            if not done(target):
                log(f"mitsuba {name} {stem} ...")
                times[stem] = render_aov(objects, cam, res, rfilter, spp, seed, target)
                log(f"mitsuba {name} {stem} {times[stem]:.1f}s")
            files[stem] = {"spp": spp, "seed": seed, "file": target.name, "channels": exr_channels(target)}
        else:
            folder = d / stem
            if not done(folder / "DONE"):
                log(f"mitsuba {name} {stem} ...")
                times[stem] = render_separate(objects, cam, res, rfilter, spp, seed, folder)
                log(f"mitsuba {name} {stem} {times[stem]:.1f}s")
            files[stem] = {"spp": spp, "seed": seed, "folder": stem,
                           "files": {p.name: exr_channels(p) for p in sorted(folder.glob("*.exr"))}}
    return files, times


def main():
    a, mode, root, names = parse_render_args("mitsuba", QUICK, STILLS)
    res = mode["res"]
    for name in names:
        fn, layout, rfilter = STILLS[name]
        objects, cam, what, bg = fn()
        d = root / name
        files, times = render_still(name, layout, objects, cam, res, rfilter, still_jobs(mode), d)
        man_path = d / "manifest.json"
        write_manifest(man_path, {
            "scene": name, "renderer": "mitsuba", "version": mi.__version__, "variant": VARIANT,
            "description": what, "resolution": [res, res], "pixel_filter": rfilter,
            "integrator": f"aov(path max_depth={MAX_DEPTH})" if layout == "aov" else f"path max_depth={MAX_DEPTH} + aov",
            "aovs": AOVS, "layout": layout, "files": files, "reference": f"ref{mode['ref_spp']:04d}",
            "render_seconds": merged_render_seconds(man_path, times), "conventions": CONVENTIONS, "background": bg, "camera": cam,
        })

    # ------------------------------------------------ sequence
    if (a.scenes and SEQ_NAME not in a.scenes.split(",")) or not mode["seq_frames"]:
        return
    objects, what, bg = scene_orbit_objects()
    n, sres, rspp = mode["seq_frames"], mode["seq_res"], mode["seq_ref_spp"]
    d = root / SEQ_NAME
    (d / "frames").mkdir(parents=True, exist_ok=True)
    (d / "ref").mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    frames = []
    max_reproj = 0.0
    for f in range(n):
        cam = orbit_camera(f, n)
        fr, rf, mo = d / "frames" / f"{f:04d}.exr", d / "ref" / f"{f:04d}.exr", d / "frames" / f"{f:04d}_motion.exr"
        if not done(fr):
            render_aov(objects, cam, sres, "box", 1, SEED_SEQ + f, fr)
        if not done(rf):
            log(f"mitsuba {SEQ_NAME} frame {f} ref ...")
            render_aov(objects, cam, sres, "box", rspp, SEED_SEQ_REF + f, rf)
        for s in mode["seq_spp"]:
            if s == 1:
                continue
            fs_ = d / seq_spp_folder(s) / f"{f:04d}.exr"
            fs_.parent.mkdir(parents=True, exist_ok=True)
            if not done(fs_):
                render_aov(objects, cam, sres, "box", s, SEED_SEQ_SPP + 1000 * s + f, fs_)
        if not done(mo):
            # motion from the REFERENCE positions would be cleaner, but a user has the 1-spp AOVs:
            # use the frame's own (1-spp, box-filtered => one sample's hit point) positions.
            pos, si = read_pos(fr)
            cur = project(pos, cam, sres)
            yy, xx = np.mgrid[0:sres, 0:sres] + 0.5
            hit = np.linalg.norm(pos, axis=-1) > 0
            err = np.abs(cur - np.stack([xx, yy], -1))[hit]
            max_reproj = max(max_reproj, float(np.median(err)) if err.size else 0.0)
            prev = project(pos, orbit_camera(max(f - 1, 0), n), sres)
            motion = np.where(hit[..., None], prev - cur, 0.0)
            write_motion(mo, motion)
        for s in mode["seq_spp"]:  # the same camera: the 1-spp frame's motion serves every spp
            if s != 1 and not done(d / seq_spp_folder(s) / mo.name):
                shutil.copyfile(mo, d / seq_spp_folder(s) / mo.name)
        frames.append({"frame": f, "file": f"frames/{fr.name}", "motion": f"frames/{mo.name}",
                       "reference": f"ref/{rf.name}", "seed": SEED_SEQ + f, "ref_seed": SEED_SEQ_REF + f,
                       "camera": cam})
    log(f"mitsuba {SEQ_NAME} {n} frames {time.time() - t0:.1f}s")
    write_manifest(d / "manifest.json", {
        "scene": SEQ_NAME, "renderer": "mitsuba", "version": mi.__version__, "variant": VARIANT,
        "description": what + "; camera orbits 60 degrees, static scene", "resolution": [sres, sres],
        "pixel_filter": "box", "spp": 1, "reference_spp": rspp, "frames": frames, "layout": "aov-sequence",
        "spp_folders": {str(s): seq_spp_folder(s) for s in mode["seq_spp"]},
        "aovs": AOVS, "channels": exr_channels(d / "frames" / "0000.exr"),
        "motion_channels": exr_channels(d / "frames" / "0000_motion.exr"),
        "reference_channels": exr_channels(d / "ref" / "0000.exr"),
        "conventions": dict(CONVENTIONS, motion=(
            "frames/NNNN_motion.exr channels motion.X, motion.Y: pixel offset from the pixel's position in "
            "the CURRENT frame to where its surface point (pos.* of this frame's 1-spp AOV) projects in the "
            "PREVIOUS frame's camera: prev_xy = (x+0.5, y+0.5) + motion, x right, y down; 0 on frame 0 and "
            "where nothing is hit. Static scene, so camera motion is all there is.")),
        "median_reprojection_error_px": round(max_reproj, 4), "background": bg,
    })


CONVENTIONS = {
    "color": "R,G,B top-level channels: linear radiance (mean over spp); integrator.R/G/B/A duplicates the "
             "nested path integrator's output with alpha",
    "albedo": "albedo.R/G/B: the first hit's BSDF albedo (0 for emitters' black BSDF and for the background)",
    "normal": "nn.X/Y/Z: sh_normal, WORLD space shading normal at the first hit, unit length (per sample, "
              "then filtered/averaged: not renormalised), 0 on the background",
    "position": "pos.X/Y/Z: world-space first hit position, 0 on the background",
    "depth": "dd.T: distance along the camera ray to the first hit (si.t), not view z; 0 on the background",
    "shape_index": "si.I: index of the hit shape in the scene (float), 0 on the background as well",
    "world": "y up; camera +z forward, +x left (Mitsuba look_at)",
    "filter": "AOVs are reconstructed with the same pixel filter as the colour",
}

if __name__ == "__main__":
    main()
