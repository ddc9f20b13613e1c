"""Items and the check of a job's arguments: everything here runs in the driver, before Ray starts.

An item is one unit of work (one Ray task): an id (also its place under the output directory),
a kind (what tasks.py runs), JSON parameters, the outputs it leaves when done (paths relative to
OUT) and the ids of the items it needs first (evaluate and sweep items need their scene's
reference). Bad arguments raise FarmInputError (a ValueError) naming the flag or file and the
problem, before anything is written.
"""
from __future__ import annotations

import itertools
import json
import re
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Dict, Iterable, List, Optional, Sequence

import numpy as np

import atrous
from atrous import names

__all__ = ["Item", "FarmInputError", "scene_label", "check_scenes", "parse_value", "check_denoise_params",
           "discover_inputs", "denoise_choices", "EVAL_METHODS", "eval_choices", "sequence_row",
           "split_sequence_params"]


def denoise_choices() -> tuple:
    """The still methods, OIDN, and the sequence methods: the library's lists as they are now (with
    the methods a plugin registered)."""
    return atrous.METHODS + ("oidn",) + atrous.SEQUENCE_METHODS


def sequence_row(method: str) -> Optional[Dict[str, Any]]:
    """The registry's row of a sequence method (atrous.sequence_methods()), None for another name."""
    return next((r for r in atrous.sequence_methods() if r["name"] == method), None)


EVAL_METHODS = ("noisy", names.EAW, names.SURE, "oidn")  # the default set


def eval_choices() -> tuple:
    """What an evaluation may ask for: the default set, then the library's other still methods."""
    return EVAL_METHODS + tuple(m for m in atrous.METHODS if m not in EVAL_METHODS)


_FRAME = re.compile(r"^frame_(\d{4,})$")
_SEED_MAX = 2 ** 32 - 1


class FarmInputError(ValueError):
    """Bad input to a farm job (a flag, a spec file, an input directory): raised before any work."""


@dataclass
class Item:
    id: str
    kind: str
    params: Dict[str, Any]
    outputs: List[str]
    deps: List[str] = field(default_factory=list)

    def to_json(self) -> Dict[str, Any]:
        return asdict(self)


# ------------------------------------------------------------------------------------ checks

def positive_int(value: Any, name: str, minimum: int = 1, maximum: Optional[int] = None) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise FarmInputError(f"{name}: expected an integer, got {value!r}")
    if value < minimum or (maximum is not None and value > maximum):
        rng = f"{minimum}..{maximum}" if maximum is not None else f">= {minimum}"
        raise FarmInputError(f"{name}: must be {rng}, got {value}")
    return int(value)


def int_list(values: Any, name: str, minimum: int = 1, maximum: Optional[int] = None) -> List[int]:
    if isinstance(values, str):
        try:
            values = [int(v) for v in values.split(",") if v.strip()]
        except ValueError:
            raise FarmInputError(f"{name}: expected a comma list of integers, got '{values}'")
    if isinstance(values, (int, np.integer)) and not isinstance(values, bool):
        values = [values]
    values = list(values)
    if not values:
        raise FarmInputError(f"{name}: empty list")
    out = [positive_int(v, name, minimum, maximum) for v in values]
    if len(set(out)) != len(out):
        raise FarmInputError(f"{name}: a value is repeated in {out}")
    return out


def name_list(values: Any, name: str) -> List[str]:
    if isinstance(values, str):
        values = [v.strip() for v in values.split(",")]
    values = [str(v) for v in values]
    if not values or any(not v for v in values):
        raise FarmInputError(f"{name}: empty name in {values!r}")
    if len(set(values)) != len(values):
        raise FarmInputError(f"{name}: a value is repeated in {values}")
    return values


def scene_label(scene: str) -> str:
    """The name of a scene's outputs: a built-in's name, or a scene file's stem."""
    return scene if scene in atrous.builtin_scenes() else Path(scene).stem


def check_scenes(scenes: Any, flag: str = "--scenes") -> List[str]:
    """Built-in names as they are, scene files as absolute paths (workers on other nodes read them
    through the shared filesystem). A file is only checked to exist here: a malformed one fails
    its own items, in the worker, and the others go on."""
    known = set(atrous.builtin_scenes())
    out = []
    for s in name_list(scenes, flag):
        if s in known:
            out.append(s)
        elif Path(s).is_file():
            out.append(str(Path(s).resolve()))
        else:
            raise FarmInputError(f"{flag}: '{s}' is neither a built-in scene ({', '.join(sorted(known))}) "
                                 "nor a scene file")
    labels = [scene_label(s) for s in out]
    dup = sorted({x for x in labels if labels.count(x) > 1})
    if dup:
        raise FarmInputError(f"{flag}: two scenes would write to the same directory '{dup[0]}' (rename a file)")
    return out


def parse_value(text: str) -> Any:
    """A parameter value from the command line: int, float, true/false, else the string."""
    t = text.strip()
    if t.lower() in ("true", "false"):
        return t.lower() == "true"
    for conv in (int, float):
        try:
            return conv(t)
        except ValueError:
            pass
    return t


def parse_assignments(pairs: Iterable[str], flag: str, lists: bool) -> Dict[str, Any]:
    """NAME=VALUE (or NAME=V1,V2,... with lists) pairs into a dict."""
    out: Dict[str, Any] = {}
    for pair in pairs:
        name, eq, value = pair.partition("=")
        name = name.strip().replace("-", "_")
        if not eq or not name or not value.strip():
            raise FarmInputError(f"{flag}: expected NAME=VALUE{',VALUE...' if lists else ''}, got '{pair}'")
        if name in out:
            raise FarmInputError(f"{flag}: '{name}' given twice")
        out[name] = [parse_value(v) for v in value.split(",")] if lists else parse_value(value)
    return out


_PROBE = np.full((8, 8, 3), 0.5, np.float32)


def split_sequence_params(method: str, params: Dict[str, Any]):
    """A sequence method's parameters: (its own table's; the still method it ends with, spatial=...,
    default auto; that still method's). A method that ends with a still method takes its own as
    <table>_<name> (the CLI's --<table>-<name>: temporal_radius), the rest being the still
    method's; one that does not takes its own table's names as they are."""
    row = sequence_row(method) or {}
    if not row.get("still_method"):
        return dict(params), names.DEFAULT, {}
    prefix = f"{row['params']}_"
    own = {k[len(prefix):]: v for k, v in params.items() if k.startswith(prefix)}
    still = {k: v for k, v in params.items() if not k.startswith(prefix) and k != "spatial"}
    return own, str(params.get("spatial", names.DEFAULT)), still


def check_denoise_params(method: str, params: Dict[str, Any], flag: str) -> None:
    """Denoises an 8x8 grey image with these parameters (a sequence method: makes its denoiser), so
    that an unknown name or an out-of-range value fails here, once, instead of in every item."""
    try:
        if method in atrous.METHODS:
            atrous.denoise(_PROBE, albedo=_PROBE, normal=_PROBE, method=method, **params)
        elif method in atrous.SEQUENCE_METHODS:
            own, spatial, still = split_sequence_params(method, params)
            atrous.SequenceDenoiser(method, device="cpu", spatial=spatial, params=own, **still)
        elif params:
            raise FarmInputError(f"{flag}: {method} takes no parameters (got {', '.join(params)})")
    except FarmInputError:
        raise
    except (ValueError, TypeError) as e:
        raise FarmInputError(f"{flag}: {e}")


def grid_points(grid: Dict[str, List[Any]]) -> List[Dict[str, Any]]:
    names = list(grid)
    return [dict(zip(names, combo)) for combo in itertools.product(*(grid[n] for n in names))]


def params_label(params: Dict[str, Any]) -> str:
    """A directory name for one point of a grid: levels=4,sigma_color=0.5."""
    return ",".join(f"{k}={json.dumps(v) if isinstance(v, bool) else v}" for k, v in params.items()) or "defaults"


# ------------------------------------------------------------------------------------ inputs

def _is_sequence(d: Path) -> bool:
    return any(p.is_dir() and _FRAME.match(p.name) for p in d.iterdir())


def _inputs_below(d: Path, depth: int) -> List[Path]:
    level = [d]
    for _ in range(depth):
        level = sorted(p for q in level for p in q.iterdir() if p.is_dir() and not p.name.startswith("."))
    return [p for p in level if (p / "color.exr").is_file() or _is_sequence(p)]


def discover_inputs(paths: Sequence[str], flag: str = "--in") -> List[Dict[str, Any]]:
    """Render directories (color.exr and its buffers, as `atrous render --out` writes) and frame
    sequences (frame_NNNN/, `atrous render --frames`) given directly, or one level down (a farm
    render job's output directory), or two (a dataset's: scene_NNNNNN/spp_N/).
    Returns [{"name", "kind": render|sequence, "path", "frames"}]."""
    found: List[Dict[str, Any]] = []
    for raw in paths:
        d = Path(raw)
        if not d.is_dir():
            raise FarmInputError(f"{flag} '{raw}': not a directory")
        if (d / "color.exr").is_file() or _is_sequence(d):
            cands, base = [d], d.parent
        else:
            # A render job's --out (render directories one level down) or a dataset's (two levels:
            # scene_NNNNNN/spp_N/); names are the paths below d, so they stay apart.
            base = d
            cands = _inputs_below(d, 1) or _inputs_below(d, 2)
            if not cands:
                raise FarmInputError(f"{flag} '{raw}': no color.exr, frame_NNNN/ directory or render "
                                     "directory (one or two levels down) in it")
        for c in cands:
            name = str(c.relative_to(base)) if base != d.parent else c.name
            if (c / "color.exr").is_file():
                found.append({"name": name, "kind": "render", "path": str(c.resolve()), "frames": []})
                continue
            frames = sorted((int(m.group(1)), p) for p in c.iterdir() if p.is_dir() and (m := _FRAME.match(p.name)))
            for (a, _), (b, pb) in zip(frames, frames[1:]):
                if b != a + 1:
                    raise FarmInputError(f"{flag}: {c}: frame_{a + 1:04d} is missing (gap before {pb.name})")
            for _, p in frames:
                if not (p / "color.exr").is_file():
                    raise FarmInputError(f"{flag}: {p / 'color.exr'}: missing")
            found.append({"name": name, "kind": "sequence", "path": str(c.resolve()),
                          "frames": [p.name for _, p in frames]})
    names = [f["name"] for f in found]
    dup = sorted({x for x in names if names.count(x) > 1})
    if dup:
        raise FarmInputError(f"{flag}: two inputs are both called '{dup[0]}' (their outputs would collide)")
    return found
