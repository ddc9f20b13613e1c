"""The progress line (stderr) and the summary table (stdout) of a farm job."""
from __future__ import annotations

import sys
import time
from typing import Any, Dict, List, Optional, TextIO


def fmt_duration(s: Optional[float]) -> str:
    if s is None:
        return "--:--"
    s = int(round(s))
    h, rem = divmod(s, 3600)
    m, sec = divmod(rem, 60)
    return f"{h}:{m:02d}:{sec:02d}" if h else f"{m}:{sec:02d}"


class Progress:
    """`[#####.....] 7/12 done, 1 failed, 2 running, 2 queued, 0:03 elapsed, ETA 0:04`.

    On a terminal the line is redrawn in place (at most 10 times a second); elsewhere (a CI log)
    one line, without the bar, each time an item finishes, as `atrous denoise --sequence` counts
    its frames (`7/12 done, ...`), and at the end. The ETA is the
    mean time per finished item of this run times the items left (with several workers, items
    finish several at a time, and so does the estimate).
    """

    def __init__(self, total: int, skipped: int, enabled: bool = True, stream: TextIO = sys.stderr) -> None:
        self.total, self.skipped = total, skipped
        self.enabled = enabled
        self.stream = stream
        self.tty = enabled and hasattr(stream, "isatty") and stream.isatty()
        self.t0 = time.perf_counter()
        self.last = self.t0
        self.done = self.failed = self.running = 0
        self.changed = False

    def line(self, bar: bool = True) -> str:
        finished = self.done + self.failed
        left = self.total - finished
        elapsed = time.perf_counter() - self.t0
        ran = finished - self.skipped
        eta = elapsed / ran * left if ran > 0 else None
        width = 24
        fill = int(width * finished / self.total) if self.total else width
        queued = max(0, left - self.running)
        return ((f"[{'#' * fill}{'.' * (width - fill)}] " if bar else "") + f"{self.done}/{self.total} done"
                + (f" ({self.skipped} skipped)" if self.skipped else "")
                + f", {self.failed} failed, {self.running} running, {queued} queued, "
                + f"{fmt_duration(elapsed)} elapsed, ETA {fmt_duration(0.0 if left == 0 else eta)}")

    def update(self, done: int, failed: int, running: int, final: bool = False) -> None:
        if (done, failed) != (self.done, self.failed):
            self.changed = True
        self.done, self.failed, self.running = done, failed, running
        if not self.enabled:
            return
        now = time.perf_counter()
        if self.tty:
            if final or now - self.last >= 0.1:
                self.stream.write("\r\x1b[2K" + self.line() + ("\n" if final else ""))
                self.stream.flush()
                self.last = now
        elif final or self.changed:
            self.stream.write(self.line(bar=False) + "\n")
            self.stream.flush()
            self.last, self.changed = now, False


def summary_table(entries: List[Dict[str, Any]], max_rows: int = 40) -> str:
    """One row per item (failed ones first; at most max_rows, the rest counted)."""
    rows = sorted(entries, key=lambda e: (e["status"] != "failed", e["id"]))
    head = ("item", "status", "seconds", "tries", "node", "note")
    body = []
    for e in rows[:max_rows]:
        status = "skipped" if e.get("skipped") else e["status"]
        secs = "" if e.get("seconds") is None else f"{e['seconds']:.2f}"
        note = e.get("error") or ""
        body.append((e["id"], status, secs, str(e.get("attempts") or ""), str(e.get("node") or ""),
                     note if len(note) <= 100 else note[:97] + "..."))
    widths = [max(len(h), *(len(r[i]) for r in body)) if body else len(h) for i, h in enumerate(head)]
    out = ["  ".join(h.ljust(w) for h, w in zip(head, widths)).rstrip(),
           "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in body]
    if len(rows) > max_rows:
        out.append(f"... and {len(rows) - max_rows} more (all of them in the manifest)")
    return "\n".join(out)
