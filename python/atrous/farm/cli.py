"""python -m atrous.farm JOB [flags]: the command line of the farm (docs/farm.md).

Exit status: 0 when every item is done; 2 for bad input: a bad flag, spec file or input directory
(one line on stderr, nothing written), or items that failed on bad input (a malformed scene
file: one line each); 1 when an item failed otherwise (retries used up, an I/O error).
"""
from __future__ import annotations

import argparse
import re
import sys
from typing import Any, Dict, List, Optional, Sequence

from .. import names
from . import jobs
from .items import EVAL_METHODS, FarmInputError, denoise_choices, eval_choices, parse_assignments
from .runner import JobResult, print_summary

PROG = "python -m atrous.farm"


class _Usage(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse's own errors: one line, exit status 2
        raise _Usage(f"{message} (see --help)")


def _run_flags(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("where and how items run")
    g.add_argument("--out", required=True, help="output directory (local, or a path every node sees)")
    g.add_argument("--address", default="local",
                   help="local (a Ray instance on this machine, the default), auto (the cluster `ray start` "
                        "runs here, or RAY_ADDRESS) or HOST:PORT of a cluster's head")
    g.add_argument("--cpus-per-task", type=float, default=1, help="CPUs Ray reserves per item (default 1); "
                   "the renderer uses as many threads")
    g.add_argument("--gpus-per-task", type=float, default=0,
                   help="GPUs per item (default 0): items then run on GPU nodes only and denoise with CUDA")
    g.add_argument("--num-cpus", type=int, help="with --address local: CPUs of the local instance (default all)")
    g.add_argument("--max-retries", type=int, default=3,
                   help="Ray's retries of an item whose worker process died (default 3)")
    g.add_argument("--quiet", action="store_true", help="no progress line and no summary table")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog=PROG, description="Render, denoise, evaluate and sweep as Ray tasks, on one machine or a "
                                       "cluster; outputs in the CLI's layouts plus OUT/manifest.json.")
    sub = p.add_subparsers(dest="job", required=True, parser_class=_Parser)

    r = sub.add_parser("render", help="scenes x spp x seeds [x frames], or --dataset SPEC.json")
    r.add_argument("--scenes", help="comma list of built-in scenes or scene .json files")
    r.add_argument("--spp", default="16", help="comma list of samples per pixel (default 16)")
    r.add_argument("--seeds", default="1", help="comma list of seeds (default 1)")
    r.add_argument("--width", type=int, default=512)
    r.add_argument("--height", type=int, default=512)
    r.add_argument("--max-depth", type=int, default=8)
    r.add_argument("--denoise", default="", help="also denoise each still with these methods (eaw,sure)")
    r.add_argument("--frames", type=int, default=0, help="an animation: one item per frame, frame_NNNN/")
    r.add_argument("--camera-path", default="auto", help="with --frames: auto, static, orbit, dolly, keyframes")
    r.add_argument("--reference-spp", type=int, default=0, help="with --frames: reference.exr per frame")
    r.add_argument("--dataset", metavar="SPEC.json",
                   help="a training set of randomised scenes instead (docs/farm.md, 'Datasets')")
    _run_flags(r)

    d = sub.add_parser("denoise", help="render directories or frame sequences with one method")
    d.add_argument("--in", dest="inputs", action="append", required=True,
                   help="a render directory (color.exr, ...), a frame sequence (frame_NNNN/) or a directory of "
                        "them, such as a render job's --out; repeat or comma-separate")
    d.add_argument("--method", default=names.DEFAULT,
                   help=f"{', '.join(denoise_choices())} (default {names.DEFAULT}: the library's default)")
    d.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="a filter parameter, named as atrous.denoise's keywords (levels=4, sigma_color=0.5)")
    d.add_argument("--plugin", action="append", default=[], metavar="FILE.py|MODULE",
                   help="a Python file or module that adds still methods (atrous.register_method), loaded "
                        "here and in every worker; repeat for more (docs/farm.md, 'Plugins')")
    _run_flags(d)

    e = sub.add_parser("evaluate", help="the quality benchmark: methods x scenes x spp against references")
    e.add_argument("--scenes", default="cornell,cornell-spheres")
    e.add_argument("--spp", default="4,16")
    e.add_argument("--methods", default=",".join(EVAL_METHODS), help=f"comma list from {','.join(eval_choices())} (default {','.join(EVAL_METHODS)})")
    _eval_flags(e)
    e.add_argument("--runs", type=int, default=3, help="timed denoise runs per item after a warm-up (median kept)")
    _run_flags(e)

    s = sub.add_parser("sweep", help=f"a parameter grid of {names.EAW} or {names.SURE} scored against references")
    s.add_argument("--method", default=names.SURE, help=f"{names.EAW} or {names.SURE}")
    s.add_argument("--grid", action="append", required=True, metavar="NAME=V1,V2,...",
                   help="a parameter and its values; repeat for more (the grid is their product)")
    s.add_argument("--scenes", default="cornell")
    s.add_argument("--spp", default="4")
    _eval_flags(s)
    _run_flags(s)
    return p


def _eval_flags(p: argparse.ArgumentParser) -> None:
    p.add_argument("--width", type=int, default=64)
    p.add_argument("--height", type=int, default=64)
    p.add_argument("--ref-spp", type=int, default=256, help="samples per pixel of the references (default 256)")
    p.add_argument("--seed", type=int, default=1, help="seed of the noisy inputs")
    p.add_argument("--ref-seed", type=int, default=1000003, help="seed of the references")
    p.add_argument("--max-depth", type=int, default=8)


def _run_kw(a: argparse.Namespace) -> Dict[str, Any]:
    if a.num_cpus is not None and a.address != "local":
        raise FarmInputError("--num-cpus: only with --address local")
    return {"address": a.address, "cpus_per_task": a.cpus_per_task, "gpus_per_task": a.gpus_per_task,
            "max_retries": a.max_retries, "num_cpus": a.num_cpus, "progress": not a.quiet}


def run(argv: Optional[Sequence[str]] = None) -> JobResult:
    """Parses and runs a command line; raises _Usage / FarmInputError for bad input."""
    a = _parser().parse_args(argv)
    kw = _run_kw(a)
    if a.job == "render":
        if a.dataset:
            if a.scenes:
                raise FarmInputError("--dataset: not with --scenes (the spec makes the scenes)")
            return jobs.render_dataset(a.out, a.dataset, **kw)
        if not a.scenes:
            raise FarmInputError("render: give --scenes (or --dataset SPEC.json)")
        return jobs.render(a.out, a.scenes, a.spp, width=a.width, height=a.height, seeds=a.seeds,
                           max_depth=a.max_depth, denoise=a.denoise, frames=a.frames,
                           camera_path=a.camera_path, reference_spp=a.reference_spp, **kw)
    if a.job == "denoise":
        inputs: List[str] = [p for v in a.inputs for p in v.split(",") if p]
        return jobs.denoise(a.out, inputs, a.method, parse_assignments(a.param, "--param", lists=False),
                            plugins=a.plugin, **kw)
    if a.job == "evaluate":
        return jobs.evaluate(a.out, a.scenes, a.spp, a.methods, width=a.width, height=a.height, ref_spp=a.ref_spp,
                             seed=a.seed, ref_seed=a.ref_seed, runs=a.runs, max_depth=a.max_depth, **kw)
    return jobs.sweep(a.out, a.method, parse_assignments(a.grid, "--grid", lists=True), a.scenes, a.spp,
                      width=a.width, height=a.height, ref_spp=a.ref_spp, seed=a.seed, ref_seed=a.ref_seed,
                      max_depth=a.max_depth, **kw)


def _flag_names(msg: str) -> str:
    """The Python API's messages start with the keyword ("spp: ..."); the CLI names the flag."""
    m = re.match(r"^([a-z_]+):", msg)
    if m and m.group(1) in _KEYWORDS:
        return _FLAGS.get(m.group(1), "--" + m.group(1).replace("_", "-")) + msg[m.end(1):]
    return msg


_KEYWORDS = {"spp", "seeds", "width", "height", "max_depth", "frames", "denoise", "camera_path", "reference_spp",
             "methods", "method", "runs", "ref_spp", "seed", "ref_seed", "grid", "params", "inputs", "scenes"}
_FLAGS = {"params": "--param", "inputs": "--in"}


def main(argv: Optional[Sequence[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        res = run(argv)
    except (_Usage, FarmInputError) as e:
        print(f"atrous-farm: error: {_flag_names(str(e))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("atrous-farm: interrupted; the items done are in the manifest, a rerun finishes the rest",
              file=sys.stderr)
        return 130
    quiet = "--quiet" in argv
    if not quiet:
        print_summary(res)
    for e in res.failed:
        print(f"atrous-farm: {e['id']}: {e.get('error')}", file=sys.stderr)
    if res.ok:
        return 0
    return 2 if all(e.get("error_kind") == "input" for e in res.failed) else 1
