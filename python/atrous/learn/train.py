"""Training loop of the learned filter v4 (docs/learned.md, "Training"): optax Adam on relMSE of the
library's output d_out mod + emission over random crops of the prepared planes
(scripts/train/prepare.py), fixed seed, checkpoints (resume), loss curve (JSON + PNG), weight
export, and a JAX evaluation on the held-out split (the ablation tables)."""
from __future__ import annotations

import glob
import json
import math
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import optax

from . import context, features, model, weights

DEFAULTS = {
    "splits": ["train", "corpus_train"],  # prepared training splits (missing ones are skipped)
    "spps": [1, 4, 16],
    "variants": ["given", "est", "noem"],  # rendered variance / the driver's estimate / also no emission
    "batch": 4, "crop": 96, "lr": 3e-3, "eps": 0.01,
    "corpus_share": None,  # None: crops drawn uniformly from all images; else this fraction from corpus_train
    "colour": True, "vcolour": True, "level_blend": True, "box": True,  # ablations (C++ implements all four)
    "context": True,  # version 4's context branch (False: train the MLP alone, as version 3)
    # "relmse": the mean relMSE of the batch; "log": the mean of each crop's log relMSE, the metric's geometric
    # mean over images, so a crop of a near-clean input (64, 256 spp) counts as much as a 1-spp one; "sqrt": the
    # mean of each crop's root relMSE, in between
    "loss": "relmse",
}


def item_of(z, variant: str, spp: int, box: bool = True):
    """(x, d, v, mod, e, ref) of one prepared image, or None when the npz lacks it."""
    pre = f"{variant}_{spp}_"
    if pre + "color" not in z:
        return None
    planes = {k[len(pre):]: z[k] for k in z if k.startswith(pre)}
    x = features.inputs_of(planes)
    if not box:
        x[..., features.BOX] = 0.0
    return (x, planes["color"], features.variance_plane(planes["variance"]), planes["modulation"], planes["emission"],
            z["reference"])


def load_items(folder: Path, spps, variants, box: bool = True, limit: int | None = None) -> list:
    items = []
    for f in sorted(glob.glob(str(folder / "*.npz")))[:limit]:
        if f.endswith(".tmp.npz"):
            continue
        with np.load(f) as zf:
            z = {k: zf[k] for k in zf.files}
        for v in variants:
            for spp in spps:
                it = item_of(z, v, spp, box)
                if it is not None:
                    items.append(it + (f"{Path(f).stem} {v} {spp}spp",))
    return items


def batch(items, rng, n: int, crop: int, groups=None):
    """n random crops (horizontal flips) of items; groups = (share, indices of the favoured items):
    each crop comes from the favoured items with probability share, else from the others."""
    out = [[] for _ in range(6)]
    for _ in range(n):
        if groups is None:
            it = items[rng.integers(len(items))]
        else:
            share, fav, rest = groups
            pool = fav if rng.random() < share else rest
            it = items[pool[rng.integers(len(pool))]]
        h, w = it[0].shape[:2]
        y, x = rng.integers(0, h - crop + 1), rng.integers(0, w - crop + 1)
        flip = rng.integers(2)
        for k in range(6):
            c = it[k][y:y + crop, x:x + crop]
            out[k].append(c[:, ::-1] if flip else c)
    xs, ds = np.stack(out[0]), np.stack(out[1])
    cells = context.cell_inputs(xs, ds)  # of the crop, as the library computes them for an image that size
    return [jnp.asarray(xs), jnp.asarray(cells)] + [jnp.asarray(np.stack(o)) for o in out[1:]]


def relmse_np(x, r) -> float:
    """docs/eval.md's relMSE (the evaluation's metric): atrous.relmse, the library's."""
    import atrous

    return atrous.relmse(np.asarray(x, np.float32), np.asarray(r, np.float32))


def evaluate(params: dict, prep_test: Path, cfg: dict, spps=(4, 16, 64, 256), variants=("given",)) -> dict:
    """JAX relMSE on a held-out split (default variant `given`, full images): per image and geomean/spp."""
    ctx = cfg.get("context", True)
    fwd = jax.jit(lambda p, x, c, d, v, m, e: model.forward(p, x, c if ctx else None, d, v, m, e, cfg["colour"],
                                                            cfg["level_blend"], cfg["vcolour"]))
    res = {}
    for x, d, v, mod, e, ref, name in load_items(prep_test, spps, list(variants), cfg["box"]):
        cells = context.cell_inputs(x, d)
        out = fwd(params, *(jnp.asarray(a[None]) for a in (x, cells, d, v, mod, e)))
        res[name] = relmse_np(np.asarray(out[0]), ref)
    for spp in spps:
        v = [r for k, r in res.items() if k.endswith(f" {spp}spp")]
        if v:
            res[f"geomean {spp}spp"] = math.exp(np.mean(np.log(v)))
    return res


def train(prep: Path, out: Path, steps: int, seed: int = 1, minutes: float | None = None, ckpt_every: int = 200,
          init: str | None = None, **overrides) -> dict:
    cfg = dict(DEFAULTS, **{k: v for k, v in overrides.items() if v is not None})
    out.mkdir(parents=True, exist_ok=True)
    t_load = time.time()
    items = [it + (s,) for s in cfg["splits"] for it in load_items(prep / s, cfg["spps"], cfg["variants"], cfg["box"])]
    groups = None
    if cfg["corpus_share"] is not None:
        fav = [i for i, it in enumerate(items) if it[-1] == "corpus_train"]
        rest = [i for i, it in enumerate(items) if it[-1] != "corpus_train"]
        if fav and rest:
            groups = (cfg["corpus_share"], fav, rest)
    if not items:
        raise SystemExit(f"train: {prep}: no prepared scenes in {cfg['splits']} (run scripts/train/prepare.py first)")
    crop = min([cfg["crop"]] + [min(it[0].shape[:2]) for it in items])
    print(f"train: {len(items)} images from {cfg['splits']} loaded in {time.time() - t_load:.0f} s; config {cfg}",
          flush=True)
    params = model.init_params(seed)
    if init:  # fine-tuning: start from a weight file (the seed still drives the crops)
        params = {k: jnp.asarray(v) for k, v in weights.from_bytes(Path(init).read_bytes(), init).items()}
        if cfg["context"] and not weights.has_context(params):  # a version-3 start: fresh convolutions, kz = 0
            fresh = context.init_params(np.random.default_rng(seed), model.N_HIDDEN)
            params.update({k: jnp.asarray(v) for k, v in fresh.items()})
    if steps <= 0:  # evaluation of the starting weights only (train.py --steps 0 --eval)
        return params
    opt = optax.chain(optax.clip_by_global_norm(1.0), optax.adam(optax.cosine_decay_schedule(cfg["lr"], steps, 0.05)))
    state = opt.init(params)
    curve, start = [], 0
    ck = out / "checkpoint.npz"
    if ck.exists():  # resume: parameters, optimiser state, step, curve and the data rng's state
        z = np.load(ck, allow_pickle=True)
        params = {k: jnp.asarray(v) for k, v in weights.from_bytes(bytes(z["weights"]), str(ck)).items()}
        state = jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(state), [jnp.asarray(v) for v in z["opt"]])
        start, curve = int(z["step"]), json.loads(str(z["curve"]))
    rng = np.random.default_rng([seed, start])

    def loss_fn(p, x, c, d, v, m, e, r):
        out = model.forward(p, x, c if cfg["context"] else None, d, v, m, e, cfg["colour"], cfg["level_blend"], cfg["vcolour"])
        per = model.relmse(out, r, cfg["eps"], axis=tuple(range(1, out.ndim)))  # each crop's
        if cfg["loss"] == "log":
            return jnp.mean(jnp.log(per + 1e-7)), jnp.mean(per)
        if cfg["loss"] == "sqrt":  # between the two: a crop's gradient weighs 1 / sqrt(its relMSE)
            return jnp.mean(jnp.sqrt(per + 1e-7)), jnp.mean(per)
        return jnp.mean(per), jnp.mean(per)

    @jax.jit
    def step_fn(p, s, x, c, d, v, m, e, r):
        (_, l), g = jax.value_and_grad(loss_fn, has_aux=True)(p, x, c, d, v, m, e, r)
        u, s = opt.update(g, s, p)
        return optax.apply_updates(p, u), s, l

    t0, run = time.time(), []

    def save(step):
        np.savez(str(ck) + ".tmp.npz", weights=np.frombuffer(weights.to_bytes(params), np.uint8), step=step,
                 curve=json.dumps(curve), opt=np.array([np.asarray(v) for v in jax.tree_util.tree_leaves(state)], dtype=object))
        Path(str(ck) + ".tmp.npz").replace(ck)
        (out / "weights.bin").write_bytes(weights.to_bytes(params))

    step = start
    for step in range(start, steps):
        params, state, l = step_fn(params, state, *batch(items, rng, cfg["batch"], crop, groups))
        run.append(float(l))
        if (step + 1) % 50 == 0:
            # mean and median: a mean relMSE is dominated by the odd 1-spp crop
            curve.append({"step": step + 1, "loss": float(np.mean(run)), "median": float(np.median(run)),
                          "seconds": round(time.time() - t0, 1)})
            run = []
            print(f"step {step + 1}/{steps} relMSE mean {curve[-1]['loss']:.4f} median {curve[-1]['median']:.4f} "
                  f"({time.time() - t0:.0f} s)", flush=True)
        if (step + 1) % ckpt_every == 0:
            save(step + 1)
        if minutes is not None and time.time() - t0 > 60 * minutes:
            print(f"train: stopping at step {step + 1}: the {minutes}-minute budget is spent", flush=True)
            break
    save(step + 1)
    (out / "loss_curve.json").write_text(json.dumps(curve, indent=1))
    (out / "config.json").write_text(json.dumps(dict(cfg, steps=steps, seed=seed, stopped_at=step + 1,
                                                     seconds=round(time.time() - t0, 1)), indent=1))
    plot_curve(curve, out / "loss_curve.png")
    return params


def plot_curve(curve: list, path: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.semilogy([c["step"] for c in curve], [c["loss"] for c in curve], label="mean")
    if curve and "median" in curve[0]:
        ax.semilogy([c["step"] for c in curve], [c["median"] for c in curve], label="median")
    ax.set_xlabel("step"), ax.set_ylabel("training relMSE (50-step windows)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
