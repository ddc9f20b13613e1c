"""The driver: connects to Ray, submits one task per item that is not done yet, follows them to
the end, and keeps OUT/manifest.json up to date. Scheduling, placement, retries of dead workers
and the passing of results between items are Ray's; this module only keeps the books.
"""
from __future__ import annotations

import fcntl
import os
import shutil
import socket
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional

from ..eval import out_dir_problem
from .items import FarmInputError, Item
from .manifest import Manifest, load, utc_now
from .progress import Progress, summary_table
from .tasks import PARTIAL, run_item

TASK_NAME = "atrous_farm_item"


@dataclass
class JobResult:
    """What a farm job did. `items` are the manifest entries of this job's items."""

    job: str
    out: Path
    manifest: Path
    items: List[Dict[str, Any]]
    elapsed_s: float
    run: Dict[str, Any] = field(default_factory=dict)

    @property
    def done(self) -> List[str]:
        return [e["id"] for e in self.items if e["status"] == "done"]

    @property
    def failed(self) -> List[Dict[str, Any]]:
        return [e for e in self.items if e["status"] == "failed"]

    @property
    def skipped(self) -> List[str]:
        return [e["id"] for e in self.items if e.get("skipped")]

    @property
    def ok(self) -> bool:
        return not self.failed and all(e["status"] == "done" for e in self.items)


def check_out_dir(out: Path) -> None:
    """OUT must be a writable directory or creatable as one (the same rule as atrous-eval's --out)."""
    problem = out_dir_problem(out)
    if problem:
        raise FarmInputError(problem)


def connect(address: str, num_cpus: Optional[int] = None) -> bool:
    """Starts or joins Ray; returns True when this call started it (and so shuts it down).
    "local": a Ray instance of this process on this machine; "auto": the cluster that `ray start`
    runs on this machine (or RAY_ADDRESS); HOST:PORT: that cluster's head."""
    import ray

    if ray.is_initialized():
        return False
    kw: Dict[str, Any] = {"logging_level": "WARNING", "log_to_driver": False}
    if address == "local":
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        ray.init(num_cpus=num_cpus, include_dashboard=False, **kw)
    else:
        if address != "auto":
            # ray.init waits for minutes on an address where nothing listens: ask the port first.
            host, _, port = address.rpartition(":")
            try:
                socket.create_connection((host.strip("[]"), int(port)), timeout=10).close()
            except (OSError, ValueError) as e:
                raise FarmInputError(f"--address {address}: no Ray head answers there "
                                     f"({getattr(e, 'strerror', None) or e})")
        try:
            ray.init(address=address, **kw)
        except (ConnectionError, RuntimeError, ValueError) as e:
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            chain, c = [], e
            while c is not None and len(chain) < 5:
                chain.append(f"{type(c).__name__} {c}")
                c = c.__cause__ or c.__context__
            if any("Authentication" in x or "auth token" in x.lower() for x in chain):
                first += "; the cluster wants its token: RAY_AUTH_TOKEN_PATH or ~/.ray/auth_token"
            raise FarmInputError(f"--address {address}: cannot join the Ray cluster ({first})")
    return True


def _tracker_class():
    import ray

    @ray.remote(num_cpus=0)
    class Tracker:
        """Which items have started (and how often): the progress line's `running` and the
        manifest's `attempts` (a retry after a dead worker starts the item again)."""

        def __init__(self) -> None:
            self.starts: Dict[str, int] = {}

        def started(self, item_id: str, pid: int, node: str) -> None:
            self.starts[item_id] = self.starts.get(item_id, 0) + 1

        def snapshot(self) -> Dict[str, int]:
            return dict(self.starts)

    return Tracker


def _error_of(exc: BaseException) -> str:
    """One line for a task that Ray gave up on (its worker died max_retries + 1 times, or it raised)."""
    import ray

    if isinstance(exc, ray.exceptions.RayTaskError):
        cause = exc.cause if getattr(exc, "cause", None) is not None else exc
        lines = [ln for ln in str(cause).strip().splitlines() if ln.strip()]
        return f"{type(cause).__name__}: {lines[-1] if lines else cause}"
    lines = [ln for ln in str(exc).strip().splitlines() if ln.strip()]
    return f"{type(exc).__name__}: {lines[0] if lines else ''}"


class _Lock:
    """OUT/.farm.lock, held while a job writes to OUT: a second job on the same OUT is refused."""

    def __init__(self, out: Path) -> None:
        self.f = open(out / ".farm.lock", "w")
        try:
            fcntl.flock(self.f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.f.close()
            raise FarmInputError(f"--out '{out}': another farm job is running on it")

    def release(self) -> None:
        self.f.close()


def run_job(job: str, spec: Dict[str, Any], items: List[Item], out: Path, *, address: str = "local",
            cpus_per_task: float = 1, gpus_per_task: float = 0, max_retries: int = 3,
            num_cpus: Optional[int] = None, progress: bool = True,
            finalize: Optional[Callable[[Manifest], None]] = None) -> JobResult:
    """Runs `items` (skipping those done in an earlier run's manifest) and returns the result."""
    if cpus_per_task <= 0:
        raise FarmInputError(f"--cpus-per-task: must be positive, got {cpus_per_task}")
    if gpus_per_task < 0:
        raise FarmInputError(f"--gpus-per-task: must be 0 or more, got {gpus_per_task}")
    if max_retries < 0:
        raise FarmInputError(f"--max-retries: must be 0 or more, got {max_retries}")
    if address != "local" and address != "auto" and ":" not in address:
        raise FarmInputError(f"--address: expected local, auto or HOST:PORT, got '{address}'")
    out = Path(out).absolute()
    check_out_dir(out)
    t_start = time.perf_counter()
    # Ray first: a cluster that cannot be joined is bad input, and nothing is written then.
    started_ray = False
    if len(Manifest(out, job, spec, items, load(out, job)).skipped) < len(items):
        started_ray = connect(address, num_cpus)
    try:
        out.mkdir(parents=True, exist_ok=True)
        lock = _Lock(out)
    except BaseException:
        _shutdown(started_ray)
        raise
    try:
        shutil.rmtree(out / PARTIAL, ignore_errors=True)  # stray attempts of a killed earlier run
        man = Manifest(out, job, spec, items, load(out, job))  # read again, under the lock
        run: Dict[str, Any] = {"started_utc": utc_now(), "address": address, "cpus_per_task": cpus_per_task,
                               "gpus_per_task": gpus_per_task, "items": len(items), "skipped": len(man.skipped)}
        man.data["runs"].append(run)
        todo = [it for it in items if it.id not in man.skipped]
        if todo and not started_ray:
            started_ray = connect(address, num_cpus)
        bar = Progress(len(items), len(man.skipped), enabled=progress)  # its clock starts with the items
        if todo:
            run.update(_follow(man, todo, out, bar, cpus_per_task, gpus_per_task, max_retries))
        c = man.counts()
        bar.update(c["done"], c["failed"], 0, final=True)
        shutil.rmtree(out / PARTIAL, ignore_errors=True)  # every attempt has ended
        if finalize is not None:
            finalize(man)
        run.update(finished_utc=utc_now(), done=c["done"], failed=c["failed"],
                   elapsed_s=time.perf_counter() - t_start)
        man.write()
    finally:
        lock.release()
        _shutdown(started_ray)
    entries = [man.entries[it.id] for it in items]
    return JobResult(job, out, man.path, entries, time.perf_counter() - t_start, run)


def _shutdown(started_ray: bool) -> None:
    if started_ray:
        import ray

        ray.shutdown()


def _follow(man: Manifest, todo: List[Item], out: Path, bar: Progress, cpus: float, gpus: float,
            max_retries: int) -> Dict[str, Any]:
    import ray

    nodes = [n for n in ray.nodes() if n.get("Alive")]
    node_ip = {n.get("NodeID"): n.get("NodeManagerAddress") for n in nodes}
    info = {"nodes": len(nodes), "cluster_cpus": ray.cluster_resources().get("CPU", 0.0),
            "cluster_gpus": ray.cluster_resources().get("GPU", 0.0), "ray": ray.__version__}
    tracker = _tracker_class().remote()
    threads = max(1, int(cpus))
    device = "cuda" if gpus > 0 else "auto"
    task = ray.remote(run_item).options(name=TASK_NAME, num_cpus=cpus, num_gpus=gpus, max_retries=max_retries,
                                        retry_exceptions=False)
    refs: Dict[str, Any] = {}
    pending: Dict[Any, str] = {}
    for it in todo:  # items come ordered: an item's dependencies before it
        dep_refs = [refs[d] for d in it.deps if d in refs]  # a dependency already done is read from OUT
        ref = task.remote(it.to_json(), str(out), threads, device, tracker, *dep_refs)
        refs[it.id] = ref
        pending[ref] = it.id
        man.set(it.id, status="pending", submitted_utc=utc_now())
    man.write()
    last_write = time.perf_counter()
    starts: Dict[str, int] = {}
    try:
        while pending:
            waiting = list(pending)
            ready, rest = ray.wait(waiting, num_returns=1, timeout=0.25)
            if ready and rest:  # and every other result that is in already
                ready += ray.wait(rest, num_returns=len(rest), timeout=0)[0]
            for ref in ready:
                item_id = pending.pop(ref)
                try:
                    res = ray.get(ref)
                except Exception as e:  # retries used up, or a bug in the task
                    res = {"status": "failed", "error": _error_of(e), "error_kind": "runtime", "result": None}
                man.set(item_id, status=res["status"], error=res.get("error"), error_kind=res.get("error_kind"),
                        result=res.get("result"), node=node_ip.get(res.get("node_id"), res.get("node")),
                        node_id=res.get("node_id"), pid=res.get("pid"),
                        seconds=res.get("seconds"), started_utc=res.get("started_utc"), finished_utc=utc_now())
            try:
                starts = ray.get(tracker.snapshot.remote(), timeout=5)
            except Exception:
                pass
            running = sum(1 for i in pending.values() if starts.get(i, 0) > 0)
            c = man.counts()
            bar.update(c["done"], c["failed"], running)
            if ready and time.perf_counter() - last_write > 1.0:
                man.write()
                last_write = time.perf_counter()
    except KeyboardInterrupt:
        for ref in pending:
            ray.cancel(ref, force=True)
        man.write()
        raise
    try:
        starts = ray.get(tracker.snapshot.remote(), timeout=5)
    except Exception:
        pass
    for it in todo:
        man.set(it.id, attempts=starts.get(it.id, 0))
    ray.kill(tracker)
    return info


def print_summary(res: JobResult, stream=sys.stdout) -> None:
    n = len(res.items)
    ran = n - len(res.skipped)
    rate = ran / res.elapsed_s * 60 if res.elapsed_s > 0 and ran else 0.0
    stream.write(summary_table(res.items) + "\n")
    where = ""
    if res.run.get("nodes"):
        nodes = res.run["nodes"]
        where = f" on {nodes} node{'s' if nodes != 1 else ''} ({res.run['cluster_cpus']:g} CPUs)"
    stream.write(f"{res.job}: {n} items, {len(res.done)} done ({len(res.skipped)} skipped), {len(res.failed)} "
                 f"failed, {res.elapsed_s:.1f} s{where}, {rate:.1f} items/min -> {res.manifest}\n")
    stream.flush()
