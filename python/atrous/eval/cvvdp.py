"""ColorVideoVDP (Mantiuk et al. 2024; PyPI's cvvdp, `pip install cvvdp` or atrous[video]) of a
denoised sequence against its reference: the visible difference of the whole video, in JOD (10 =
no visible difference). `atrous compare --sequence` runs it through the `atrous-cvvdp` command
where it is installed, and the evaluation can call :func:`jod` directly.

The frames are linear HDR; both sequences are tonemapped as atrous's PSNR does (atrous.tonemap:
clamp((x / (1 + x))^(1/2.2), 0, 1)) and shown on cvvdp's "standard_fhd" display (an SDR monitor,
sRGB) at 24 frames per second, on the CPU unless --device says otherwise.

    atrous-cvvdp --check            exit 0 when cvvdp can run, else 3 and one line saying why
    atrous-cvvdp --pairs LIST       LIST: one line per frame, REFERENCE<TAB>TEST (image files);
                                    prints "JOD: x"
"""
from __future__ import annotations

import argparse
import sys
from typing import Optional, Sequence

import numpy as np

import atrous

DISPLAY = "standard_fhd"
FPS = 24.0


def unavailable() -> Optional[str]:
    """None when cvvdp (and PyTorch) import, else why not, in one line."""
    try:
        import pycvvdp  # noqa: F401
        import torch  # noqa: F401
    except Exception as e:  # ImportError, or a broken torch install
        return f"cvvdp is not installed in {sys.executable} (pip install cvvdp): {e}"
    return None


def jod(test: Sequence[np.ndarray], reference: Sequence[np.ndarray], fps: float = FPS, display: str = DISPLAY,
        device: str = "cpu") -> float:
    """ColorVideoVDP's JOD of `test` against `reference`: two equally long lists of H x W x 3 linear
    HDR frames of one size. ValueError for an empty or mismatched pair of sequences."""
    if len(test) == 0 or len(test) != len(reference):
        raise ValueError(f"cvvdp: {len(test)} test frames against {len(reference)} reference frames")
    why = unavailable()
    if why:
        raise RuntimeError(why)
    import pycvvdp
    import torch

    t = np.stack([atrous.tonemap(f) for f in test])
    r = np.stack([atrous.tonemap(f) for f in reference])
    if t.shape != r.shape:
        raise ValueError(f"cvvdp: test frames {t.shape[1:3]} against reference frames {r.shape[1:3]}")
    metric = pycvvdp.cvvdp(display_name=display, device=torch.device(device), quiet=True)
    q, _ = metric.predict(t, r, dim_order="FHWC", frames_per_second=fps)
    return float(q)


def run(argv: Optional[Sequence[str]] = None) -> None:
    p = argparse.ArgumentParser(prog="atrous-cvvdp", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--check", action="store_true", help="exit 0 when cvvdp can run, else 3 with the reason")
    p.add_argument("--pairs", help="a file of REFERENCE<TAB>TEST lines, one per frame in order")
    p.add_argument("--fps", type=float, default=FPS)
    p.add_argument("--display", default=DISPLAY)
    p.add_argument("--device", default="cpu")
    a = p.parse_args(argv)
    why = unavailable()
    if a.check:
        if why:
            print(why)
            sys.exit(3)
        print("ColorVideoVDP: ready")
        return
    if not a.pairs:
        p.error("give --pairs LIST (or --check)")
    if why:
        print(why, file=sys.stderr)
        sys.exit(3)
    refs, tests = [], []
    with open(a.pairs, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            parts = line.rstrip("\n").split("\t")
            if len(parts) != 2:
                print(f"{a.pairs}:{n}: expected REFERENCE<TAB>TEST", file=sys.stderr)
                sys.exit(2)
            refs.append(atrous.read_image(parts[0]))
            tests.append(atrous.read_image(parts[1]))
    try:
        value = jod(tests, refs, a.fps, a.display, a.device)
    except ValueError as e:
        print(str(e), file=sys.stderr)
        sys.exit(2)
    print(f"JOD: {value:.6f}")


if __name__ == "__main__":
    run()
