#!/usr/bin/env python3
"""Helpers of scripts/gpu-pack.sh and scripts/gpu-check.sh (standard library only: the GPU machine
has Python 3.12 and nothing installed for this project).

  sync SRC DST              make DST a copy of SRC, rewriting only files whose bytes differ (so a
                            rebuild from a fresh `git archive` snapshot recompiles what changed only)
  fatbin-arch FILE...       the CUDA code each ELF file embeds, from its .nv_fatbin section
                            (cuobjdump --list-elf without the CUDA toolkit's cuobjdump): JSON
                            {file: {"sass": ["sm_90"], "ptx": [...]}}
  untar ARCHIVE DIR         tar -x without the tar program's xz (Python's lzma)
  deb-extract DEB DIR       what `dpkg -x DEB DIR` does (ar archive, data.tar.{xz,gz,zst}) where dpkg
                            is missing; zst needs the zstd program
  gtest-count JSON...       tests / failures / skipped of --gtest_output=json files, one JSON line
  oidn-json LOG             oidnBenchmark's "NAME ... N msec/image" lines as JSON
  summary STEPS.tsv OUT     the step table (name, status, rc, seconds, log, note) as OUT (JSON); ok
                            when every step is ok or skipped (absent on purpose, e.g. no OIDN)
"""
import glob
import json
import os
import shutil
import struct
import subprocess
import sys
import tarfile

# Our own archives: keep links and modes as they are (Python 3.14 filters by default).
TRUSTED = {"filter": "fully_trusted"} if hasattr(tarfile, "fully_trusted_filter") else {}


def sync(src, dst):
    seen = set()
    changed = 0
    for root, dirs, files in os.walk(src):
        rel = os.path.relpath(root, src)
        os.makedirs(os.path.join(dst, rel), exist_ok=True)
        for f in files:
            s = os.path.join(root, f)
            d = os.path.normpath(os.path.join(dst, rel, f))
            seen.add(d)
            if os.path.islink(s):
                if os.path.lexists(d) and (not os.path.islink(d) or os.readlink(d) != os.readlink(s)):
                    os.remove(d)
                if not os.path.lexists(d):
                    os.symlink(os.readlink(s), d)
                continue
            with open(s, "rb") as fs:
                data = fs.read()
            if os.path.isfile(d) and not os.path.islink(d):
                with open(d, "rb") as fd:
                    if fd.read() == data:
                        continue
            if os.path.lexists(d):
                os.remove(d)
            with open(d, "wb") as fd:
                fd.write(data)
            shutil.copymode(s, d)
            changed += 1
    removed = 0
    for root, dirs, files in os.walk(dst):
        for f in files:
            d = os.path.normpath(os.path.join(root, f))
            if d not in seen:
                os.remove(d)
                removed += 1
    print(f"sync: {changed} file(s) updated, {removed} removed")


def elf_section(path, name):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x7fELF" or data[4] != 2:
        return None
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x3A)
    def sh(i):
        return struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize)
    stroff = sh(shstrndx)[4]
    for i in range(shnum):
        s = sh(i)
        end = data.index(b"\0", stroff + s[0])
        if data[stroff + s[0]:end].decode() == name:
            return data[s[4]:s[4] + s[5]]
    return None


def fatbin_arch(paths):
    # Fat binary layout (as cuobjdump reads it): a 16-byte header (magic 0xBA55ED50, version,
    # header size, payload size) followed by entries, each with its own header: kind (1 PTX, 2 ELF)
    # at 0, header size at 4, payload size at 8, the SM version at 28. Several fat binaries may
    # follow each other in the section (one per translation unit).
    out = {}
    for p in paths:
        sass, ptx = set(), set()
        sec = elf_section(p, ".nv_fatbin")
        off = 0
        while sec is not None and off + 16 <= len(sec):
            magic, _ver, hsize, size = struct.unpack_from("<IHHQ", sec, off)
            if magic != 0xBA55ED50:
                off += 8  # sections are 8-aligned: skip padding
                continue
            e = off + hsize
            while e + 32 <= off + hsize + size:
                kind, _v, ehsize, payload = struct.unpack_from("<HHIQ", sec, e)
                arch, = struct.unpack_from("<I", sec, e + 28)
                (ptx if kind == 1 else sass).add(f"sm_{arch}" if kind != 1 else f"compute_{arch}")
                e += ehsize + payload
            off += hsize + size
        out[p] = {"sass": sorted(sass), "ptx": sorted(ptx), "has_fatbin": sec is not None}
    print(json.dumps(out, indent=1))


def deb_extract(deb, dest):
    with open(deb, "rb") as f:
        data = f.read()
    if data[:8] != b"!<arch>\n":
        sys.exit(f"{deb}: not an ar archive")
    off = 8
    while off + 60 <= len(data):
        name = data[off:off + 16].decode().strip().rstrip("/")
        size = int(data[off + 48:off + 58].decode().strip())
        body = data[off + 60:off + 60 + size]
        if name.startswith("data.tar"):
            os.makedirs(dest, exist_ok=True)
            tmp = os.path.join(dest, ".deb-" + name)
            with open(tmp, "wb") as t:
                t.write(body)
            try:
                if name.endswith(".zst"):
                    subprocess.run(["tar", "--zstd", "-xf", tmp, "-C", dest], check=True)
                else:
                    with tarfile.open(tmp) as t:
                        t.extractall(dest, **TRUSTED)
            finally:
                os.remove(tmp)
            return
        off += 60 + size + (size & 1)
    sys.exit(f"{deb}: no data.tar member")


def untar(archive, dest):
    with tarfile.open(archive) as t:
        t.extractall(dest, **TRUSTED)


def gtest_count(paths):
    tot = {"tests": 0, "failures": 0, "skipped": 0, "files": 0}
    for p in paths:
        try:
            with open(p) as f:
                j = json.load(f)
        except (OSError, ValueError):
            continue
        tot["files"] += 1
        tot["tests"] += j.get("tests", 0)
        tot["failures"] += j.get("failures", 0)
        for s in j.get("testsuites", []):
            for t in s.get("testsuite", []):
                if t.get("result") == "SKIPPED" or t.get("status") == "NOTRUN":
                    tot["skipped"] += 1
    print(json.dumps(tot))


def oidn_json(log):
    rows = []
    with open(log, errors="replace") as f:
        for line in f:
            # e.g. "RT.hdr_alb_nrm.1920x1080 ... 6.22 msec/image"
            if "msec/image" not in line:
                continue
            parts = line.split()
            name = parts[0]
            try:
                ms = float(parts[parts.index("msec/image") - 1])
            except (ValueError, IndexError):
                continue
            size = name.rsplit(".", 1)[-1]
            w, _, h = size.partition("x")
            rows.append({"what": "oidn", "benchmark": name, "width": int(w) if w.isdigit() else None,
                         "height": int(h) if h.isdigit() else None, "msec_per_image": ms})
    print(json.dumps({"results": rows}, indent=1))


def summary(tsv, out):
    steps = []
    with open(tsv) as f:
        for line in f:
            name, status, rc, secs, log, note = (line.rstrip("\n").split("\t") + [""] * 6)[:6]
            steps.append({"step": name, "status": status, "rc": int(rc) if rc.lstrip("-").isdigit() else None,
                          "seconds": float(secs) if secs else None, "log": log, "note": note})
    doc = {"ok": all(s["status"] in ("ok", "skipped") for s in steps),
           "failed": [s["step"] for s in steps if s["status"] not in ("ok", "skipped")], "steps": steps}
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
    print(json.dumps({"ok": doc["ok"], "failed": doc["failed"]}))


def variants(folder):
    """The variants step's table: per size, method and build, the median of the rounds' medians."""
    import statistics
    rows = {}
    for f in glob.glob(os.path.join(folder, "variant_*.json")):
        v, size = os.path.basename(f)[len("variant_"):].rsplit("_r", 1)[0].rsplit("_", 1)
        for r in json.load(open(f))["results"]:
            rows.setdefault((size, r["what"], v), []).append(r["median_ms"])
    table = [{"size": k[0], "what": k[1], "build": k[2], "median_ms": statistics.median(t), "rounds_ms": t}
             for k, t in sorted(rows.items())]
    with open(os.path.join(folder, "variants.json"), "w") as f:
        json.dump(table, f, indent=1)
    for r in table:
        print(f"{r['size']:>10} {r['what']:8} {r['build']:8} {r['median_ms']:8.3f} ms  rounds {r['rounds_ms']}")


if __name__ == "__main__":
    cmd, args = sys.argv[1], sys.argv[2:]
    {"sync": lambda: sync(*args), "fatbin-arch": lambda: fatbin_arch(args),
     "deb-extract": lambda: deb_extract(*args), "untar": lambda: untar(*args), "gtest-count": lambda: gtest_count(args),
     "oidn-json": lambda: oidn_json(args[0]), "summary": lambda: summary(*args),
     "variants": lambda: variants(args[0])}[cmd]()
