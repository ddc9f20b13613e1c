"""atrous-eval's command line (python -m atrous.eval [scenes]): the flags, checked before any work.
Bad input raises UsageError (one line on stderr, exit status 2)."""
from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import List, Optional, Sequence

import atrous

from ..plugins import load_plugins, resolve_plugins

class UsageError(SystemExit):
    """Bad input on the command line, raised before anything is rendered or written; main()
    prints it as one line on stderr and returns exit status 2 (the project's CLI rule)."""

    def __init__(self, message: str):
        super().__init__(2)
        self.message = message

    def __str__(self) -> str:
        return self.message


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse's own errors (unknown flag, --runs abc): one line, 2
        raise UsageError(f"{message} (see --help)")


def _int_list(text: str, flag: str) -> List[int]:
    try:
        vals = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UsageError(f"{flag}: expected a comma list of integers, got '{text}'")
    if not vals or any(v <= 0 for v in vals):
        raise UsageError(f"{flag}: values must be positive, got '{text}'")
    return vals


def out_dir_problem(out) -> Optional[str]:
    """Why --out cannot be used as the output directory (it must be a writable directory or
    creatable as one), or None; nothing is created here. Also atrous.farm's check."""
    p = Path(out)
    if p.exists():
        if not p.is_dir():
            return f"--out '{out}': exists and is not a directory"
        if not os.access(p, os.W_OK | os.X_OK):
            return f"--out '{out}': directory is not writable"
        return None
    parent = p.absolute().parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        return f"--out '{out}': {parent} is not a directory"
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"--out '{out}': cannot create it ({parent} is not writable)"
    return None


def _check_out_dir(out: str) -> None:
    problem = out_dir_problem(out)
    if problem:
        raise UsageError(problem)


def _check_sequence(seq_dir: str) -> None:
    """The frame directories and their required buffers exist (pixels are read later)."""
    from . import sequence as seq

    try:
        frames = seq.list_frames(seq_dir)
    except ValueError as e:
        raise UsageError(f"--sequence: {e}")
    for f in frames:
        for name in seq.REQUIRED:
            if not (f / f"{name}.exr").is_file():
                raise UsageError(f"--sequence: {f / (name + '.exr')}: missing (every frame needs {name}.exr)")


def parse_args(argv: Optional[Sequence[str]] = None) -> EvalConfig:
    """The EvalConfig of a command line. Every argument is checked here, before any work: bad
    input raises UsageError (a SystemExit with status 2 after one line on stderr)."""
    from . import DEFAULT_METHODS, EvalConfig, all_methods, quick_config
    from . import __doc__ as doc

    p = _Parser(prog="atrous-eval", description=doc.split("\n\n")[0],
                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="eval-out", help="output directory (report.html, *.png, results.json)")
    p.add_argument("--quick", action="store_true",
                   help="CI size: scenes cornell,cornell-spheres, 64x64, spp 4,16, reference 256 spp, 3 runs")
    p.add_argument("--scenes", help="comma list of built-in scenes or scene .json files (default: all built-in)")
    p.add_argument("--spp", help="comma list of input samples per pixel (default 4,16,64)")
    p.add_argument("--size", help="image size, N or WxH (default 256)")
    p.add_argument("--ref-spp", type=int, help="samples per pixel of the references (default 1024)")
    p.add_argument("--methods", help=f"comma list from {','.join(all_methods())} "
                   f"(default: {','.join(DEFAULT_METHODS)})")
    p.add_argument("--plugin", action="append", default=[], metavar="FILE.py|MODULE",
                   help="a Python file or module that adds still methods (atrous.register_method), loaded "
                        "before --methods is checked; repeat for more")
    p.add_argument("--learned-weights", metavar="FILE",
                   help="weight file of the learned filter for learned/auto (default: the built-in weights)")
    p.add_argument("--runs", type=int, help="timed runs per method, after a warm-up; the median is kept (default 5)")
    p.add_argument("--seed", type=int, help="seed of the noisy inputs, 0..2^32-1 (references use another)")
    p.add_argument("--resolutions", help="comma list of square sizes for runtime vs resolution (default 128,256,512; "
                   "'0' to skip)")
    p.add_argument("--no-equal-time", action="store_true", help="skip the equal-time renders")
    p.add_argument("--sequence", help="frame-sequence directory (frame_NNNN/color.exr ...) to add the SVGF column")
    p.add_argument("--static-sequence", type=int, default=0, metavar="N",
                   help="synthesise an N-frame static-camera sequence (1 spp frames) and evaluate it")
    p.add_argument("--sequence-scene", default="cornell-point",
                   help="scene of --static-sequence (default cornell-point: no emitter in view)")
    a = p.parse_args(argv)
    try:
        load_plugins(resolve_plugins(a.plugin))
    except ValueError as e:
        raise UsageError(str(e))
    cfg = quick_config(a.out) if a.quick else EvalConfig(out=a.out)
    if a.scenes is not None:
        cfg.scenes = [s.strip() for s in a.scenes.split(",") if s.strip()]
        if not cfg.scenes:
            raise UsageError(f"--scenes: no scene in '{a.scenes}'")
    if a.spp is not None:
        cfg.spp = _int_list(a.spp, "--spp")
    if a.size is not None:
        try:
            parts = [int(v) for v in a.size.lower().split("x")]
            if len(parts) > 2:
                raise ValueError(a.size)
            cfg.width, cfg.height = (parts[0], parts[0]) if len(parts) == 1 else (parts[0], parts[1])
        except (ValueError, IndexError):
            raise UsageError(f"--size: expected N or WxH, got '{a.size}'")
        if cfg.width <= 0 or cfg.height <= 0:
            raise UsageError(f"--size: must be positive, got '{a.size}'")
    if a.ref_spp is not None:
        if a.ref_spp <= 0:
            raise UsageError(f"--ref-spp: must be positive, got {a.ref_spp}")
        cfg.ref_spp = a.ref_spp
    if a.methods is not None:
        cfg.methods = [m.strip() for m in a.methods.split(",") if m.strip()]
        bad = [m for m in cfg.methods if m not in all_methods()]
        if bad or not cfg.methods:
            raise UsageError(f"--methods: unknown {', '.join(bad) or repr(a.methods)} "
                             f"(expected {', '.join(all_methods())})")
    if a.learned_weights is not None:
        if not os.path.isfile(a.learned_weights):
            raise UsageError(f"--learned-weights: '{a.learned_weights}' is not a file")
        cfg.learned_weights = a.learned_weights
    if a.runs is not None:
        if a.runs < 1:
            raise UsageError(f"--runs: must be at least 1, got {a.runs}")
        cfg.runs = a.runs
    if a.seed is not None:
        if not 0 <= a.seed < 2 ** 32:
            raise UsageError(f"--seed: must be in 0..{2 ** 32 - 1}, got {a.seed}")
        cfg.seed = a.seed
    if a.resolutions is not None:
        cfg.resolutions = [] if a.resolutions.strip() == "0" else _int_list(a.resolutions, "--resolutions")
    cfg.equal_time = not a.no_equal_time
    if a.static_sequence < 0:
        raise UsageError(f"--static-sequence: must be 0 or more, got {a.static_sequence}")
    cfg.sequence = a.sequence
    cfg.static_sequence = a.static_sequence
    cfg.sequence_scene = a.sequence_scene
    if cfg.static_sequence and cfg.sequence:
        raise UsageError("give --sequence or --static-sequence, not both")
    known = set(atrous.builtin_scenes())
    for s in cfg.scenes:
        if s not in known and not Path(s).is_file():
            raise UsageError(f"--scenes: '{s}' is neither a built-in scene ({', '.join(sorted(known))}) nor a scene file")
    if cfg.static_sequence and cfg.sequence_scene not in known and not Path(cfg.sequence_scene).is_file():
        raise UsageError(f"--sequence-scene: '{cfg.sequence_scene}' is neither a built-in scene "
                         f"({', '.join(sorted(known))}) nor a scene file")
    if cfg.sequence is not None:
        _check_sequence(cfg.sequence)
    _check_out_dir(cfg.out)
    return cfg


