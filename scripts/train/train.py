#!/usr/bin/env python3
"""Train the learned filter (docs/learned.md): `make train` runs this after scripts/train/dataset.py.
Writes out/train/run/{checkpoint.npz, weights.bin, loss_curve.json, loss_curve.png}; --export also
regenerates src/filters/learned_weights_default.cpp (the weights the library ships)."""
import argparse
import sys
from pathlib import Path

# python/atrous/learn as the top-level package `learn`: atrous/__init__.py needs the built extension.
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python" / "atrous"))
from learn import train, weights  # noqa: E402


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--data", default="out/train/data")
    p.add_argument("--out", default="out/train/run")
    p.add_argument("--steps", type=int, default=6000)
    p.add_argument("--minutes", type=float, default=None, help="stop after this long (wall clock)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--export", action="store_true", help="write src/filters/learned_weights_default.cpp")
    a = p.parse_args()
    train.train(Path(a.data), Path(a.out), a.steps, seed=a.seed, minutes=a.minutes)
    if a.export:
        data = (Path(a.out) / "weights.bin").read_bytes()
        Path("src/filters/learned_weights_default.cpp").write_text(weights.to_cpp(data))
    return 0


if __name__ == "__main__":
    sys.exit(main())
