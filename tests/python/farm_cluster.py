"""A real Ray cluster on this machine for the farm tests: `ray start --head` plus worker nodes, each
a `ray start --block` process of this test run (stopped by SIGTERM to that process, which ends its
raylet and workers; nothing else on the machine is touched).

The nodes are started with --node-ip-address=127.0.0.1 and the jobs join at 127.0.0.1:PORT, but
Ray 2.60 registers a node given a loopback address under the machine's reachable one instead
(ray._private.services.resolve_ip_for_localhost), so the manifest's `node` is that address. The
head has no CPUs, so every item runs on a worker node; each worker node has one CPU, so two
workers run two items at once. The cluster's token (Ray's token authentication) and its temp
directory are private to the run.
"""
from __future__ import annotations

import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Dict, List

RAY = str(Path(sys.executable).with_name("ray"))


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LocalCluster:
    def __init__(self, workers: int = 2, cpus_per_worker: int = 1) -> None:
        # Unix socket paths must stay short: a short directory directly under /tmp.
        self.temp = tempfile.mkdtemp(prefix="rf", dir="/tmp")
        token = Path(self.temp) / "token"
        token.write_text(secrets.token_hex(32))
        self.env: Dict[str, str] = dict(os.environ, RAY_AUTH_MODE="token", RAY_AUTH_TOKEN_PATH=str(token),
                                        RAY_USAGE_STATS_ENABLED="0")
        self.port = _free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.procs: List[subprocess.Popen] = []
        try:
            self._start(["--head", f"--port={self.port}", "--num-cpus=0", f"--temp-dir={self.temp}",
                         "--include-dashboard=false"], "head")
            self._wait_nodes(1)
            for i in range(workers):
                self._start([f"--address={self.address}", f"--num-cpus={cpus_per_worker}"], f"worker{i}")
                self._wait_nodes(2 + i)
        except BaseException:
            self.stop()
            raise

    def _start(self, args: List[str], name: str) -> None:
        log = open(Path(self.temp) / f"{name}.log", "w")
        cmd = [RAY, "start", "--block", "--node-ip-address=127.0.0.1", "--disable-usage-stats", *args]
        self.procs.append(subprocess.Popen(cmd, env=self.env, stdout=log, stderr=subprocess.STDOUT,
                                           stdin=subprocess.DEVNULL))

    def _wait_nodes(self, n: int, timeout: float = 60.0) -> None:
        """Waits until `n` nodes are alive (asked with a short-lived `ray` driver process)."""
        probe = ("import ray,sys; ray.init(address=sys.argv[1], logging_level='ERROR'); "
                 "print(sum(1 for x in ray.nodes() if x['Alive']))")
        t0 = time.time()
        while time.time() - t0 < timeout:
            for p in self.procs:
                if p.poll() is not None:
                    raise RuntimeError(f"ray start exited with {p.returncode}: see {self.temp}/*.log")
            r = subprocess.run([sys.executable, "-c", probe, self.address], env=self.env,
                               capture_output=True, text=True, timeout=60)
            if r.returncode == 0 and r.stdout.strip().splitlines()[-1:] == [str(n)]:
                return
            time.sleep(0.5)
        raise RuntimeError(f"the local Ray cluster did not reach {n} nodes in {timeout:.0f} s ({self.temp})")

    def stop(self) -> None:
        for p in reversed(self.procs):  # workers first, then the head
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        for p in self.procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        self.procs = []
        shutil.rmtree(self.temp, ignore_errors=True)
