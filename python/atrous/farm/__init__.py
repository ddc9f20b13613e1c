"""atrous.farm: rendering and denoising work split into items, each a Ray task running the atrous
library, on one machine or a Ray cluster (docs/farm.md).

    python -m atrous.farm render --scenes cornell,cornell-point --spp 2,4 --width 32 --height 32 \\
        --address local --out farm-out

    import atrous.farm
    res = atrous.farm.render("farm-out", ["cornell", "cornell-point"], [2, 4], width=32, height=32)
    res.ok, res.done, res.failed

Jobs: render (scenes x spp x seeds [x frames], or a dataset spec of randomised scenes:
render_dataset), denoise (render directories or frame sequences with a method and parameters),
evaluate (the quality benchmark: methods x scenes x spp, OIDN included) and sweep (a parameter
grid scored against references). Each writes the layouts the CLI writes plus OUT/manifest.json;
a rerun skips the items done. Run options (keywords of every job): address ("local", "auto" or
"HOST:PORT"), cpus_per_task, gpus_per_task, max_retries (for dead workers), num_cpus (of a local
instance), progress. Bad arguments raise ValueError (FarmInputError) before anything is written;
items that fail are in the result's `failed`, with their messages, and do not stop the others.
"""
from __future__ import annotations

from .items import FarmInputError, Item
from .jobs import denoise, evaluate, render, render_dataset, sweep
from .runner import JobResult, run_job

__all__ = ["render", "render_dataset", "denoise", "evaluate", "sweep", "run_job", "JobResult", "Item",
           "FarmInputError"]
