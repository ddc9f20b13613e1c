"""The library's image metrics (include/atrous/metrics.h): the one relMSE that `atrous compare`,
the evaluation, training and the tests report, and the temporal error of a sequence's steps."""
from __future__ import annotations

from typing import Any, Dict

from . import _core, _prepare


def metrics(image: Any, reference: Any) -> Dict[str, float]:
    """MSE, relMSE, PSNR (tonemapped) and SSIM of `image` against `reference` (docs/eval.md, "What is measured").

    NaN/Inf pixels count as 0 in the figures; their numbers are returned as ``non_finite_pixels``
    (in `image`) and ``reference_non_finite_pixels``, so a broken image cannot pass for a good one.
    """
    return dict(_core.metrics(_prepare(image, "image", allow_gray=False),
                              _prepare(reference, "reference", allow_gray=False)))


def relmse(image: Any, reference: Any) -> float:
    """The relMSE of :func:`metrics` (mean over pixels and channels of (x - r)^2 / (r^2 + 0.01)):
    the one figure `atrous compare`, the evaluation, training and the tests report."""
    return float(metrics(image, reference)["relmse"])


def temporal_metrics(image: Any, previous: Any, reference: Any, previous_reference: Any) -> Dict[str, float]:
    """The temporal error of one step of a sequence (docs/eval.md, "Sequences"): with d = image -
    previous and d_ref = reference - previous_reference, ``relmse`` = mean of (d - d_ref)^2 /
    (reference^2 + 0.01) (flicker the reference does not have), ``psnr`` the tPSNR of the tonemapped
    frames' differences."""
    arrays = [_prepare(x, n, allow_gray=False) for x, n in ((image, "image"), (previous, "previous"),
                                                           (reference, "reference"),
                                                           (previous_reference, "previous_reference"))]
    return dict(_core.temporal_metrics(*arrays))


def tonemap(image: Any) -> Any:
    """The tonemap the PSNR and SSIM of :func:`metrics` compare through: clamp((x / (1 + x))^(1/2.2),
    0, 1), x < 0 -> 0 (tonemapForMetrics, include/atrous/metrics.h); an H x W x 3 numpy array."""
    return _core.tonemap(_prepare(image, "image", allow_gray=False))
