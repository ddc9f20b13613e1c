#!/usr/bin/env python3
"""How much can per-pixel, per-level detail selection gain over EAW? (run by hand; docs/quality.md)

SURE-À-Trous (docs/denoising.md, "SURE details") outputs c_N + Σ_i s_i(p) d_i(p) with s_i(p) from a candidate set,
d_i = c_i − c_{i+1} the details of the EAW cascade. This script measures, on a rendered scene:

- the EAW output after k levels, k = 0..5 (c_k; c_0 is the input after the firefly pass),
- an *oracle* that knows the reference and picks, per pixel and level, the s_i from
  {0, 0.2, ..., 1} minimising the true squared error over the same (2r+1)² window SURE uses
  (coordinate descent over the levels, 3 sweeps): an upper bound on what any choice of s_i can
  reach from this cascade,
- the per-level SURE choice with the *empirical* detail variance v_i (measured over K independent
  renders), i.e. without any propagation error, for first levels 0..3,
- the correlation of the detail noise between adjacent levels,
- the library's SURE (defaults) and with first level 0 (the paper's form).

  .venv/bin/python bench/sure_oracle.py --scene cornell-point --size 256 --ref out/quality-dev/refs/cornell-point-256-1024/color.exr
"""
import argparse
import json

import numpy as np

import atrous


def box(a, r):
    """Sum over the (2r+1)² window, borders replicated (as the library's SURE window)."""
    p = np.pad(a, r, mode="edge")
    c = np.pad(p.cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    n = 2 * r + 1
    return c[n:, n:] - c[:-n, n:] - c[n:, :-n] + c[:-n, :-n]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default="cornell-point")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--ref", required=True, help="reference color.exr (same scene and size)")
    ap.add_argument("--renders", type=int, default=8, help="independent renders (K) for the empirical v_i")
    ap.add_argument("--window", type=int, default=3, help="window radius r")
    ap.add_argument("--json", help="write the results here")
    args = ap.parse_args()
    ref = atrous.read_image(args.ref)
    levels = 5
    C, lib_sure, lib_sure0 = [], [], []
    for k in range(args.renders):
        b = atrous.render(args.scene, width=args.size, height=args.size, spp=args.spp, seed=1000 + k)
        kw = {n: b.get(n) for n in ["albedo", "normal", "position", "variance", "ids", "emission"]}
        c = [atrous.denoise(b["color"], method="sure", device="cpu", sure_candidates=[1.0], sure_first_level=0, **kw)]
        for lv in range(1, levels + 1):
            c.append(atrous.denoise(b["color"], method="eaw", device="cpu", levels=lv, **kw))
        C.append(np.stack(c))
        lib_sure.append(atrous.denoise(b["color"], method="sure", device="cpu", **kw))
        lib_sure0.append(atrous.denoise(b["color"], method="sure", device="cpu", sure_first_level=0, **kw))
    C = np.stack(C)  # K × (levels+1) × H × W × 3
    D = C[:, :-1] - C[:, 1:]
    vemp = D.var(0, ddof=1)
    S = np.linspace(0.0, 1.0, 6)
    r = args.window

    def mse(x):
        return float(((x - ref) ** 2).mean())

    res = {"scene": args.scene, "size": args.size, "spp": args.spp, "renders": args.renders, "window": r,
           "eaw_levels_mse": [float(np.mean([mse(C[k, lv]) for k in range(len(C))])) for lv in range(levels + 1)],
           "library_sure": float(np.mean([mse(x) for x in lib_sure])),
           "library_sure_first_level_0": float(np.mean([mse(x) for x in lib_sure0]))}
    oracle, keep = [], np.zeros(levels)
    for k in range(min(2, len(C))):  # the oracle on two renders (it is slow)
        c, d = C[k], D[k]
        s = np.zeros((levels,) + ref.shape[:2])
        for _ in range(3):
            for i in range(levels):
                rest = c[levels] + sum(s[j][..., None] * d[j] for j in range(levels) if j != i)
                err = np.stack([box(((rest + sv * d[i] - ref) ** 2).sum(-1), r) for sv in S])
                s[i] = S[err.argmin(0)]
        oracle.append(mse(c[levels] + sum(s[j][..., None] * d[j] for j in range(levels))))
        keep += s.mean((1, 2)) / min(2, len(C))
    res["oracle_mse"] = float(np.mean(oracle))
    res["oracle_mean_fraction_kept_per_level"] = [round(float(v), 3) for v in keep]
    for first in range(4):
        tot = 0.0
        for k in range(len(C)):
            out = C[k, levels].copy()
            for i in range(first, levels):
                sD = box((D[k, i] ** 2).sum(-1), r)
                sV = box(vemp[i].sum(-1), r)
                s = S[np.stack([(1 - sv) ** 2 * sD + (2 * sv - 1) * sV for sv in S]).argmin(0)]
                out += s[..., None] * D[k, i]
            tot += mse(out) / len(C)
        res["sure_empirical_v_first_level_%d" % first] = tot
    corr = []
    for i in range(levels - 1):
        a = D[:, i] - D[:, i].mean(0)
        b = D[:, i + 1] - D[:, i + 1].mean(0)
        corr.append(round(float((a * b).mean() / np.sqrt((a * a).mean() * (b * b).mean())), 3))
    res["detail_noise_correlation_adjacent_levels"] = corr
    print(json.dumps(res, indent=2))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=2)


if __name__ == "__main__":
    main()
