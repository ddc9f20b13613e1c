"""The fuzz harness's process watch (fuzz.py): one command run with its own peak memory (the
child's resource usage from os.wait4, not the cumulative RUSAGE_CHILDREN), killed when it passes
the time limit or the memory cap; and the snapshots that tell whether a case changed its input
files or left files behind."""
import hashlib
import json
import os
import select
import signal
import subprocess
import sys
import threading
import time

MEMORY_LIMIT_MB = 300     # the bound for any input under 1 MB
SMALL_INPUT_BYTES = 1 << 20
PAGE = os.sysconf("SC_PAGE_SIZE")


def rss_mb(pid):
    try:
        with open("/proc/%d/statm" % pid) as f:
            return int(f.read().split()[1]) * PAGE / 2.0 ** 20
    except (OSError, ValueError, IndexError):
        return 0.0


# A small process that starts the commands: a child's ru_maxrss includes the resident set of the
# process it was forked from (the kernel keeps the high-water mark across fork and exec), so the
# harness (tens of MB, more as it runs) does not fork them itself. One spawner per worker thread;
# its own resident set (~10 MB) is the floor of every measurement.
SPAWNER = r"""
import json, os, sys
inp, out = sys.stdin, sys.stdout
for line in inp:
    r = json.loads(line)
    pid = os.fork()
    if pid == 0:
        try:
            fo = os.open(r["out"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            fe = os.open(r["err"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            fi = os.open(os.devnull, os.O_RDONLY)
            os.dup2(fi, 0); os.dup2(fo, 1); os.dup2(fe, 2)
            os.closerange(3, 65536)
            if r.get("cwd"):
                os.chdir(r["cwd"])
            os.execv(r["argv"][0], r["argv"])
        finally:
            os._exit(127)
    out.write(json.dumps({"pid": pid}) + "\n"); out.flush()
    _, status, ru = os.wait4(pid, 0)
    out.write(json.dumps({"status": status, "maxrss_kb": ru.ru_maxrss}) + "\n"); out.flush()
"""
_local = threading.local()
_spawners = []


def _spawner(env):
    s = getattr(_local, "spawner", None)
    if s is None or s.poll() is not None:
        s = subprocess.Popen([sys.executable, "-S", "-E", "-c", SPAWNER], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, env=env, bufsize=0)
        s.pending = b""
        _local.spawner = s
        _spawners.append(s)
    return s


def _line(s, wait):
    """The spawner's next line, or None when none came within `wait` seconds (None: block)."""
    while b"\n" not in s.pending:
        ready, _, _ = select.select([s.stdout], [], [], wait)
        if not ready:
            return None
        chunk = os.read(s.stdout.fileno(), 65536)
        if not chunk:
            raise RuntimeError("the fuzz spawner process died")
        s.pending += chunk
    line, s.pending = s.pending.split(b"\n", 1)
    return json.loads(line)


def close_spawners():
    for s in _spawners:
        try:
            s.stdin.close()
            s.wait(timeout=5)
        except (OSError, subprocess.TimeoutExpired):
            s.kill()


def run_watched(argv, timeout, env, cap_mb, log_prefix, cwd=None):
    """Runs argv; stdout/stderr go to log_prefix.out/.err. Returns a dict: rc (negative: signal),
    stdout, stderr, timed_out, mem_killed, peak_mb (the command's own ru_maxrss), seconds."""
    out_path, err_path = log_prefix + ".out", log_prefix + ".err"
    s = _spawner(env)
    t0 = time.time()
    s.stdin.write((json.dumps({"argv": argv, "out": out_path, "err": err_path, "cwd": cwd}) + "\n").encode())
    pid = _line(s, None)["pid"]
    timed_out = mem_killed = False
    seen, delay = 0.0, 0.002
    while True:
        done = _line(s, delay)
        if done is not None:
            break
        r = rss_mb(pid)
        seen = max(seen, r)
        if not timed_out and not mem_killed:
            timed_out = time.time() - t0 > timeout
            mem_killed = not timed_out and r > cap_mb
            if timed_out or mem_killed:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:  # it ended (and was reaped) since the last look
                    pass
        delay = min(delay * 2, 0.05)
    status = done["status"]
    rc = -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)
    out = open(out_path, "rb").read().decode(errors="replace")
    err = open(err_path, "rb").read().decode(errors="replace")
    return {"rc": rc, "stdout": out, "stderr": err, "timed_out": timed_out, "mem_killed": mem_killed,
            "peak_mb": max(done["maxrss_kb"] / 1024.0, seen), "seconds": time.time() - t0}


def _hash(path):
    h = hashlib.sha1()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def snapshot(roots):
    """{path: (size, sha1)} of every regular file at or under the roots (links not followed)."""
    snap = {}
    for r in roots:
        if os.path.isfile(r) and not os.path.islink(r):
            snap[r] = (os.path.getsize(r), _hash(r))
        elif os.path.isdir(r) and not os.path.islink(r):
            for dp, dns, fns in os.walk(r):
                for fn in fns:
                    p = os.path.join(dp, fn)
                    if os.path.isfile(p) and not os.path.islink(p):
                        snap[p] = (os.path.getsize(p), _hash(p))
    return snap


def entries(roots):
    """Every path (file or directory) under the directory roots."""
    seen = set()
    for r in roots:
        if os.path.isdir(r) and not os.path.islink(r):
            for dp, dns, fns in os.walk(r):
                seen.update(os.path.join(dp, n) for n in dns + fns)
    return seen


def modified(before):
    """The first input file changed or removed since `before` (None when all are as they were)."""
    for p, (size, digest) in sorted(before.items()):
        if not os.path.isfile(p):
            return p + " was removed"
        if os.path.getsize(p) != size or _hash(p) != digest:
            return p + " was changed"
    return None


def input_roots(case):
    """The paths a case reads: its own directory and every existing path in its command line
    (the CLI itself excepted), plus any it names explicitly (case.inputs)."""
    roots = [case.dir] if case.dir else []
    for a in case.argv[1:] + list(case.inputs):
        if a and os.path.isabs(a) and os.path.exists(a) and a not in roots:
            roots.append(a)
    return roots
