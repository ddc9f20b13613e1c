"""OUT/manifest.json: the job, its items with their parameters, status and timings, and one record
per run (docs/farm.md, "The manifest"). Written under a temporary name and renamed, so a reader
(or a killed driver) never sees half a manifest.
"""
from __future__ import annotations

import datetime as _dt
import json
import math
import os
from pathlib import Path
from typing import Any, Dict, List, Optional

from .items import FarmInputError, Item

FORMAT = "atrous-farm-manifest/1"
NAME = "manifest.json"


def utc_now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if hasattr(x, "item") and callable(x.item):  # numpy scalars
        return _jsonable(x.item())
    return x


def load(out: Path, job: str) -> Optional[Dict[str, Any]]:
    """The manifest of an earlier run in `out`, or None. A manifest of another job, or one that
    cannot be read, is an input error: the directory belongs to something else."""
    path = out / NAME
    if not path.exists():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise FarmInputError(f"{path}: cannot read the manifest of an earlier run ({e}); "
                             "remove it or use another --out")
    if not isinstance(data, dict) or data.get("format") != FORMAT or not isinstance(data.get("items"), list):
        raise FarmInputError(f"{path}: not an atrous farm manifest ({FORMAT}); use another --out")
    if data.get("job") != job:
        raise FarmInputError(f"{path}: holds a '{data.get('job')}' job, not '{job}'; use another --out")
    return data


def is_done(entry: Optional[Dict[str, Any]], item: Item, out: Path) -> bool:
    """An item is skipped when the manifest has it done with the same kind and parameters and
    its outputs are all still there."""
    return (entry is not None and entry.get("status") == "done" and entry.get("kind") == item.kind
            and entry.get("params") == _jsonable(item.params)
            and all((out / o).exists() for o in item.outputs))


class Manifest:
    def __init__(self, out: Path, job: str, spec: Dict[str, Any], items: List[Item],
                 earlier: Optional[Dict[str, Any]]) -> None:
        self.path = out / NAME
        self.out = out
        old = {e["id"]: e for e in (earlier or {}).get("items", []) if isinstance(e, dict) and "id" in e}
        self.data: Dict[str, Any] = {
            "format": FORMAT, "job": job, "spec": _jsonable(spec),
            "created_utc": (earlier or {}).get("created_utc", utc_now()), "updated_utc": utc_now(),
            "runs": list((earlier or {}).get("runs", [])), "items": [],
        }
        self.entries: Dict[str, Dict[str, Any]] = {}
        self.skipped: List[str] = []
        for it in items:
            prev = old.pop(it.id, None)
            if is_done(prev, it, out):
                entry = dict(prev, skipped=True)
                self.skipped.append(it.id)
            else:
                entry = {**it.to_json(), "status": "pending", "error": None, "error_kind": None, "attempts": 0,
                         "node": None, "node_id": None, "pid": None, "submitted_utc": None, "started_utc": None,
                         "finished_utc": None, "seconds": None, "result": None}
            entry["params"] = _jsonable(it.params)
            self.entries[it.id] = entry
            self.data["items"].append(entry)
        # Items of earlier runs that this job does not have: kept, so that the manifest still says
        # what the directory holds.
        for e in old.values():
            self.data["items"].append(dict(e, in_current_job=False))

    def set(self, item_id: str, **fields: Any) -> None:
        self.entries[item_id].update(fields)

    def counts(self) -> Dict[str, int]:
        c = {"done": 0, "failed": 0, "pending": 0}
        for e in self.entries.values():
            c[e["status"]] = c.get(e["status"], 0) + 1
        return c

    def write(self) -> None:
        self.data["updated_utc"] = utc_now()
        tmp = self.path.with_name(f".{NAME}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(_jsonable(self.data), indent=1))
        os.replace(tmp, self.path)
