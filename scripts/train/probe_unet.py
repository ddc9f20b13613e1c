#!/usr/bin/env python3
"""Probe, not a product path (docs/learned.md, "Probe: a full-resolution U-Net"): replaces version 4's
quarter-resolution context branch by a full-resolution U-Net (3 levels down, 16/24/32 channels, about
18 000 multiply-adds a pixel) whose output shifts the per-pixel MLP's first hidden layer, by patching
atrous.learn.context, so that train.py's loop, checkpoints and evaluation run unchanged. No C++ reads
its weights. Run in .venv-train:

  scripts/train/probe_unet.py train --out out/probe/unet --init W3.bin --lr 1e-3 --corpus-share 0.25 \\
      --spps 1 4 16 64 --loss sqrt --steps 1200          (train.py's arguments)
  scripts/train/probe_unet.py eval out/probe/unet/weights.bin out/probe/eval_unet.json --unet
  scripts/train/probe_unet.py eval W3.bin out/probe/eval_D.json           (a version-3 file, no context)

eval writes the JAX relMSE of the held-out studio split (variant given; 4, 16, 64 spp) and of the
corpus test stills (variant est; 4, 16 spp: scripts/corpus/train_export.py --test, then prepare.py)."""
import json
import runpy
import sys
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from atrous.learn import context, model, weights

ROOT = Path(__file__).resolve().parents[2]
C1, C2, C3 = 16, 24, 32
SHAPES = (("k1", (3, 3, 15, C1)), ("kb1", (C1,)), ("k1b", (3, 3, C1, C1)), ("kb1b", (C1,)),
          ("k2", (3, 3, C1, C2)), ("kb2", (C2,)), ("k2b", (3, 3, C2, C2)), ("kb2b", (C2,)),
          ("k3", (3, 3, C2, C3)), ("kb3", (C3,)), ("k3b", (3, 3, C3, C3)), ("kb3b", (C3,)),
          ("k4", (3, 3, C3, C3)), ("kb4", (C3,)),
          ("ku3", (3, 3, 2 * C3, C3)), ("kbu3", (C3,)), ("ku2", (3, 3, C3 + C2, C2)), ("kbu2", (C2,)),
          ("ku1", (3, 3, C2 + C1, C1)), ("kbu1", (C1,)))


def shift(p, x, h, w):
    """The U-Net's shift of the MLP's first hidden layer, from the 15 per-pixel inputs at full resolution."""
    r, c = jax.nn.relu, context.conv3
    up = lambda a, like: context.upsample(a, 2, like.shape[1], like.shape[2])  # noqa: E731
    e1 = r(c(r(c(x, p["k1"], p["kb1"])), p["k1b"], p["kb1b"]))
    e2 = r(c(r(c(context.pool2(e1), p["k2"], p["kb2"])), p["k2b"], p["kb2b"]))
    e3 = r(c(r(c(context.pool2(e2), p["k3"], p["kb3"])), p["k3b"], p["kb3b"]))
    e4 = r(c(context.pool2(e3), p["k4"], p["kb4"]))
    u3 = r(c(jnp.concatenate([e3, up(e4, e3)], -1), p["ku3"], p["kbu3"]))
    u2 = r(c(jnp.concatenate([e2, up(u3, e2)], -1), p["ku2"], p["kbu2"]))
    u1 = r(c(jnp.concatenate([e1, up(u2, e1)], -1), p["ku1"], p["kbu1"]))
    return u1 @ p["kz"] + p["kbz"]


def patch():
    context.SHAPES, context.N_CTX, context.N_CTX_IN = SHAPES, C1, 15
    context.cell_inputs = lambda x, d: np.asarray(x, np.float32)  # the "cells" are the pixels themselves
    context.hidden_shift = shift
    model.CTX_SHAPES = SHAPES + context.z_shapes(model.N_HIDDEN)
    model.ALL_SHAPES = model.SHAPES + model.CTX_SHAPES
    weights.ALL_SHAPES, weights.N_CTX, weights.N_CTX_IN = model.ALL_SHAPES, C1, 15


def evaluate(wfile: str, out: str, unet: bool) -> None:
    from atrous.learn import train

    p = {k: jnp.asarray(v) for k, v in weights.from_bytes(Path(wfile).read_bytes(), wfile).items()}
    cfg = dict(train.DEFAULTS, context=unet)
    prep = ROOT / "out" / "train" / "prep"
    res = {"studio": train.evaluate(p, prep / "test", cfg, spps=(4, 16, 64), variants=("given",)),
           "corpus": train.evaluate(p, prep / "corpus_test", cfg, spps=(4, 16), variants=("est",))}
    Path(out).write_text(json.dumps(res, indent=1))
    print({k: {g: round(x, 5) for g, x in v.items() if g.startswith("geomean")} for k, v in res.items()})


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] not in ("train", "eval"):
        sys.exit(__doc__)
    if sys.argv[1] == "train" or "--unet" in sys.argv:
        patch()
    if sys.argv[1] == "train":
        sys.argv = ["train.py"] + sys.argv[2:]
        runpy.run_path(str(ROOT / "scripts" / "train" / "train.py"), run_name="__main__")
    else:
        evaluate(sys.argv[2], sys.argv[3], "--unet" in sys.argv)
