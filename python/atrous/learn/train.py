"""Training loop of the learned filter (docs/learned.md, "Training"): optax Adam on relMSE of the
remodulated output over random crops of the cached dataset (scripts/train/dataset.py), fixed seed,
checkpoints (resume), loss curve (JSON + PNG), weight export."""
from __future__ import annotations

import glob
import json
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import optax

from . import features, model, weights

SPPS = (1, 4, 16)


def load_split(folder: Path, limit: int | None = None) -> list:
    items = []
    for f in sorted(glob.glob(str(folder / "*.npz")))[:limit]:
        z = np.load(f)
        for spp in SPPS:
            x, d, a, e = features.prepare(*(z[f"{b}_{spp}"] for b in ("color", "variance", "albedo", "normal", "depth",
                                                                        "emission")))
            items.append((x, d, a, e, np.nan_to_num(z["reference"]).astype(np.float32), spp, Path(f).stem))
    return items


def batch(items, rng, n: int, crop: int):
    out = [[] for _ in range(5)]
    for _ in range(n):
        it = items[rng.integers(len(items))]
        h, w = it[0].shape[:2]
        crop = min(crop, h, w)
        y, x = rng.integers(0, h - crop + 1), rng.integers(0, w - crop + 1)
        flip = rng.integers(2)
        for k in range(5):
            c = it[k][y:y + crop, x:x + crop]
            out[k].append(c[:, ::-1] if flip else c)
    return [jnp.asarray(np.stack(o)) for o in out]


def train(data: Path, out: Path, steps: int, seed: int = 1, batch_size: int = 4, crop: int = 96, lr: float = 3e-3,
          ckpt_every: int = 200, minutes: float | None = None) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    items = load_split(data / "train")
    if not items:
        raise SystemExit(f"train: {data / 'train'}: no scenes (run scripts/train/dataset.py first)")
    params = model.init_params(seed)
    opt = optax.chain(optax.clip_by_global_norm(1.0), optax.adam(optax.cosine_decay_schedule(lr, steps, 0.05)))
    state = opt.init(params)
    curve, start = [], 0
    ck = out / "checkpoint.npz"
    if ck.exists():  # resume: parameters, optimiser state, step, curve and the data rng's state
        z = np.load(ck, allow_pickle=True)
        params = weights.from_bytes(bytes(z["weights"]), str(ck))
        params = {k: jnp.asarray(v) for k, v in params.items()}
        state = jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(state), [jnp.asarray(v) for v in z["opt"]])
        start, curve = int(z["step"]), json.loads(str(z["curve"]))
    rng = np.random.default_rng([seed, start])

    def loss_fn(p, x, d, a, e, r):
        return model.relmse(model.forward(p, x, d, a, e), r)

    @jax.jit
    def step_fn(p, s, x, d, a, e, r):
        l, g = jax.value_and_grad(loss_fn)(p, x, d, a, e, r)
        u, s = opt.update(g, s, p)
        return optax.apply_updates(p, u), s, l

    t0, run = time.time(), []

    def save(step):
        np.savez(str(ck) + ".tmp.npz", weights=np.frombuffer(weights.to_bytes(params), np.uint8), step=step,
                 curve=json.dumps(curve), opt=np.array([np.asarray(v) for v in jax.tree_util.tree_leaves(state)], dtype=object))
        Path(str(ck) + ".tmp.npz").replace(ck)

    step = start
    for step in range(start, steps):
        params, state, l = step_fn(params, state, *batch(items, rng, batch_size, crop))
        run.append(float(l))
        if (step + 1) % 50 == 0:
            curve.append({"step": step + 1, "loss": float(np.mean(run)), "seconds": round(time.time() - t0, 1)})
            run = []
            print(f"step {step + 1}/{steps} relMSE {curve[-1]['loss']:.4f} ({time.time() - t0:.0f} s)", flush=True)
        if (step + 1) % ckpt_every == 0:
            save(step + 1)
        if minutes is not None and time.time() - t0 > 60 * minutes:
            print(f"train: stopping at step {step + 1}: the {minutes}-minute budget is spent", flush=True)
            break
    save(step + 1)
    (out / "weights.bin").write_bytes(weights.to_bytes(params))
    (out / "loss_curve.json").write_text(json.dumps(curve, indent=1))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.semilogy([c["step"] for c in curve], [c["loss"] for c in curve])
        ax.set_xlabel("step"), ax.set_ylabel("training relMSE (50-step mean)")
        fig.tight_layout()
        fig.savefig(out / "loss_curve.png", dpi=100)
    except ImportError:
        pass
    return {k: np.asarray(v) for k, v in params.items()}
