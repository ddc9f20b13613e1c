#!/usr/bin/env python3
"""Probe, not a product path (docs/learned.md, "Probe: a residual after the default"; issue 47):
does a small U-Net that predicts a correction of the default method's output (a residual in
log space, so an output pixel is no longer a convex combination of its neighbourhood) move the
default toward OIDN on other renderers' stills, when trained on atrous's own scenes with
OIDN-high targets (no reference renders)?

  # data: a farm dataset with OIDN targets (docs/farm.md, "Training targets")
  .venv/bin/python -m atrous.farm render --dataset SPEC.json --out out/probe/residual/data
  # inputs: the default's output and the buffers, per scene and spp, into one npz (the project venv)
  .venv/bin/python scripts/train/probe_residual.py prepare out/probe/residual/data out/probe/residual/train.npz
  .venv/bin/python scripts/train/probe_residual.py prepare-corpus out/probe/residual/test.npz DIR...
  # train (.venv-train: jax, optax), resumable from OUT/ckpt.npz; a JSON line per 50 steps in OUT/log.jsonl
  .venv-train/bin/python scripts/train/probe_residual.py train out/probe/residual/train.npz out/probe/residual --minutes 12
  .venv-train/bin/python scripts/train/probe_residual.py eval out/probe/residual/test.npz out/probe/residual

The network: 15 inputs (log1p of the default's output and of the noisy colour, the albedo, the
normal, and a noise level: the 7x7 mean of |log1p(noisy) - log1p(default)|), a 3-level U-Net (16 / 24 / 32 channels, two 3x3 convolutions a level, about 16 000
multiply-adds a pixel), 3 outputs r; the result is expm1(log1p(default) + r). Loss: relMSE against
the target (the metric the corpus tables use). No C++ reads these weights.
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
C1, C2, C3 = 16, 24, 32
NIN = 15


def noise_level(base, color, radius=3):
    """A noise input: the 7x7 mean of |log1p(noisy) - log1p(default)| per channel (what the default
    took away, large where the input is noisy, small where it is clean)."""
    d = np.abs(np.log1p(np.maximum(color, 0)) - np.log1p(np.maximum(base, 0)))
    s = np.pad(d, ((radius, radius), (radius, radius), (0, 0)), mode="edge").cumsum(0).cumsum(1)
    s = np.pad(s, ((1, 0), (1, 0), (0, 0)))
    k = 2 * radius + 1
    return (s[k:, k:] - s[:-k, k:] - s[k:, :-k] + s[:-k, :-k]) / (k * k)


def features(base, color, albedo, normal):
    """The network's inputs, H x W x NIN float32."""
    f = [np.log1p(np.maximum(base, 0)), np.log1p(np.maximum(color, 0)),
         np.clip(np.nan_to_num(albedo), 0, 1), np.clip(np.nan_to_num(normal), -1, 1),
         noise_level(base, color)]
    return np.concatenate(f, axis=-1).astype(np.float32)


# ------------------------------------------------------------------------------------ data (project venv)

def _default(b):
    import atrous
    kw = {k: b[k] for k in ("albedo", "normal", "depth", "emission", "position") if b.get(k) is not None}
    kw["albedo"] = np.ascontiguousarray(np.clip(kw["albedo"], 0, 1), np.float32)
    return np.asarray(atrous.denoise(np.ascontiguousarray(b["color"], np.float32), **kw), np.float32)


def prepare(data_dir, out):
    """Every scene_*/spp_N of a farm dataset with target.exr: the default's output (no variance
    buffer, as other renderers' files come), the features and the target."""
    import atrous
    xs, bases, targets, names = [], [], [], []
    for sd in sorted(Path(data_dir).glob("scene_*")):
        if not (sd / "target.exr").is_file():
            continue
        t = atrous.read_image(sd / "target.exr")[..., :3]
        for d in sorted(sd.glob("spp_*")):
            b = atrous.read_buffers(str(d))
            b.pop("variance", None)
            base = _default(b)
            xs.append(features(base, b["color"], b["albedo"], b["normal"]))
            bases.append(base)
            targets.append(t)
            names.append(f"{sd.name}/{d.name}")
    np.savez(out, x=np.stack(xs), base=np.stack(bases), target=np.stack(targets), names=np.array(names))
    print(f"{len(names)} images -> {out}")


def prepare_corpus(out, dirs):
    """Corpus scene folders (manifest.json; atrous.eval.corpus's loaders): every noisy still with
    its reference, the default's output and OIDN fast's (to compare), any size (kept as a list)."""
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
            base = _default(b)
            key = f"{sd.parent.parent.name}-{sd.name}/{e['spp']}"  # e.g. full-mi_glass/4
            items[key + "/x"] = features(base, b["color"], b["albedo"], b["normal"])
            items[key + "/base"] = base
            items[key + "/ref"] = ref
            items[key + "/oidn_fast"] = np.asarray(pyoidn.denoise(*oidn_inputs(b), hdr=True, quality="fast"),
                                                   np.float32)
    np.savez(out, **items)
    print(f"{len(items) // 4} stills -> {out}")


# ------------------------------------------------------------------------------------ model (JAX)

def shapes():
    return (("k1", (3, 3, NIN, C1)), ("b1", (C1,)), ("k1b", (3, 3, C1, C1)), ("b1b", (C1,)),
            ("k2", (3, 3, C1, C2)), ("b2", (C2,)), ("k2b", (3, 3, C2, C2)), ("b2b", (C2,)),
            ("k3", (3, 3, C2, C3)), ("b3", (C3,)), ("k3b", (3, 3, C3, C3)), ("b3b", (C3,)),
            ("ku2", (3, 3, C3 + C2, C2)), ("bu2", (C2,)), ("ku1", (3, 3, C2 + C1, C1)), ("bu1", (C1,)),
            ("ko", (1, 1, C1, 3)), ("bo", (3,)))


def init(seed=0):
    rng = np.random.default_rng(seed)
    p = {}
    for name, shp in shapes():
        if name.startswith("b"):
            p[name] = np.zeros(shp, np.float32)
        else:
            fan = shp[0] * shp[1] * shp[2]
            p[name] = (rng.standard_normal(shp) * math.sqrt(2.0 / fan)).astype(np.float32)
    p["ko"] *= 0.01  # start near the default's output
    return p


def forward(p, x):
    """x: N x H x W x 12 (H, W multiples of 4) -> the residual r, N x H x W x 3."""
    import jax
    import jax.numpy as jnp

    def conv(a, k, b):
        return jax.lax.conv_general_dilated(a, k, (1, 1), "SAME", dimension_numbers=("NHWC", "HWIO", "NHWC")) + b

    r = jax.nn.relu

    def down(a):
        n, h, w, c = a.shape
        return a.reshape(n, h // 2, 2, w // 2, 2, c).mean(axis=(2, 4))

    def up(a):
        return jnp.repeat(jnp.repeat(a, 2, axis=1), 2, axis=2)

    e1 = r(conv(r(conv(x, p["k1"], p["b1"])), p["k1b"], p["b1b"]))
    e2 = r(conv(r(conv(down(e1), p["k2"], p["b2"])), p["k2b"], p["b2b"]))
    e3 = r(conv(r(conv(down(e2), p["k3"], p["b3"])), p["k3b"], p["b3b"]))
    d2 = r(conv(jnp.concatenate([up(e3), e2], -1), p["ku2"], p["bu2"]))
    d1 = r(conv(jnp.concatenate([up(d2), e1], -1), p["ku1"], p["bu1"]))
    return conv(d1, p["ko"], p["bo"])


def apply(p, x, base):
    import jax.numpy as jnp
    return jnp.expm1(jnp.log1p(jnp.maximum(base, 0.0)) + forward(p, x))


def relmse_loss(out, target):
    import jax.numpy as jnp
    return jnp.mean((out - target) ** 2 / (target ** 2 + 0.01))


def train(data, out_dir, minutes, steps, lr, crop, batch, seed):
    import jax
    import optax
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    z = np.load(data)
    x, base, target = z["x"], z["base"], z["target"]
    ckpt = out_dir / "ckpt.npz"
    opt = optax.adam(lr)
    if ckpt.exists():
        c = np.load(ckpt, allow_pickle=True)
        params = {k[2:]: c[k] for k in c.files if k.startswith("p/")}
        step0 = int(c["step"])
        state = opt.init(params)
        print(f"resumed at step {step0} (the optimiser's moments start again)")
    else:
        params, step0 = init(seed), 0
        state = opt.init(params)

    def loss_fn(p, xb, bb, tb):
        return relmse_loss(apply(p, xb, bb), tb)

    @jax.jit
    def step_fn(p, s, xb, bb, tb):
        l, g = jax.value_and_grad(loss_fn)(p, xb, bb, tb)
        u, s = opt.update(g, s, p)
        return optax.apply_updates(p, u), s, l

    rng = np.random.default_rng(seed + step0)
    n, h, w = x.shape[:3]
    t0, losses, step = time.time(), [], step0
    log = open(out_dir / "log.jsonl", "a")
    while step < steps and time.time() - t0 < minutes * 60:
        idx = rng.integers(0, n, batch)
        ys, xs_ = rng.integers(0, h - crop + 1, batch), rng.integers(0, w - crop + 1, batch)
        sl = [(i, slice(a, a + crop), slice(b, b + crop)) for i, a, b in zip(idx, ys, xs_)]
        xb = np.stack([x[i][a, b] for i, a, b in sl])
        bb = np.stack([base[i][a, b] for i, a, b in sl])
        tb = np.stack([target[i][a, b] for i, a, b in sl])
        params, state, l = step_fn(params, state, xb, bb, tb)
        losses.append(float(l))
        step += 1
        if step % 50 == 0:
            rec = {"step": step, "loss": float(np.median(losses)), "seconds": round(time.time() - t0, 1),
                   "data": str(data), "images": int(n), "lr": lr, "crop": crop, "batch": batch}
            log.write(json.dumps(rec) + "\n")
            log.flush()
            print(rec, flush=True)
            losses = []
        if step % 250 == 0 or step == steps:
            np.savez(ckpt, step=step, **{f"p/{k}": np.asarray(v) for k, v in params.items()})
    np.savez(ckpt, step=step, **{f"p/{k}": np.asarray(v) for k, v in params.items()})
    print(f"stopped at step {step} after {time.time() - t0:.0f} s -> {ckpt}")


def evaluate(test, out_dir):
    import jax
    c = np.load(Path(out_dir) / "ckpt.npz")
    params = {k[2:]: c[k] for k in c.files if k.startswith("p/")}
    z = np.load(test)
    keys = sorted({k.rsplit("/", 1)[0] for k in z.files})
    f = jax.jit(apply)
    rows = {}

    def rel(a, ref):
        return float(np.mean((a - ref) ** 2 / (ref ** 2 + 0.01)))

    for k in keys:
        x, base, ref, oidn = z[k + "/x"], z[k + "/base"], z[k + "/ref"], z[k + "/oidn_fast"]
        h, w = x.shape[:2]
        ph, pw = (-h) % 4, (-w) % 4
        xp = np.pad(x, ((0, ph), (0, pw), (0, 0)), mode="edge")[None]
        bp = np.pad(base, ((0, ph), (0, pw), (0, 0)), mode="edge")[None]
        out = np.asarray(f(params, xp, bp))[0, :h, :w]
        rows[k] = {"default": rel(base, ref), "residual": rel(out, ref), "oidn_fast": rel(oidn, ref),
                   "mean_default": float(base.mean() / ref.mean()), "mean_residual": float(out.mean() / ref.mean())}
        r = rows[k]
        print(f"{k:28s} default {r['default']:.5f}  +residual {r['residual']:.5f} ({r['residual'] / r['default']:.3f}x)"
              f"  OIDN fast {r['oidn_fast']:.5f}   mean {r['mean_default']:.3f} -> {r['mean_residual']:.3f}")
    g = {m: math.exp(np.mean([math.log(v[m]) for v in rows.values()])) for m in ("default", "residual", "oidn_fast")}
    print("geometric mean", {m: round(v, 5) for m, v in g.items()}, "residual/default", round(g["residual"] / g["default"], 3))
    (Path(out_dir) / "eval.json").write_text(json.dumps({"step": int(c["step"]), "rows": rows, "geomean": g}, indent=1))


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("prepare")
    a.add_argument("data")
    a.add_argument("out")
    a = sub.add_parser("prepare-corpus")
    a.add_argument("out")
    a.add_argument("dirs", nargs="+")
    a = sub.add_parser("train")
    a.add_argument("data")
    a.add_argument("out")
    a.add_argument("--minutes", type=float, default=10)
    a.add_argument("--steps", type=int, default=100000)
    a.add_argument("--lr", type=float, default=1e-3)
    a.add_argument("--crop", type=int, default=64)
    a.add_argument("--batch", type=int, default=8)
    a.add_argument("--seed", type=int, default=1)
    a = sub.add_parser("eval")
    a.add_argument("test")
    a.add_argument("out")
    a = ap.parse_args(argv)
    if a.cmd == "prepare":
        prepare(a.data, a.out)
    elif a.cmd == "prepare-corpus":
        prepare_corpus(a.out, a.dirs)
    elif a.cmd == "train":
        train(a.data, a.out, a.minutes, a.steps, a.lr, a.crop, a.batch, a.seed)
    else:
        evaluate(a.test, a.out)


if __name__ == "__main__":
    main(sys.argv[1:])
