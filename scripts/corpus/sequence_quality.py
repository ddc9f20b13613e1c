#!/usr/bin/env python3
"""relMSE and temporal relMSE of `atrous denoise --sequence` runs (any flags) beside OIDN high per
frame, on the third-party corpus's animations and on atrous's own rendered sequences
(docs/temporal.md, docs/quality.md "Sequences").

    .venv/bin/python scripts/corpus/sequence_quality.py --corpus out/corpus/full --own out/heldout_seq \\
        temporal="" per_frame_auto="--method auto" svgf="--method svgf"

With --strips DIR it also writes, per sequence, DIR/<sequence>.png (the middle frame: noisy | each
variant | OIDN per frame | reference) and DIR/<sequence>.gif (every frame).

Each VARIANT=FLAGS runs `atrous denoise --sequence SEQ --out DIR FLAGS` on the sequence as the
renderer wrote it ("" is what a user gets without --method). Corpus sequences are the scenes of
<corpus>/{cycles,mitsuba}/ whose manifest lists frames, at each spp of its spp_folders (frames/ at
1 spp, frames_s0004/ ..., all against ref/); own sequences are
`atrous render --frames N --reference-spp S` folders (frame_NNNN/ with reference.exr), e.g.

    atrous render --scene cornell-moving --frames 20 --spp 1 --reference-spp 256 --width 128 --height 128 --out out/heldout_seq/cornell_moving
    atrous render --scene cornell-spheres --camera-path orbit --frames 20 --spp 1 --reference-spp 256 --width 128 --height 128 --out out/heldout_seq/spheres_orbit

OIDN (pyoidn, HDR, colour + albedo + normal) runs per frame on the buffers the corpus loaders read
(atrous.eval corpus (python/atrous/eval/corpus.py)) or on the frame's color/albedo/normal.exr. The metrics are `atrous
compare --sequence`'s, over all pixels and again with the pixels that show a light (reference
luminance above LIGHT_LUM in any frame, grown by a pixel) left out, and the reference-free flicker
measure (`compare --input SEQ`: each frame against the one before it, warped by the noisy
sequence's motion) with how often it orders two variants as the temporal relMSE does. Runs in the
project venv (.venv: numpy, pyoidn, atrous).
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from atrous.eval import corpus as Q  # the corpus loaders

ROOT = Path(__file__).resolve().parents[2]


def corpus_sequences(corpus: Path):
    """(name, scene dir, frames folder, reference folder, spp) per corpus sequence and spp."""
    for renderer in ("cycles", "mitsuba"):
        for d in sorted((corpus / renderer).glob("*")):
            man = d / "manifest.json"
            if not man.exists():
                continue
            m = json.loads(man.read_text())
            if "frames" not in m or not (d / "frames").is_dir():
                continue
            for spp, folder in sorted(m.get("spp_folders", {"1": "frames"}).items(), key=lambda kv: int(kv[0])):
                if (d / folder).is_dir():
                    yield f"{d.name}_{int(spp)}spp", d, d / folder, d / "ref", int(spp)


def own_sequences(own: Path):
    for d in sorted(own.glob("*")):
        if (d / "frame_0000" / "reference.exr").exists():
            yield d.name, d, d, d, None


def frame_buffers(scene: Path, folder: Path, ref: bool = False):
    """(name, buffers) per frame in order: the noisy frame's color, albedo and normal at `folder`'s
    spp through the corpus loaders (atrous.eval corpus (python/atrous/eval/corpus.py)), or an own sequence's files; with
    ref=True the reference's color. name: the frame_NNNN that `atrous denoise --sequence` writes."""
    import atrous

    if (scene / "manifest.json").exists():
        man = json.loads((scene / "manifest.json").read_text())
        for fr in man["frames"]:
            fr = dict(fr, file=f"{folder.name}/{Path(fr['file']).name}")  # the spp's folder
            yield f"frame_{fr['frame']:04d}", Q.load_frame(scene, man, fr, ref=ref)
        return
    for d in sorted(scene.glob("frame_*")):
        rd = lambda k: np.asarray(atrous.read_image(str(d / f"{k}.exr")), np.float32)  # noqa: E731
        yield d.name, ({"color": rd("reference")} if ref else {k: rd(k) for k in ("color", "albedo", "normal")})


def oidn_per_frame(scene: Path, folder: Path, out: Path):
    """OIDN high on each frame, as the evaluation runs it (atrous.eval.oidn_inputs)."""
    import atrous
    import pyoidn
    from atrous.eval import oidn_inputs

    out.mkdir(parents=True, exist_ok=True)
    for name, b in frame_buffers(scene, folder):
        o = pyoidn.denoise(*oidn_inputs(b), hdr=True, quality="high")
        atrous.write_image(str(out / f"{name}.exr"), np.asarray(o, np.float32))


def light_mask(refs):
    """Pixels that show a light in any frame: reference luminance above LIGHT_LUM (a white diffuse
    surface under these scenes' lights stays below it; a visible emitter and its mirror images do
    not), grown by one pixel for the partly covered edge."""
    lum = np.stack([r[..., :3] @ np.array([0.2126, 0.7152, 0.0722], np.float32) for r in refs])
    m = (lum > LIGHT_LUM).any(0)
    g = m.copy()
    g[1:] |= m[:-1]
    g[:-1] |= m[1:]
    g[:, 1:] |= m[:, :-1]
    g[:, :-1] |= m[:, 1:]
    return g


LIGHT_LUM = 1.5


def masked_copy(src: Path, dst: Path, refs, mask):
    """src's frame_NNNN.exr with the masked pixels set to the reference (no error there)."""
    import atrous

    dst.mkdir(parents=True, exist_ok=True)
    for k, f in enumerate(sorted(src.glob("frame_*.exr"))):
        img = np.array(atrous.read_image(str(f)), np.float32)
        img[mask] = refs[k][..., :3][mask]
        atrous.write_image(str(dst / f.name), img)


def tonemap(img):
    import atrous

    return atrous.tonemap(img[..., :3], np.uint8)  # the library's one 8-bit preview


def write_strips(strips: Path, name: str, columns):
    """strips/<name>.png (the middle frame, 2x nearest-neighbour) and strips/<name>.gif (every frame,
    8 fps, 1x): the columns side by side, each labelled. columns: (label, list of frames)."""
    strips.mkdir(parents=True, exist_ok=True)
    for scale, frames_wanted, out in ((2, [len(columns[0][1]) // 2], "png"), (1, range(len(columns[0][1])), "gif")):
        _strip(strips / f"{name}.{out}", columns, scale, frames_wanted)


def _strip(path: Path, columns, scale, frames_wanted):
    from PIL import Image, ImageDraw

    images = []
    for k in frames_wanted:
        tiles = []
        for label, frames in columns:
            t = Image.fromarray(tonemap(frames[k]))
            t = t.resize((t.width * scale, t.height * scale), Image.NEAREST)
            canvas = Image.new("RGB", (t.width, t.height + 16), (0, 0, 0))
            canvas.paste(t, (0, 16))
            ImageDraw.Draw(canvas).text((3, 2), label, fill=(255, 255, 255))
            tiles.append(canvas)
        row = Image.new("RGB", (sum(t.width for t in tiles) + 2 * (len(tiles) - 1), tiles[0].height), (40, 40, 40))
        x = 0
        for t in tiles:
            row.paste(t, (x, 0))
            x += t.width + 2
        images.append(row)
    if path.suffix == ".png":
        images[0].save(path)
    else:
        images[0].save(path, save_all=True, append_images=images[1:], duration=125, loop=0)


def atrous_write(path, img):
    import atrous

    atrous.write_image(str(path), np.ascontiguousarray(img, np.float32))


def compare(cli, ref, outs, guide=None):
    """`atrous compare --sequence REF OUTS --json`; with guide (the noisy sequence) also the
    reference-free flicker measure, the frames placed by the guide's motion (--input)."""
    extra = ["--input", str(guide)] if guide else []
    r = subprocess.run([cli, "compare", "--sequence", str(ref)] + [str(o) for o in outs] + ["--json", "--no-flip",
                       "--no-cvvdp"] + extra, capture_output=True, text=True, check=True)
    return json.loads(r.stdout)


def pair_agreement(r, names, a="temporal_relmse", b="flicker"):
    """Of the pairs of variants, how many `a` and `b` order alike (ties count half)."""
    agree = pairs = 0.0
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            da = r[names[i]][a] - r[names[j]][a]
            db = r[names[i]][b] - r[names[j]][b]
            pairs += 1
            agree += 1.0 if da * db > 0 else 0.5 if da * db == 0 else 0.0
    return agree, pairs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", type=Path, help="the third-party corpus (scripts/corpus/render.py --full)")
    ap.add_argument("--own", type=Path, help="a folder of `atrous render --frames` sequences with references")
    ap.add_argument("--cli", default=str(ROOT / "build" / "atrous"))
    ap.add_argument("--json", type=Path, help="write the figures here too")
    ap.add_argument("--strips", type=Path,
                    help="write DIR/<sequence>.png (the middle frame) and .gif (all frames): noisy | variants | "
                         "OIDN per frame | reference")
    ap.add_argument("--only", nargs="+", help="the sequences whose name holds one of these strings (e.g. 16spp)")
    ap.add_argument("variants", nargs="+", help="NAME=FLAGS")
    a = ap.parse_args()
    variants = [v.split("=", 1) for v in a.variants]
    seqs = []
    if a.corpus:
        seqs += list(corpus_sequences(a.corpus))
    if a.own:
        seqs += list(own_sequences(a.own))
    if a.only:
        seqs = [s for s in seqs if any(o in s[0] for o in a.only)]
    if not seqs:
        sys.exit("sequence_quality: no sequence found (give --corpus and/or --own)")
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene, seq, ref, spp in seqs:
            outs = []
            for vname, flags in variants:
                o = Path(tmp) / name / vname
                subprocess.run([a.cli, "denoise", "--sequence", str(seq), "--out", str(o)] + shlex.split(flags),
                               check=True, stdout=subprocess.DEVNULL)
                outs.append(o)
            o = Path(tmp) / name / "oidn_high_per_frame"
            oidn_per_frame(scene, seq, o)
            outs.append(o)
            rows = compare(a.cli, ref, outs, guide=seq)
            r = {Path(x["path"]).name: {k: x[k] for k in ("relmse", "temporal_relmse", "psnr", "flicker")}
                 for x in rows["sequences"]}
            r["reference_flicker"] = rows.get("reference_flicker")
            # The same with the pixels that show a light left out (their error set to 0, the means
            # taken over the other pixels).
            refs = [np.asarray(b["color"], np.float32) for _, b in frame_buffers(scene, seq, ref=True)]
            mask = light_mask(refs)
            keep = 1.0 - float(mask.mean())
            mref = Path(tmp) / name / "masked_ref"
            mref.mkdir(parents=True)
            for k, rimg in enumerate(refs):
                atrous_write(mref / f"frame_{k:04d}.exr", rimg[..., :3])
            mouts = []
            for o in outs:
                masked_copy(o, Path(tmp) / name / ("masked_" + o.name), refs, mask)
                mouts.append(Path(tmp) / name / ("masked_" + o.name))
            for x in compare(a.cli, mref, mouts)["sequences"]:
                n = Path(x["path"]).name[len("masked_"):]
                r[n]["relmse_no_lights"] = x["relmse"] / keep
                r[n]["temporal_relmse_no_lights"] = x["temporal_relmse"] / keep
            r["light_pixels"] = float(mask.mean())
            results[name] = r
            if a.strips:
                import atrous

                cols = [("noisy", [b["color"] for _, b in frame_buffers(scene, seq)])]
                for o in outs:
                    cols.append((o.name.replace("_per_frame", "").replace("oidn_high", "OIDN high/frame"),
                                 [np.asarray(atrous.read_image(str(f)), np.float32)
                                  for f in sorted(o.glob("frame_*.exr"))]))
                cols.append(("reference", refs))
                write_strips(a.strips, name, cols)
    names = [v[0] for v in variants] + ["oidn_high_per_frame"]
    for key, title in (("", "all pixels"), ("_no_lights", "the pixels that show a light left out")):
        print(f"\nrelMSE / temporal relMSE, {title}:\n")
        print("| sequence | " + " | ".join(names) + " |")
        print("|---" * (len(names) + 1) + "|")
        for s, r in results.items():
            extra = f" ({100 * r['light_pixels']:.1f}% left out)" if key else ""
            print(f"| {s}{extra} | " + " | ".join(
                f"{r[n]['relmse' + key]:.4f} / {r[n]['temporal_relmse' + key]:.4f}" for n in names) + " |")
    # The reference-free flicker (compare --no-reference's measure, the frames placed by the noisy
    # sequence's own motion) beside the temporal error it stands in for, and how often the two rank
    # a pair of variants alike.
    print("\ntemporal relMSE / flicker (no reference), and the pairs of variants the two order alike:\n")
    print("| sequence | " + " | ".join(names) + " | reference's flicker | pairs alike |")
    print("|---" * (len(names) + 3) + "|")
    total_agree = total_pairs = 0.0
    for s, r in results.items():
        agree, pairs = pair_agreement(r, names)
        total_agree, total_pairs = total_agree + agree, total_pairs + pairs
        print(f"| {s} | " + " | ".join(f"{r[n]['temporal_relmse']:.4f} / {r[n]['flicker']:.4f}" for n in names) +
              f" | {r['reference_flicker']:.4f} | {agree:g} of {pairs:g} |")
    print(f"\npairs ordered alike: {total_agree:g} of {total_pairs:g}")
    if a.json:
        a.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
