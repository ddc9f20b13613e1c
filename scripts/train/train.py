#!/usr/bin/env python3
"""Train the learned filter v3 (docs/learned.md) on the prepared planes (scripts/train/prepare.py):
`make train` runs this after dataset.py and prepare.py. Writes <out>/{checkpoint.npz, weights.bin,
loss_curve.json, loss_curve.png, config.json} (a rerun resumes from the checkpoint); --eval writes
<out>/eval_jax.json (the held-out split through the JAX forward pass); --export regenerates
src/filters/learned_weights_default.cpp (the weights the library ships). The ablation switches
(--no-colour, --no-vcolour, --no-blend, --no-box) exist for measurements only: C++ implements the full model."""
import argparse
import json
import sys
from pathlib import Path

# The atrous package as installed into .venv-train (scripts/train/setup.sh installs the wheel).
from atrous.learn import train, weights


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--prep", default="out/train/prep", help="prepared planes: <prep>/<split>/*.npz")
    p.add_argument("--out", default="out/train/run")
    p.add_argument("--steps", type=int, default=6000)
    p.add_argument("--minutes", type=float, default=None, help="stop after this long (wall clock)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--splits", nargs="+", help=f"training splits (default {train.DEFAULTS['splits']})")
    p.add_argument("--spps", nargs="+", type=int, help=f"default {train.DEFAULTS['spps']}")
    p.add_argument("--variants", nargs="+", choices=["given", "est", "noem"])
    p.add_argument("--init", help="start from this weight file (fine-tuning) instead of the seed's initialisation")
    p.add_argument("--batch", type=int)
    p.add_argument("--crop", type=int)
    p.add_argument("--lr", type=float)
    p.add_argument("--corpus-share", type=float, help="fraction of the crops drawn from the corpus_train split "
                   "(default: uniform over all images, where it is ~4%%)")
    p.add_argument("--loss", choices=["relmse", "log", "sqrt"], help="relmse: the batch's mean relMSE (default); log: "
                   "the mean of each crop's log relMSE (the metric's geometric mean); sqrt: of its square root")
    p.add_argument("--eps", type=float, help="the loss's relMSE epsilon (default 0.01, the metric's)")
    p.add_argument("--no-colour", dest="colour", action="store_const", const=False)
    p.add_argument("--no-vcolour", dest="vcolour", action="store_const", const=False)
    p.add_argument("--no-blend", dest="level_blend", action="store_const", const=False)
    p.add_argument("--no-box", dest="box", action="store_const", const=False)
    p.add_argument("--no-context", dest="context", action="store_const", const=False,
                   help="train without the context branch (version 3's network; the file still has it, zero)")
    p.add_argument("--eval", action="store_true", help="relMSE on <prep>/test (JAX) into <out>/eval_jax.json")
    p.add_argument("--export", action="store_true", help="write src/filters/learned_weights_default.cpp")
    a = p.parse_args()
    over = {k: getattr(a, k) for k in ("splits", "spps", "variants", "batch", "crop", "lr", "eps", "loss", "corpus_share", "colour", "vcolour",
                                       "level_blend", "box", "context")}
    params = train.train(Path(a.prep), Path(a.out), a.steps, seed=a.seed, minutes=a.minutes, init=a.init, **over)
    if a.eval:
        cfg = dict(train.DEFAULTS, **{k: v for k, v in over.items() if v is not None})
        res = train.evaluate(params, Path(a.prep) / "test", cfg)
        (Path(a.out) / "eval_jax.json").write_text(json.dumps(res, indent=1))
        print({k: round(v, 5) for k, v in res.items() if k.startswith("geomean")})
        if (Path(a.prep) / "corpus_test").is_dir():  # other renderers' test stills, as the CLI prepares them
            res = train.evaluate(params, Path(a.prep) / "corpus_test", cfg, variants=("est",))
            (Path(a.out) / "eval_corpus_jax.json").write_text(json.dumps(res, indent=1))
            print("corpus test", {k: round(v, 5) for k, v in res.items() if k.startswith("geomean")})
    if a.export:
        data = (Path(a.out) / "weights.bin").read_bytes()
        weights.from_bytes(data, str(Path(a.out) / "weights.bin"))
        Path("src/filters/learned_weights_default.cpp").write_text(weights.to_cpp(data))
        print("train: wrote src/filters/learned_weights_default.cpp")
    return 0


if __name__ == "__main__":
    sys.exit(main())
