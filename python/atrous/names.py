"""The built-in methods' names, read from the library's registries (the name of each built-in
still row, DenoiseOptions' default, and the sequence registry's svgf and temporal rows), for code
about one particular method: the evaluation's baselines and studies, the farm's and the add-on's
defaults. Code about every method reads :data:`atrous.METHODS`, :data:`atrous.SEQUENCE_METHODS`
and :func:`atrous.denoise_methods` instead; no module of the package spells a method's name."""
from __future__ import annotations

from . import _core

EAW = str(_core.EAW_METHOD)          # the edge-avoiding à-trous wavelet filter
SURE = str(_core.SURE_METHOD)        # SURE-based à-trous
LEARNED = str(_core.LEARNED_METHOD)  # the learned à-trous filter
BLEND = str(_core.BLEND_METHOD)      # the mean of the learned filter and SURE
REFINE = str(_core.REFINE_METHOD)    # SURE, then the refine U-Net
DEFAULT = str(_core.DEFAULT_METHOD)  # what denoise() runs without a method (auto)
SVGF = str(_core.SVGF_METHOD)        # the causal sequence method
TEMPORAL = str(_core.TEMPORAL_METHOD)  # the offline sequence method

__all__ = ["EAW", "SURE", "LEARNED", "BLEND", "REFINE", "DEFAULT", "SVGF", "TEMPORAL"]
