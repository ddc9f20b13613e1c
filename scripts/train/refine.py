#!/usr/bin/env python3
"""Training of the refine stage (docs/learned.md, "Refine"; python/atrous/learn/refine.py is the
network, src/filters/refine.h the same in C++): a U-Net that predicts a residual in log space after
a still method (--method, default sure), trained on farm items with OIDN-high targets.

  # data: a farm dataset with OIDN targets (docs/farm.md, "Training targets")
  .venv/bin/python -m atrous.farm render --dataset SPEC.json --out out/refine/data
  # inputs: the method's output and the buffers, per scene and spp, into one npz (the project venv)
  .venv/bin/python scripts/train/refine.py prepare out/refine/data out/refine/train.npz
  .venv/bin/python scripts/train/refine.py prepare-train-corpus out/refine/corpus_train.npz out/corpus/train/*/tr_*
  .venv/bin/python scripts/train/refine.py prepare-corpus out/refine/test.npz DIR...
  # train (.venv-train: jax, optax), resumable from OUT/ckpt.npz; a JSON line per 50 steps in OUT/log.jsonl
  .venv-train/bin/python scripts/train/refine.py train out/refine/train.npz[,out/refine/corpus_train.npz] out/refine/run --minutes 20
  .venv-train/bin/python scripts/train/refine.py eval out/refine/test.npz out/refine/run
  # the weight file the library compiles in (src/filters/refine_default.atrf), naming the run
  .venv-train/bin/python scripts/train/refine.py export out/refine/run src/filters/refine_default.atrf --run NAME

Loss: relMSE against the OIDN target (the corpus tables' metric) plus an energy term: the 8x8
block means of the output against those of the render OIDN was given (target_input.exr, 256 spp,
unbiased where OIDN's output can be a few percent dark), relative, weighted --energy; and a
plain-MSE term per crop (weighted --mse), which the brightest pixels dominate.
"""
from __future__ import annotations

import functools
import importlib.util
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
# The network module by path: the training venv has no atrous package.
_spec = importlib.util.spec_from_file_location("refine_net", ROOT / "python/atrous/learn/refine.py")
R = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(R)
BLOCK = 8


# ------------------------------------------------------------------------------------ data (project venv)

def _method_output(b, method):
    import atrous
    kw = {k: b[k] for k in ("albedo", "normal", "depth", "emission", "position") if b.get(k) is not None}
    return np.asarray(atrous.denoise(np.ascontiguousarray(b["color"], np.float32), method=method, **kw), np.float32)


def prepare(data_dir, out, method):
    """Every scene_*/spp_N of a farm dataset with target.exr: the method's output (no variance
    buffer, as other renderers' files come), the features, the target and the anchor."""
    import atrous
    xs, bases, targets, anchors, names = [], [], [], [], []
    for sd in sorted(Path(data_dir).glob("scene_*")):
        if not (sd / "target.exr").is_file() or not (sd / "target_input.exr").is_file():
            continue
        t = atrous.read_image(sd / "target.exr")[..., :3]
        anchor = atrous.read_image(sd / "target_input.exr")[..., :3]
        for d in sorted(sd.glob("spp_*")):
            b = atrous.read_buffers(str(d))
            b.pop("variance", None)
            base = _method_output(b, method)
            xs.append(R.features(base, b["color"], b["albedo"], b["normal"]))
            bases.append(base), targets.append(t), anchors.append(anchor)
            names.append(f"{sd.name}/{d.name}")
    np.savez(out, x=np.stack(xs), base=np.stack(bases), target=np.stack(targets), anchor=np.stack(anchors),
             names=np.array(names), method=method)
    print(f"{len(names)} images ({method}) -> {out}")


def prepare_train_corpus(out, dirs, method):
    """The corpus's training split (docs/corpus.md, "Training split": other renderers' scenes, none
    of them a test scene), in the renderers' own files: each noisy still with its true reference as
    both target and anchor, in prepare's format (the same size as the farm's views: 128^2)."""
    from atrous.eval.corpus import load_still
    xs, bases, targets, names = [], [], [], []
    for sd in map(Path, dirs):
        man = json.loads((sd / "manifest.json").read_text())
        ref = load_still(sd, man, man["reference"])["color"][..., :3]
        for stem, e in man["files"].items():
            if stem == man["reference"]:
                continue
            b = load_still(sd, man, stem)
            base = _method_output(b, method)
            xs.append(R.features(base, b["color"], b["albedo"], b["normal"]))
            bases.append(base), targets.append(ref)
            names.append(f"{sd.name}/{e['spp']}")
    np.savez(out, x=np.stack(xs), base=np.stack(bases), target=np.stack(targets), anchor=np.stack(targets),
             names=np.array(names), method=method)
    print(f"{len(names)} images ({method}) -> {out}")


def prepare_corpus(out, dirs, method):
    """Corpus scene folders (manifest.json; atrous.eval.corpus's loaders): every noisy still with
    its reference, the method's output and OIDN fast's (to compare), any size (kept as a list)."""
    import pyoidn
    from atrous.eval import oidn_inputs
    from atrous.eval.corpus import load_still
    items = {}
    for sd in map(Path, dirs):
        man = json.loads((sd / "manifest.json").read_text())
        ref = load_still(sd, man, man["reference"])["color"]
        for stem, e in man["files"].items():
            if stem == man["reference"]:
                continue
            b = load_still(sd, man, stem)
            base = _method_output(b, method)
            key = f"{sd.parent.parent.name}-{sd.name}/{e['spp']}"  # e.g. full-mi_glass/4
            items[key + "/x"] = R.features(base, b["color"], b["albedo"], b["normal"])
            items[key + "/base"] = base
            items[key + "/ref"] = ref
            items[key + "/oidn_fast"] = np.asarray(pyoidn.denoise(*oidn_inputs(b), hdr=True, quality="fast"),
                                                   np.float32)
    np.savez(out, method=method, **items)
    print(f"{len(items) // 4} stills ({method}) -> {out}")


# ------------------------------------------------------------------------------------ model (JAX)

def conv_jax(a, k, b):
    import jax
    return jax.lax.conv_general_dilated(a, k, (1, 1), "SAME", dimension_numbers=("NHWC", "HWIO", "NHWC")) + b


# The output head (issue 47: "a residual ..., signed per-pixel kernels ..., or a direct prediction;
# measure which"); only `residual` is built into the library (docs/learned.md, "Heads").
#   residual: expm1(log1p(base) + clip(r, +-3)), r 3 channels (the shipped stage)
#   kernel:   a signed, unnormalised per-pixel kernel shared by the channels: 5x5 taps over the
#             base and 3x3 over the noisy colour (34 outputs; the centre base tap starts at 1)
#   direct:   expm1(clip(r, -10, 12)): the image in log space from the features alone
HEADS = {"residual": 3, "kernel": 34, "direct": 3}


def init_params(seed, head):
    p = R.init(seed)
    n = HEADS[head]
    if n != p["bo"].shape[0]:
        rng = np.random.default_rng(seed + 7)
        p["ko"] = (rng.standard_normal((1, 1, R.C1, n)) * 0.01 * math.sqrt(2.0 / R.C1)).astype(np.float32)
        p["bo"] = np.zeros((n,), np.float32)
    if head == "kernel":
        p["bo"][12] = 1.0  # the 5x5 base kernel's centre
    return p


def _taps(img, r, jnp):
    """The (2r+1)^2 shifted copies of img (N x H x W x C, edges replicated), row-major."""
    n, h, w, _ = img.shape
    q = jnp.pad(img, ((0, 0), (r, r), (r, r), (0, 0)), mode="edge")
    return [q[:, r + dy:r + dy + h, r + dx:r + dx + w] for dy in range(-r, r + 1) for dx in range(-r, r + 1)]


def head_output(r, x, base, head):
    import jax.numpy as jnp
    if head == "residual":
        return R.apply_residual(base, r, jnp)
    if head == "direct":
        return jnp.maximum(jnp.expm1(jnp.clip(r, -10.0, 12.0)), 0.0)
    color = jnp.expm1(x[..., 3:6])
    out = sum(r[..., k:k + 1] * t for k, t in enumerate(_taps(base, 2, jnp)))
    out = out + sum(r[..., 25 + k:26 + k] * t for k, t in enumerate(_taps(color, 1, jnp)))
    return jnp.maximum(out, 0.0)


def apply(p, x, base, head):
    """The stage on crops of one energy block (training) or, for eval, whole images through
    energy_gain afterwards (apply_full)."""
    import jax.numpy as jnp
    return R.energy_gain_crop(base, refined_only(p, x, base, head), jnp)


def refined_only(p, x, base, head):
    import jax.numpy as jnp
    return head_output(R.forward(p, x, conv_jax, jnp), x, base, head)


def blocks(a):
    n, h, w, c = a.shape
    return a.reshape(n, h // BLOCK, BLOCK, w // BLOCK, BLOCK, c).mean(axis=(2, 4))


def loss_terms(out, target, anchor):
    """relMSE; the energy term (8x8 block means against the anchor's, relative); and the plain
    MSE per crop over the crop's mean square target (the brightest pixels dominate it: highlights,
    visible lights)."""
    import jax.numpy as jnp
    rel = jnp.mean((out - target) ** 2 / (target ** 2 + 0.01))
    bo, ba = blocks(out), blocks(anchor)
    energy = jnp.mean((bo - ba) ** 2 / (ba ** 2 + 0.01))
    mse = jnp.mean(jnp.mean((out - target) ** 2, axis=(1, 2, 3)) / (jnp.mean(target ** 2, axis=(1, 2, 3)) + 0.01))
    return rel, energy, mse


def load_ckpt(path):
    """(params, step, head); checkpoints from before --head are the residual's."""
    c = np.load(path, allow_pickle=True)
    head = str(c["head"]) if "head" in c.files else "residual"
    return {k[2:]: c[k] for k in c.files if k.startswith("p/")}, int(c["step"]), head


def train(data, out_dir, minutes, steps, lr, crop, batch, seed, energy_weight, mse_weight, head="residual"):
    import jax
    import optax
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    # "a.npz,b.npz:4": b's images four times over (drawn four times as often)
    parts = [(d.rsplit(":", 1)[0], int(d.rsplit(":", 1)[1])) if ":" in d else (d, 1) for d in str(data).split(",")]
    zs = [(np.load(d), n) for d, n in parts]
    x, base, target, anchor = (np.concatenate([z[k] for z, n in zs for _ in range(n)])
                               for k in ("x", "base", "target", "anchor"))
    ckpt = out_dir / "ckpt.npz"
    opt = optax.adam(lr)
    if ckpt.exists():
        params, step0, saved = load_ckpt(ckpt)
        if saved != head:
            raise SystemExit(f"{ckpt}: a {saved} head's checkpoint, asked for --head {head}")
        print(f"resumed at step {step0} (the optimiser's moments start again)")
    else:
        params, step0 = init_params(seed, head), 0
    state = opt.init(params)

    def loss_fn(p, xb, bb, tb, ab):
        rel, en, mse = loss_terms(apply(p, xb, bb, head), tb, ab)
        return rel + energy_weight * en + mse_weight * mse, (rel, en, mse)

    @jax.jit
    def step_fn(p, s, xb, bb, tb, ab):
        (l, aux), g = jax.value_and_grad(loss_fn, has_aux=True)(p, xb, bb, tb, ab)
        u, s = opt.update(g, s, p)
        return optax.apply_updates(p, u), s, l, aux

    rng = np.random.default_rng(seed + step0)
    n, h, w = x.shape[:3]
    t0, losses, step = time.time(), [], step0
    log = open(out_dir / "log.jsonl", "a")

    def save():
        np.savez(ckpt, step=step, head=head, **{f"p/{k}": np.asarray(v) for k, v in params.items()})

    assert crop <= R.ENERGY_BLOCK, "training crops are one energy block (energy_gain_crop)"
    while step < steps and time.time() - t0 < minutes * 60:
        idx = rng.integers(0, n, batch)
        ys = rng.integers(0, (h - crop) // BLOCK + 1, batch) * BLOCK
        xs_ = rng.integers(0, (w - crop) // BLOCK + 1, batch) * BLOCK
        sl = [(i, slice(a, a + crop), slice(b, b + crop)) for i, a, b in zip(idx, ys, xs_)]
        flip = rng.integers(0, 2, batch)  # mirrored crops

        def crops(arr):
            return np.stack([arr[i][a, b][:, ::-1] if f else arr[i][a, b] for (i, a, b), f in zip(sl, flip)])

        params, state, l, (rel, en, mse) = step_fn(params, state, crops(x), crops(base), crops(target), crops(anchor))
        losses.append((float(l), float(rel), float(en), float(mse)))
        step += 1
        if step % 50 == 0:
            m = np.median(np.array(losses), axis=0)
            rec = {"step": step, "loss": float(m[0]), "relmse": float(m[1]), "energy": float(m[2]), "mse": float(m[3]),
                   "seconds": round(time.time() - t0, 1), "data": str(data), "images": int(n), "lr": lr, "crop": crop,
                   "batch": batch, "energy_weight": energy_weight, "mse_weight": mse_weight, "head": head}
            log.write(json.dumps(rec) + "\n")
            log.flush()
            print(rec, flush=True)
            losses = []
        if step % 250 == 0 or step == steps:
            save()
    save()
    print(f"stopped at step {step} after {time.time() - t0:.0f} s -> {ckpt}")


def evaluate(test, out_dir):
    import jax
    params, step, head = load_ckpt(Path(out_dir) / "ckpt.npz")
    z = np.load(test)
    keys = sorted({k.rsplit("/", 1)[0] for k in z.files if "/" in k})
    f = jax.jit(functools.partial(refined_only, head=head))
    rows = {}

    def rel(a, ref):
        return float(np.mean((a - ref) ** 2 / (ref ** 2 + 0.01)))

    for k in keys:
        x, base, ref, oidn = z[k + "/x"], z[k + "/base"], z[k + "/ref"], z[k + "/oidn_fast"]
        h, w = x.shape[:2]
        out = R.energy_gain(base, np.asarray(f(params, R.pad4(x)[None], R.pad4(base)[None]))[0, :h, :w])
        rows[k] = {"base": rel(base, ref), "refined": rel(out, ref), "oidn_fast": rel(oidn, ref),
                   "mse_base": float(np.mean((base - ref) ** 2)), "mse_refined": float(np.mean((out - ref) ** 2)),
                   "mean_base": float(base.mean() / ref.mean()), "mean_refined": float(out.mean() / ref.mean())}
        r = rows[k]
        print(f"{k:28s} base {r['base']:.5f}  refined {r['refined']:.5f} ({r['refined'] / r['base']:.3f}x)"
              f"  OIDN fast {r['oidn_fast']:.5f}   mean {r['mean_base']:.3f} -> {r['mean_refined']:.3f}")
    g = {m: math.exp(np.mean([math.log(v[m]) for v in rows.values()])) for m in ("base", "refined", "oidn_fast")}
    print("geometric mean", {m: round(v, 5) for m, v in g.items()}, "refined/base", round(g["refined"] / g["base"], 3),
          "refined/oidn_fast", round(g["refined"] / g["oidn_fast"], 3))
    (Path(out_dir) / "eval.json").write_text(json.dumps({"step": step, "head": head, "method": str(z["method"]), "rows": rows,
                                                         "geomean": g}, indent=1))


def export(out_dir, path, run):
    params, step, head = load_ckpt(Path(out_dir) / "ckpt.npz")
    if head != "residual":
        raise SystemExit(f"{out_dir}: a {head} head; the library's weight file holds the residual head only")
    Path(path).write_bytes(R.to_bytes(params, run, step))
    print(f"{run} step {step} -> {path}")


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("prepare")
    a.add_argument("data")
    a.add_argument("out")
    a.add_argument("--method", default="sure")
    a = sub.add_parser("prepare-corpus")
    a.add_argument("out")
    a.add_argument("dirs", nargs="+")
    a.add_argument("--method", default="sure")
    a = sub.add_parser("prepare-train-corpus")
    a.add_argument("out")
    a.add_argument("dirs", nargs="+")
    a.add_argument("--method", default="sure")
    a = sub.add_parser("train")
    a.add_argument("data", help="one npz of prepare's, or several joined by commas (the same image size), "
                                "each optionally :N (its images N times over)")
    a.add_argument("out")
    a.add_argument("--minutes", type=float, default=10)
    a.add_argument("--steps", type=int, default=1000000)
    a.add_argument("--lr", type=float, default=1e-3)
    a.add_argument("--crop", type=int, default=64)
    a.add_argument("--batch", type=int, default=8)
    a.add_argument("--seed", type=int, default=1)
    a.add_argument("--energy", type=float, default=2.0, help="weight of the block-mean energy term")
    a.add_argument("--mse", type=float, default=0.0, help="weight of the plain-MSE term (runs A, B: 0)")
    a.add_argument("--head", choices=sorted(HEADS), default="residual", help="the output head (HEADS above)")
    a = sub.add_parser("eval")
    a.add_argument("test")
    a.add_argument("out")
    a = sub.add_parser("export")
    a.add_argument("out")
    a.add_argument("path")
    a.add_argument("--run", required=True)
    a = ap.parse_args(argv)
    if a.cmd == "prepare":
        prepare(a.data, a.out, a.method)
    elif a.cmd == "prepare-corpus":
        prepare_corpus(a.out, a.dirs, a.method)
    elif a.cmd == "prepare-train-corpus":
        prepare_train_corpus(a.out, a.dirs, a.method)
    elif a.cmd == "train":
        train(a.data, a.out, a.minutes, a.steps, a.lr, a.crop, a.batch, a.seed, a.energy, a.mse, a.head)
    elif a.cmd == "eval":
        evaluate(a.test, a.out)
    else:
        export(a.out, a.path, a.run)


if __name__ == "__main__":
    main(sys.argv[1:])
