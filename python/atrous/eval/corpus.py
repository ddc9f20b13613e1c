"""Denoising quality on the third-party corpus (scripts/corpus/render.py): noisy vs OIDN vs atrous.

    .venv/bin/python -m atrous.eval corpus                      # out/corpus/full if it has scenes, else quick
    .venv/bin/python -m atrous.eval corpus --corpus out/corpus/quick --crops
    .venv/bin/python -m atrous.eval corpus --preview            # also tonemapped PNGs of every reference

Runs in the project venv (.venv: numpy, pyoidn, atrous). The EXRs are read with the OpenEXR Python
bindings: from .venv if installed there, else from .venv-corpus's site-packages (same Python 3.11).
The buffers are fed to atrous.denoise by hand from each renderer's own layout (one loader per
layout below). Neither renderer writes a variance, so the atrous filters estimate the noise.

relMSE = mean((x - ref)^2 / (ref^2 + 1e-2)) over pixels and channels. Writes <corpus>/quality.json
and prints a markdown table; --crops writes <corpus>/crops/<scene>_<spp>.png
(noisy | OIDN | eaw | sure | reference).
"""
import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

import atrous
from atrous.names import EAW, SURE

# The atrous filters run on the corpus (their names from the library's registry) and the columns.
FILTERS = (EAW, SURE)
COLUMNS = ("noisy", "oidn") + FILTERS

ROOT = Path.cwd()  # the repository root: run from it (its out/ and build/ are the defaults)

import OpenEXR  # noqa: E402  (python/requirements.txt puts it in .venv, as in .venv-corpus)


def read_exr(path):
    """{channel name: H x W float32} over all parts of an EXR."""
    out = {}
    with OpenEXR.File(str(path), separate_channels=True) as f:
        for p in f.parts:
            for k, c in p.channels.items():
                out[k] = np.asarray(c.pixels, np.float32)
    return out


def _stack(ch, names):
    return np.ascontiguousarray(np.stack([ch[n] for n in names], -1).astype(np.float32))


def _unit(n):
    ln = np.linalg.norm(n, axis=-1, keepdims=True)
    return np.where(ln > 1e-6, n / np.maximum(ln, 1e-6), 0.0).astype(np.float32)


# ---------------------------------------------------------------- loaders, one per layout
def load_mitsuba_aov(path, pixel_filter="gaussian"):
    """Mitsuba 3 `aov` integrator EXR (AOVs albedo:albedo,nn:sh_normal,pos:position,dd:depth,si:shape_index)."""
    ch = read_exr(path)
    b = {"color": _stack(ch, ["R", "G", "B"]),
         "albedo": _stack(ch, ["albedo.R", "albedo.G", "albedo.B"]),
         "normal": _unit(_stack(ch, ["nn.X", "nn.Y", "nn.Z"])),
         "position": _stack(ch, ["pos.X", "pos.Y", "pos.Z"]),
         "depth": ch["dd.T"].astype(np.float32)}
    if pixel_filter == "box" and "si.I" in ch:  # a filtered (gaussian) shape index is fractional: no ids then
        bg = (b["depth"] <= 0)
        sid = np.where(bg, -1.0, np.round(ch["si.I"]))
        b["ids"] = np.ascontiguousarray(np.stack([sid, sid, np.zeros_like(sid)], -1).astype(np.float32))
    return b


def load_mitsuba_separate(folder, pixel_filter="box"):
    """Mitsuba 3 separate files: color.exr (R,G,B) + albedo/normal/position.exr (R,G,B), depth.exr (Y)."""
    folder = Path(folder)
    rgb = lambda n: _stack(read_exr(folder / f"{n}.exr"), ["R", "G", "B"])  # noqa: E731
    b = {"color": rgb("color"), "albedo": rgb("albedo"), "normal": _unit(rgb("normal")),
         "position": rgb("position"), "depth": read_exr(folder / "depth.exr")["Y"]}
    si = folder / "shape_index.exr"
    if pixel_filter == "box" and si.exists():
        s = read_exr(si)["Y"]
        sid = np.where(b["depth"] <= 0, -1.0, np.round(s))
        b["ids"] = np.ascontiguousarray(np.stack([sid, sid, np.zeros_like(sid)], -1).astype(np.float32))
    return b


def load_blender(path, layer="ViewLayer"):
    """Blender (Cycles) multilayer EXR: one part per pass, channels '<layer>.<pass>.<chan>'."""
    ch = read_exr(path)
    p = lambda name, cs: _stack(ch, [f"{layer}.{name}.{c}" for c in cs])  # noqa: E731
    depth = ch[f"{layer}.Depth.Z"]
    bg = depth >= 1e9  # the world: Z = 1e10
    ob = ch[f"{layer}.Object Index.X"]
    ma = ch[f"{layer}.Material Index.X"]
    b = {"color": p("Combined", "RGB"),
         "albedo": p("Denoising Albedo", "RGB"),
         "normal": _unit(p("Denoising Normal", "XYZ")),
         "position": p("Position", "XYZ"),
         "depth": np.where(bg, 0.0, depth).astype(np.float32),
         "emission": p("Emission", "RGB"),
         "ids": np.ascontiguousarray(np.stack([np.where(ob > 0, ob, -1), np.where(ob > 0, ma, -1),
                                               np.zeros_like(ob)], -1).astype(np.float32))}
    v = p("Vector", "XYZW")
    b["motion"] = np.ascontiguousarray(np.stack([v[..., 0], -v[..., 1]], -1))  # prev - cur, y down
    return b


def load_luxcore(folder):
    """LuxCoreRender film outputs, one file each (scripts/corpus/luxcore_stills.py): RGB, ALBEDO,
    AVG_SHADING_NORMAL, POSITION, DEPTH (R, G, B channels; the sky at +inf depth and position)."""
    folder = Path(folder)
    rgb = lambda n: _stack(read_exr(folder / f"{n}.exr"), ["R", "G", "B"])  # noqa: E731
    depth = read_exr(folder / "DEPTH.exr")["R"]
    sky = ~np.isfinite(depth)
    pos = rgb("POSITION")
    return {"color": rgb("RGB"), "albedo": rgb("ALBEDO"), "normal": _unit(np.nan_to_num(rgb("AVG_SHADING_NORMAL"))),
            "position": np.where(sky[..., None], 0.0, pos).astype(np.float32),
            "depth": np.where(sky, 0.0, depth).astype(np.float32)}


def load_mitsuba_motion(path):
    ch = read_exr(path)
    return _stack(ch, ["motion.X", "motion.Y"])


def load_still(scene_dir, man, stem):
    layout = man["layout"]
    entry = man["files"][stem]
    if layout == "aov":
        return load_mitsuba_aov(scene_dir / entry["file"], man["pixel_filter"])
    if layout == "separate":
        return load_mitsuba_separate(scene_dir / entry["folder"], man["pixel_filter"])
    if layout == "blender-multilayer-exr":
        return load_blender(scene_dir / entry["file"])
    if layout == "luxcore":
        return load_luxcore(scene_dir / entry["folder"])
    raise ValueError(f"unknown layout {layout}")


def load_frame(scene_dir, man, fr, ref=False):
    rel = fr["reference"] if ref else fr["file"]
    if man["renderer"] == "mitsuba":
        b = load_mitsuba_aov(scene_dir / rel, man["pixel_filter"])
        if not ref:
            b["motion"] = load_mitsuba_motion(scene_dir / fr["motion"])
        return b
    return load_blender(scene_dir / rel)


# ---------------------------------------------------------------- metrics and methods
def relmse(x, ref):
    """atrous.relmse (docs/eval.md), as `atrous compare` prints it; imported when first used."""
    import atrous

    return atrous.relmse(x, ref)


def run_methods(b, oidn, want):
    import atrous
    out = {"noisy": b["color"]}
    feats = {k: b.get(k) for k in ("albedo", "normal", "position", "depth", "ids", "emission")}
    # Cycles' Denoising Albedo carries the emitter's radiance (30 on the visible panel): clip to
    # [0, 1] as OIDN's wrapper does, so both denoisers get the same albedo.
    feats["albedo"] = np.ascontiguousarray(np.clip(feats["albedo"], 0.0, 1.0))
    times = {}
    if oidn is not None and "oidn" in want:
        t = time.perf_counter()
        out["oidn"] = np.asarray(oidn(b), np.float32)
        times["oidn"] = time.perf_counter() - t
    for m in FILTERS:
        if m in want:
            t = time.perf_counter()
            out[m] = np.asarray(atrous.denoise(b["color"], method=m, **feats), np.float32)
            times[m] = time.perf_counter() - t
    return out, times


def tonemap(img):
    return atrous.tonemap(img, np.uint8)  # the library's one 8-bit preview


def save_png(path, rgb8):
    from PIL import Image
    Image.fromarray(rgb8).save(path)


def crop_strip(images, ref, size):
    """Side by side crops (the crop window with the most reference detail), 2x nearest upscaled."""
    h, w = ref.shape[:2]
    s = min(size, h, w)
    lum = ref.mean(-1)
    best, by, bx = -1.0, 0, 0
    for y in range(0, h - s + 1, max(1, s // 4)):
        for x in range(0, w - s + 1, max(1, s // 4)):
            win = lum[y:y + s, x:x + s]
            g = np.abs(np.diff(win, axis=0)).mean() + np.abs(np.diff(win, axis=1)).mean()
            if g > best:
                best, by, bx = g, y, x
    tiles = [tonemap(im[by:by + s, bx:bx + s]) for im in images]
    gap = np.full((s, 2, 3), 255, np.uint8)
    strip = np.concatenate(sum([[t, gap] for t in tiles], [])[:-1], axis=1)
    return np.repeat(np.repeat(strip, 2, 0), 2, 1)


# ---------------------------------------------------------------- main
def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m atrous.eval corpus", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", default=None, help="corpus root (default out/corpus/full, else out/corpus/quick)")
    ap.add_argument("--methods", default=",".join(COLUMNS))
    ap.add_argument("--crops", action="store_true", help="write side-by-side PNG crops")
    ap.add_argument("--crop-size", type=int, default=96)
    ap.add_argument("--preview", action="store_true", help="tonemapped PNG of every reference")
    ap.add_argument("--scenes", default="", help="comma-separated scene names")
    ap.add_argument("--no-sequences", action="store_true")
    ap.add_argument("--out", default=None, help="JSON path (default <corpus>/quality.json)")
    a = ap.parse_args(argv)
    corpus = Path(a.corpus) if a.corpus else None
    if corpus is None:
        full = ROOT / "out" / "corpus" / "full"
        corpus = full if any(full.glob("*/*/manifest.json")) else ROOT / "out" / "corpus" / "quick"
    want = a.methods.split(",")
    oidn = None
    if "oidn" in want:
        try:
            from atrous.eval import load_oidn
            oidn, note = load_oidn()
            if oidn is None:
                print(f"quality: OIDN skipped: {note}", file=sys.stderr)
        except Exception as e:  # pragma: no cover
            print(f"quality: OIDN skipped: {e}", file=sys.stderr)
    cols = [m for m in COLUMNS if m in want and (m != "oidn" or oidn is not None)]
    only = set(a.scenes.split(",")) if a.scenes else None
    results = []
    crops_dir = corpus / "crops"
    for man_path in sorted(corpus.glob("*/*/manifest.json")):
        man = json.loads(man_path.read_text())
        sd = man_path.parent
        name = man["scene"]
        if only and name not in only:
            continue
        if "frames" in man:
            if a.no_sequences:
                continue
            results.append(eval_sequence(sd, man, oidn, want, cols))
            continue
        ref_stem = man["reference"]
        if ref_stem not in man["files"]:
            continue
        ref = load_still(sd, man, ref_stem)["color"]
        if a.preview:
            crops_dir.mkdir(parents=True, exist_ok=True)
            save_png(crops_dir / f"{name}_reference.png", tonemap(ref))
        for stem, e in sorted(man["files"].items()):
            if stem == ref_stem:
                continue
            b = load_still(sd, man, stem)
            imgs, times = run_methods(b, oidn, want)
            row = {"scene": name, "renderer": man["renderer"], "layout": man["layout"], "spp": e["spp"],
                   "ref_spp": man["files"][ref_stem]["spp"], "resolution": man["resolution"],
                   "relmse": {m: relmse(imgs[m], ref) for m in cols},
                   "seconds": {m: round(t, 4) for m, t in times.items()},
                   "buffers": sorted(k for k in b if k != "color")}
            results.append(row)
            print(fmt_row(row, cols), flush=True)
            if a.crops:
                crops_dir.mkdir(parents=True, exist_ok=True)
                order = [m for m in COLUMNS if m in imgs]
                save_png(crops_dir / f"{name}_spp{e['spp']:04d}.png",
                         crop_strip([imgs[m] for m in order] + [ref], ref, a.crop_size))
    out = Path(a.out) if a.out else corpus / "quality.json"
    out.write_text(json.dumps({"corpus": str(corpus), "columns": cols, "results": results}, indent=2) + "\n")
    print()
    print(table(results, cols))
    print(f"\nwrote {out}")


def eval_sequence(sd, man, oidn, want, cols):
    """Per-frame 1-spp relMSE against the per-frame references, averaged; plus SVGF with the motion."""
    import atrous
    from atrous.sequence import SVGF

    per = {m: [] for m in cols + [SVGF]}
    svgf = atrous.Svgf("cpu")
    for fr in man["frames"]:
        b = load_frame(sd, man, fr)
        ref = load_frame(sd, man, fr, ref=True)["color"]
        imgs, _ = run_methods(b, oidn, want)
        for m in cols:
            per[m].append(relmse(imgs[m], ref))
        s = svgf.denoise_frame(b["color"], albedo=b["albedo"], normal=b["normal"],
                               depth=np.ascontiguousarray(np.repeat(b["depth"][..., None], 3, -1)),
                               ids=b.get("ids"), motion=b["motion"], emission=b.get("emission"))
        per[SVGF].append(relmse(np.asarray(s, np.float32), ref))
    half = len(man["frames"]) // 2
    row = {"scene": man["scene"], "renderer": man["renderer"], "layout": man["layout"], "spp": 1,
           "ref_spp": man["reference_spp"], "resolution": man["resolution"], "frames": len(man["frames"]),
           "relmse": {m: float(np.mean(v)) for m, v in per.items()},
           "relmse_second_half": {m: float(np.mean(v[half:])) for m, v in per.items()},
           "relmse_per_frame": per}
    print(fmt_row(row, cols + [SVGF]), flush=True)
    return row


def fmt_row(r, cols):
    v = " | ".join(f"{r['relmse'][m]:.4g}" if m in r["relmse"] else "-" for m in cols)
    extra = f" ({r['frames']} frames)" if "frames" in r else ""
    return f"| {r['scene']}{extra} | {r['spp']} | {r['ref_spp']} | {v} |"


def table(results, cols):
    from atrous.sequence import SVGF

    allc = cols + ([SVGF] if any("frames" in r for r in results) else [])
    lines = ["| scene | spp | ref spp | " + " | ".join(allc) + " |",
             "|---|---|---|" + "---|" * len(allc)]
    lines += [fmt_row(r, allc) for r in results]
    return "\n".join(lines)

