#!/usr/bin/env python3
"""The layers of docs/architecture.md ("The system on one page"), checked on every #include.

Each file of the library and of the front-ends belongs to one layer (LAYERS: the longest matching
path wins); a layer may include its own headers and those of the layers ALLOWED lists for it, and
nothing else: core depends on nothing above it, render, io and filters only on core (and render on
io's image reader, for a scene's textures and sky maps), the sessions on those four, the front-ends
on the public headers (include/atrous) of every layer and on their own files. Tests and benchmarks
are white-box users and are not checked.

    tests/layer_includes.py [ROOT]     exit 1 and one line per include that breaks the drawing

ctest runs it (the test LayerIncludes).
"""
import os
import re
import sys

# Path (a folder with a trailing '/', or a file) -> layer. The backends' folders hold each layer's
# code for that backend: src/cpu the filters' row loops, src/cuda core's executor and memory, the
# renderer's kernels and the filters' pipelines.
LAYERS = {
    "src/core/": "core",
    "include/atrous/image.h": "core",
    "include/atrous/device.h": "core",
    "include/atrous/platform.h": "core",
    "include/atrous/error.h": "core",
    "include/atrous/buffers.h": "core",
    "include/atrous/math.h": "core",
    "include/atrous/interop.h": "core",
    "include/atrous/stage_time.h": "core",
    "include/atrous/timer.h": "core",
    "include/atrous/srgb.h": "core",
    "include/atrous/param_table.h": "core",
    "include/atrous/cuda_check.cuh": "core",
    "src/cuda/cuda_exec.cuh": "core",
    "src/cuda/device_buffer.cuh": "core",
    "src/cuda/cuda_memory.cu": "core",
    "src/cuda/cuda_strided.cu": "core",
    "src/render/": "render",
    "include/atrous/render.h": "render",
    "include/atrous/camera.h": "render",
    "src/cuda/cuda_render.cu": "render",
    "src/cuda/cuda_bvh.cuh": "render",
    "src/cuda/cuda_accumulate.cu": "render",
    "src/io/": "io",
    "include/atrous/io.h": "io",
    "include/atrous/io/": "io",
    "src/filters/": "filters",
    "src/cpu/": "filters",
    "src/cuda/": "filters",
    "include/atrous/denoise.h": "filters",
    "include/atrous/svgf.h": "filters",
    "include/atrous/temporal.h": "filters",
    "include/atrous/learned.h": "filters",
    "include/atrous/refine.h": "filters",
    "include/atrous/params.h": "filters",
    "include/atrous/metrics.h": "filters",
    "include/atrous/param_set.h": "filters",
    "include/atrous/sequence_methods.h": "filters",
    "src/api/": "sessions",
    "include/atrous/sequence.h": "sessions",
    "include/atrous/view_pipeline.h": "sessions",
    "include/atrous/plugins.h": "sessions",
    "apps/": "front-end",
    "src/capi/": "front-end",
    "include/atrous/atrous.h": "front-end",
    "python/src/": "front-end",
}

# Layer -> the layers it may include besides itself: the arrows of the drawing.
ALLOWED = {
    "core": set(),
    "io": {"core"},
    "render": {"core", "io"},
    "filters": {"core"},
    "sessions": {"core", "io", "render", "filters"},
    "front-end": {"core", "io", "render", "filters", "sessions"},
}

# Includes that break the drawing and are being removed (file, included header): each is reported
# as known while it is there, and as stale once it is gone, so that this list only shrinks.
PENDING = set()  # empty since issue 48 (io/buffer_set.h no longer includes denoise.h)

# Folders an #include "..." is looked up in (besides the including file's own), as the build's
# include paths: include/ and src/ for the library, apps/atrous for the viewer's view/*.h.
SEARCH = ["include", "src", "apps/atrous", "python/src"]
CHECKED = ["src", "include/atrous", "apps", "python/src"]
SOURCE_EXT = (".h", ".hpp", ".cpp", ".cu", ".cuh")
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')


def layer_of(rel):
    best = None
    for path, layer in LAYERS.items():
        hit = rel.startswith(path) if path.endswith("/") else rel == path
        if hit and (best is None or len(path) > len(best[0])):
            best = (path, layer)
    return best[1] if best else None


def resolve(root, rel_dir, name):
    for base in [rel_dir] + SEARCH:
        cand = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(os.path.join(root, cand)):
            return cand
    return None


def check(root):
    problems, pending = [], set()
    for top in CHECKED:
        for d, _, files in os.walk(os.path.join(root, top)):
            for f in sorted(files):
                if not f.endswith(SOURCE_EXT):
                    continue
                rel = os.path.relpath(os.path.join(d, f), root)
                src_layer = layer_of(rel)
                if src_layer is None:
                    problems.append(f"{rel}: in no layer (add it to LAYERS in tests/layer_includes.py)")
                    continue
                with open(os.path.join(root, rel), encoding="utf-8") as fh:
                    for n, line in enumerate(fh, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = resolve(root, os.path.dirname(rel), m.group(1))
                        if target is None:
                            continue  # a system or third-party header
                        dst_layer = layer_of(target)
                        if dst_layer is None:
                            problems.append(f"{rel}:{n}: includes {target}, which is in no layer")
                        elif src_layer == "front-end" and dst_layer != "front-end" and not target.startswith("include/"):
                            problems.append(f"{rel}:{n}: a front-end includes the private header {target}")
                        elif dst_layer != src_layer and dst_layer not in ALLOWED[src_layer]:
                            if (rel, target) in PENDING:
                                pending.add((rel, target))
                                print(f"{rel}:{n}: {src_layer} includes {target} ({dst_layer}): known, PENDING")
                            else:
                                problems.append(f"{rel}:{n}: {src_layer} includes {target} ({dst_layer})")
    for rel, target in sorted(PENDING - pending):
        problems.append(f"{rel} no longer includes {target}: remove it from PENDING")
    return problems


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    problems = check(os.path.abspath(root))
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} include(s) break the layers of docs/architecture.md")
        return 1
    print("every include follows the layers of docs/architecture.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
