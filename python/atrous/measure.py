"""The library's image metrics (include/atrous/metrics.h): the one relMSE that `atrous compare`,
the evaluation, training and the tests report, the temporal error of a sequence's steps, and the
one tonemap (and its 8-bit preview) the metrics and every picture of the evaluation go through.
Arrays follow the package's array rule (checked by the library)."""
from __future__ import annotations

from typing import Any, Dict

import numpy as np

from . import _core


def metrics(image: Any, reference: Any) -> Dict[str, float]:
    """MSE, relMSE, PSNR (tonemapped) and SSIM of `image` against `reference` (docs/eval.md, "What is measured").

    NaN/Inf pixels count as 0 in the figures; their numbers are returned as ``non_finite_pixels``
    (in `image`) and ``reference_non_finite_pixels``, so a broken image cannot pass for a good one.
    """
    return dict(_core.metrics(image, reference))


def relmse(image: Any, reference: Any) -> float:
    """The relMSE of :func:`metrics` (mean over pixels and channels of (x - r)^2 / (r^2 + 0.01)):
    the one figure `atrous compare`, the evaluation, training and the tests report."""
    return float(metrics(image, reference)["relmse"])


def temporal_metrics(image: Any, previous: Any, reference: Any, previous_reference: Any) -> Dict[str, float]:
    """The temporal error of one step of a sequence (docs/eval.md, "Sequences"): with d = image -
    previous and d_ref = reference - previous_reference, ``relmse`` = mean of (d - d_ref)^2 /
    (reference^2 + 0.01) (flicker the reference does not have), ``psnr`` the tPSNR of the tonemapped
    frames' differences."""
    return dict(_core.temporal_metrics(image, previous, reference, previous_reference))


def tonemap(image: Any, dtype: Any = np.float32) -> np.ndarray:
    """The tonemap the PSNR and SSIM of :func:`metrics` compare through: clamp((x / (1 + x))^(1/2.2),
    0, 1), x < 0 and non-finite values -> 0 (tonemapForMetrics, include/atrous/metrics.h), as an
    H x W x 3 numpy array. dtype=numpy.uint8: the same as 8 bits, rounded to nearest as every 8-bit
    image atrous writes (tonemap8, displayByte in include/atrous/srgb.h): the one preview of an HDR
    image that the evaluation's reports and crops, the corpus previews and the training's pictures
    show."""
    dt = np.dtype(dtype)
    if dt not in (np.float32, np.uint8):
        raise ValueError(f"tonemap: dtype must be float32 or uint8, got {dt}")
    return _core.tonemap(image, dt == np.uint8)
