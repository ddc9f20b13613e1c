"""A toy still method as a plugin: one registry row (atrous.register_method) plus its policy, a
3x3 box filter weighted by the albedo's likeness (a cross-bilateral stop on the albedo's green
channel, as tests/toy_policy.h in C++). Loaded by tests/python/test_methods.py in-process and by
the farm's workers (--plugin)."""
import numpy as np

import atrous


def toy_cascade(planes, out):
    c = planes["color"]
    a = planes["albedo"]
    g = a[..., 1] if a is not None else np.zeros(c.shape[:2], np.float32)
    h, w = g.shape
    cp = np.pad(c, ((1, 1), (1, 1), (0, 0)), mode="edge")
    gp = np.pad(g, 1, mode="edge")
    acc = np.zeros_like(c)
    ws = np.zeros(g.shape, np.float32)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            wq = np.exp(-100.0 * (gp[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] - g) ** 2).astype(np.float32)
            acc += wq[..., None] * cp[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
            ws += wq
    out[...] = acc / ws[..., None]


# "pytoy": the C++ toy (tests/toy_method.cpp, a plugin) is "toy", and a farm's workers may hold both.
if "pytoy" not in atrous.METHODS:
    atrous.register_method("pytoy", toy_cascade, "a toy: a 3x3 cross-bilateral box on the albedo (tests/python/toy_plugin.py)")
