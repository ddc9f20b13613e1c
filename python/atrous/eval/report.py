"""Summary, plots (matplotlib, Agg) and the self-contained HTML report of atrous-eval."""
from __future__ import annotations

import base64
import html
import io
import math
from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np

import atrous

COLORS = {"noisy": "#7f7f7f", "oidn": "#d62728", "render 1 spp": "#000000"}
# The still methods' colours, in the registry's order (eaw, sure, learned, blend, auto, then a
# registered method's).
_STILL_COLORS = ("#1f77b4", "#2ca02c", "#ff7f0e", "#17becf", "#8c564b", "#7f7f00", "#aec7e8")
COLORS.update({str(r["name"]): _STILL_COLORS[i % len(_STILL_COLORS)] for i, r in enumerate(atrous.denoise_methods())})
# The sequence methods' colours, in the registry's order (temporal, svgf, then a plugin's).
_SEQUENCE_COLORS = ("#e377c2", "#9467bd", "#bcbd22", "#8c564b", "#aec7e8")
COLORS.update({str(r["name"]): _SEQUENCE_COLORS[i % len(_SEQUENCE_COLORS)]
               for i, r in enumerate(atrous.sequence_methods())})


def _geomean(xs: List[float]) -> Optional[float]:
    xs = [x for x in xs if x is not None and x > 0 and math.isfinite(x)]
    return float(math.exp(sum(math.log(x) for x in xs) / len(xs))) if xs else None


# ------------------------------------------------------------------------------------ summary

def summarise(data: Dict[str, Any]) -> Dict[str, Any]:
    """Per-method aggregates, the OIDN comparison in numbers, and plain-text findings."""
    rows = data["results"]
    by = {(r["scene"], r["spp"], r["method"]): r for r in rows}
    cases = sorted({(r["scene"], r["spp"]) for r in rows}, key=lambda c: (c[0], c[1]))
    per_method = {}
    for m in data["methods"]:
        red, gain, ms, flips = [], [], [], []
        for sc, spp in cases:
            r, n = by.get((sc, spp, m)), by.get((sc, spp, "noisy"))
            if r is None:
                continue
            if n is not None and r["relmse"] > 0:
                red.append(n["relmse"] / r["relmse"])
                gain.append(r["psnr"] - n["psnr"])
            ms.append(r["ms"])
            if r.get("flip") is not None:
                flips.append(r["flip"])
        per_method[m] = {
            "relmse_reduction_geomean": _geomean(red) if m != "noisy" else 1.0,
            "psnr_gain_mean_db": float(np.mean(gain)) if gain else None,
            "median_ms": float(np.median(ms)) if ms else None,
            "mean_flip": float(np.mean(flips)) if flips else None,
        }
        pm = per_method[m]
        if m != "noisy" and pm["psnr_gain_mean_db"] is not None and pm["median_ms"]:
            pm["db_per_10ms"] = pm["psnr_gain_mean_db"] / pm["median_ms"] * 10.0
    findings: List[str] = []
    versus: List[Dict[str, Any]] = []
    present = [m for m in atrous.METHODS if m in data["methods"]]
    if "oidn" in data["methods"] and present:
        for sc, spp in cases:
            o = by.get((sc, spp, "oidn"))
            cand = [by[(sc, spp, m)] for m in present if (sc, spp, m) in by]
            if o is None or not cand:
                continue
            best = min(cand, key=lambda r: r["relmse"])
            fastest = min(cand, key=lambda r: r["ms"])
            versus.append({"scene": sc, "spp": spp, "best_atrous": best["method"],
                           "atrous_relmse": best["relmse"], "oidn_relmse": o["relmse"],
                           "relmse_ratio": best["relmse"] / o["relmse"] if o["relmse"] > 0 else None,
                           "psnr_diff_db": o["psnr"] - best["psnr"],
                           "speedup": o["ms"] / best["ms"] if best["ms"] > 0 else None,
                           "speedup_fastest": o["ms"] / fastest["ms"] if fastest["ms"] > 0 else None})
        wins = [v for v in versus if v["relmse_ratio"] and v["relmse_ratio"] > 1]
        ratios = [v["relmse_ratio"] for v in versus if v["relmse_ratio"]]
        if ratios:
            findings.append(
                f"Quality: OIDN has the lower relMSE in {len(wins)} of {len(versus)} scene x spp cases; the "
                f"best atrous filter's relMSE is {_geomean(ratios):.2f}x OIDN's (geometric mean; range "
                f"{min(ratios):.2f}x to {max(ratios):.2f}x), and OIDN's PSNR is "
                f"{np.mean([v['psnr_diff_db'] for v in versus]):+.2f} dB higher on average.")
            losses = [v for v in versus if v["relmse_ratio"] and v["relmse_ratio"] < 1]
            if losses:
                findings.append(
                    "atrous has the lower relMSE in: " + ", ".join(
                        f"{v['scene']} {v['spp']} spp ({v['best_atrous']} {1 / v['relmse_ratio']:.1f}x lower)"
                        for v in losses) + ".")
            sp = [v["speedup"] for v in versus if v["speedup"]]
            if sp:
                g = _geomean(sp)
                how = f"runs {g:.1f}x faster than" if g >= 1 else f"is {1 / g:.1f}x slower than"
                findings.append(
                    f"Speed: the best atrous filter {how} OIDN (geometric mean of the per-case median "
                    f"times; {per_method['oidn']['median_ms']:.1f} ms median for OIDN on this CPU).")
    for m in present:
        pm = per_method[m]
        if pm["relmse_reduction_geomean"]:
            findings.append(f"{m}: relMSE {pm['relmse_reduction_geomean']:.2f}x lower than the noisy input "
                            f"(geometric mean), {pm['psnr_gain_mean_db']:+.2f} dB PSNR, "
                            f"{pm['median_ms']:.1f} ms median.")
    et = data.get("equal_time") or []
    if et:
        adv = {}
        for r in et:
            if r["advantage"]:
                adv.setdefault(r["method"], []).append(r["advantage"])
        for m, xs in adv.items():
            findings.append(f"Equal time: {m} beats spending its time on more samples in {sum(x > 1 for x in xs)} "
                            f"of {len(xs)} cases (equal-time noisy relMSE / denoised relMSE = {_geomean(xs):.2f}, "
                            "geometric mean; > 1 means denoising wins).")
    return {"per_method": per_method, "versus_oidn": versus, "findings": findings}


# ------------------------------------------------------------------------------------ plots

def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _null_formatter():
    from matplotlib.ticker import NullFormatter

    return NullFormatter()


def _grid(n: int):
    cols = 2 if n in (2, 4) else min(n, 3)
    rows = (n + cols - 1) // cols
    return rows, cols


def _log_axes(ax, title: str, xlabel: str, ylabel: str, xbase: Optional[int] = None) -> None:
    """Log y (and, with xbase, log x to that base), titles and the plots' grid."""
    if xbase:
        ax.set_xscale("log", base=xbase)
    ax.set_yscale("log")
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)


def _end_panels(fig, axes, n: int, legend_size: int, title: str) -> None:
    """A per-scene panel figure: blank the unused panels, the legend on the first, the title."""
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=legend_size)
    fig.suptitle(title)


def _save(plt, fig, out: Path, made: Dict[str, str], name: str) -> None:
    fig.tight_layout()
    fig.savefig(out / f"{name}.png", dpi=100)
    plt.close(fig)
    made[name] = f"{name}.png"


def write_plots(data: Dict[str, Any], out: Path) -> Dict[str, str]:
    """Writes the PNG plots into `out`; returns {name: file name}."""
    plt = _plt()
    made = {}
    rows = data["results"]
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    methods = data["methods"]

    # 1. Quality vs spp (the main plot).
    nr, nc = _grid(len(scenes))
    fig, axes = plt.subplots(nr, nc, figsize=(3.6 * nc, 3.2 * nr), squeeze=False)
    for ax, sc in zip(axes.flat, scenes):
        for m in methods:
            pts = sorted((r["spp"], r["relmse"]) for r in rows if r["scene"] == sc and r["method"] == m)
            if pts:
                ax.plot(*zip(*pts), "o-", color=COLORS.get(m), label=m)
        floor = data["references"].get(sc, {}).get("floor_relmse")
        if floor:
            ax.axhline(floor, color="k", ls=":", lw=1, label="reference noise")
        _log_axes(ax, sc, "input spp", "relMSE", xbase=2)
    _end_panels(fig, axes, len(scenes), 8, f"relMSE vs spp ({data['config']['width']}x{data['config']['height']}, "
                f"reference {data['config']['ref_spp']} spp)")
    _save(plt, fig, out, made, "quality_vs_spp")

    # 2. Equal time: relMSE vs total time (render + denoise) per scene.
    et = data.get("equal_time") or []
    if et:
        fig, axes = plt.subplots(nr, nc, figsize=(3.6 * nc, 3.2 * nr), squeeze=False)
        for ax, sc in zip(axes.flat, scenes):
            ms_spp = data["references"][sc]["ms_per_spp"]
            noisy = {}
            for r in rows:
                if r["scene"] == sc and r["method"] == "noisy":
                    noisy[r["spp"]] = r["relmse"]
            for r in et:
                if r["scene"] == sc:
                    noisy[r["equal_time_spp"]] = r["noisy_equal_time_relmse"]
            pts = sorted((s * ms_spp, v) for s, v in noisy.items())
            ax.plot(*zip(*pts), "o-", color=COLORS["noisy"], label="rendering only")
            for m in methods:
                p = sorted((r["total_ms"], r["denoised_relmse"]) for r in et if r["scene"] == sc and r["method"] == m)
                if p:
                    ax.plot(*zip(*p), "s-", color=COLORS.get(m), label=f"{m} (render + denoise)")
            _log_axes(ax, sc, "render + denoise time (ms)", "relMSE", xbase=10)
            ax.xaxis.set_minor_formatter(_null_formatter())  # after the scale, which resets it
        _end_panels(fig, axes, len(scenes), 7, "Equal time: relMSE vs time spent")
        _save(plt, fig, out, made, "equal_time")

    # 3. Runtime vs resolution.
    rt = data.get("runtime_vs_resolution") or []
    if rt:
        fig, ax = plt.subplots(figsize=(5.5, 4))
        for m in list(dict.fromkeys(r["method"] for r in rt)):
            p = sorted((r["megapixels"], r["ms"]) for r in rt if r["method"] == m)
            ax.plot(*zip(*p), "o--" if m.startswith("render") else "o-", color=COLORS.get(m), label=m)
        _log_axes(ax, f"Denoise time vs resolution ({data['environment'].get('cpu_count')} CPU threads)",
                  "megapixels", "ms (median)", xbase=10)
        ax.legend(fontsize=8)
        _save(plt, fig, out, made, "runtime_vs_resolution")

    # 4. Quality per millisecond: relMSE reduction vs denoise time, one point per scene x spp.
    by = {(r["scene"], r["spp"], r["method"]): r for r in rows}
    fig, ax = plt.subplots(figsize=(5.5, 4))
    any_pt = False
    for m in methods:
        if m == "noisy":
            continue
        p = [(r["ms"], by[(r["scene"], r["spp"], "noisy")]["relmse"] / r["relmse"]) for r in rows
             if r["method"] == m and (r["scene"], r["spp"], "noisy") in by and r["relmse"] > 0]
        if p:
            any_pt = True
            ax.scatter(*zip(*p), color=COLORS.get(m), label=m, alpha=0.8)
    if any_pt:
        ax.axhline(1.0, color="k", lw=0.8)
        _log_axes(ax, "Quality per millisecond (one point per scene x spp)", "denoise time (ms, median)",
                  "relMSE reduction over noisy (x)", xbase=10)
        ax.legend(fontsize=8)
        _save(plt, fig, out, made, "quality_per_ms")
    else:
        plt.close(fig)

    # 5. Sequence: per-frame relMSE.
    seq = data.get("sequence")
    if seq and seq.get("frames"):
        fig, ax = plt.subplots(figsize=(5.5, 4))
        for m in seq["methods"]:
            ys = [f["relmse"].get(m) for f in seq["frames"]]
            if any(y is not None for y in ys):
                ax.plot(range(len(ys)), ys, "o-", ms=3, color=COLORS.get(m), label=m)
        _log_axes(ax, "Sequence: relMSE per frame", "frame", "relMSE")
        ax.legend(fontsize=8)
        _save(plt, fig, out, made, "sequence")
    return made


# ------------------------------------------------------------------------------------ images

def tonemap(img: np.ndarray) -> np.ndarray:
    """Linear HDR -> 8-bit display: the library's one preview (atrous.tonemap as uint8: the metrics'
    x / (1 + x), gamma 1/2.2, rounded to 8 bits; non-finite values 0)."""
    return atrous.tonemap(img, np.uint8)


def png_bytes(rgb8: np.ndarray, palette: int = 0) -> bytes:
    """PNG of an 8-bit RGB array; palette > 0 quantises to that many colours (for the smooth
    colour-mapped error maps, about a third of the size)."""
    buf = io.BytesIO()
    try:
        from PIL import Image

        im = Image.fromarray(rgb8)
        if palette:
            im = im.quantize(palette)
        im.save(buf, format="PNG", optimize=True)
    except ImportError:  # matplotlib always has a PNG writer
        import matplotlib.image as mpimg

        mpimg.imsave(buf, rgb8, format="png")
    return buf.getvalue()


def data_uri(rgb8: np.ndarray, palette: int = 0) -> str:
    return "data:image/png;base64," + base64.b64encode(png_bytes(rgb8, palette)).decode("ascii")


def _half(rgb8: np.ndarray) -> np.ndarray:
    """2x2 box downsampling (the full-frame thumbnails are only there to locate the crop)."""
    h, w = (rgb8.shape[0] // 2) * 2, (rgb8.shape[1] // 2) * 2
    x = rgb8[:h, :w].astype(np.float32)
    return ((x[0::2, 0::2] + x[1::2, 0::2] + x[0::2, 1::2] + x[1::2, 1::2]) / 4 + 0.5).astype(np.uint8)


def choose_crop(ref: np.ndarray, size: int) -> tuple:
    """The size x size window with the most detail (summed tonemapped gradient) of the reference:
    where denoisers blur or keep noise, visibly. Returns (y, x)."""
    h, w = ref.shape[:2]
    size = min(size, h, w)
    lum = tonemap(ref).astype(np.float32).mean(axis=2)
    g = np.zeros_like(lum)
    g[:, 1:] += np.abs(np.diff(lum, axis=1))
    g[1:, :] += np.abs(np.diff(lum, axis=0))
    integ = np.pad(g.cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    step = max(1, size // 4)
    best, where = -1.0, (0, 0)
    for y in list(range(0, h - size + 1, step)) + [h - size]:
        for x in list(range(0, w - size + 1, step)) + [w - size]:
            s = integ[y + size, x + size] - integ[y, x + size] - integ[y + size, x] + integ[y, x]
            if s > best:
                best, where = s, (y, x)
    return where


def _boxed(rgb8: np.ndarray, y: int, x: int, size: int) -> np.ndarray:
    out = rgb8.copy()
    col = np.array([255, 220, 0], np.uint8)
    t = max(1, min(out.shape[:2]) // 128)
    out[y:y + t, x:x + size] = col
    out[y + size - t:y + size, x:x + size] = col
    out[y:y + size, x:x + t] = col
    out[y:y + size, x + size - t:x + size] = col
    return out


# ------------------------------------------------------------------------------------ tables

def _fmt(v: Any, nd: int = 4) -> str:
    if v is None:
        return "n/a"
    if isinstance(v, float):
        if not math.isfinite(v):
            return "n/a"
        if v != 0 and abs(v) < 1e-3:
            return f"{v:.2e}"
        return f"{v:.{nd}f}"
    return str(v)


def markdown_table(data: Dict[str, Any]) -> str:
    """The main results as a markdown table (scene, spp, method, relMSE, PSNR, SSIM, FLIP, ms)."""
    lines = ["| scene | spp | method | relMSE | PSNR (dB) | SSIM | FLIP | ms |",
             "|---|---:|---|---:|---:|---:|---:|---:|"]
    for r in data["results"]:
        lines.append(f"| {r['scene']} | {r['spp']} | {r['method']} | {_fmt(r['relmse'], 5)} | "
                     f"{_fmt(r['psnr'], 2)} | {_fmt(r['ssim'], 4)} | {_fmt(r.get('flip'), 4)} | "
                     f"{'-' if r['method'] == 'noisy' else _fmt(r['ms'], 1)} |")
    return "\n".join(lines) + "\n"


def _table(headers: List[str], rows: List[List[str]], cls: str = "") -> str:
    h = "".join(f"<th>{html.escape(x)}</th>" for x in headers)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in rows)
    return f'<table class="{cls}"><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table>'


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:24px;max-width:1400px;color:#222}
h1{margin-bottom:4px} h2{margin-top:32px;border-bottom:1px solid #ddd}
table{border-collapse:collapse;margin:8px 0;font-size:13px}
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right} th{background:#f3f3f3}
td:first-child,th:first-child{text-align:left}
td.best{font-weight:bold;background:#e8f5e9}
.note{background:#fff8e1;border-left:4px solid #f9a825;padding:6px 10px;margin:6px 0}
.finding{margin:4px 0}
.strip{display:flex;gap:6px;flex-wrap:wrap;align-items:flex-start;margin:4px 0 10px}
.strip figure{margin:0;text-align:center;font-size:12px}
.strip img{width:200px;image-rendering:pixelated;border:1px solid #999}
img.plot{max-width:100%;border:1px solid #ddd;margin:6px 0}
code{background:#f3f3f3;padding:1px 4px}
"""


def write_html(data: Dict[str, Any], images: Dict[str, Dict[str, Any]], path: Path) -> None:
    cfg, env = data["config"], data["environment"]
    methods = data["methods"]
    out_dir = Path(path).parent
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>atrous evaluation</title>"
             f"<style>{_CSS}</style></head><body>",
             "<h1>atrous denoisers vs Intel Open Image Denoise</h1>",
             f"<p>{html.escape(env.get('date_utc', ''))} &middot; {cfg['width']}x{cfg['height']} &middot; "
             f"input spp {', '.join(map(str, cfg['spp']))} &middot; references at <b>{cfg['ref_spp']} spp</b> "
             f"(seed {cfg['ref_seed']}; inputs seed {cfg['seed']}) &middot; timings: median of {cfg['runs']} runs "
             f"after a warm-up, {env.get('cpu_count')} CPU threads, load average at the end "
             f"{env.get('load_average')} (a shared machine: timings are noisy)</p>",
             "<p>Methods: <b>noisy</b> = the path-traced input; <b>eaw</b> and <b>sure</b> = atrous's "
             "edge-avoiding and SURE-based à-trous filters (default parameters, every feature buffer); "
             "<b>learned</b> = atrous's learned à-trous filter (a per-pixel network steering an à-trous "
             "cascade, docs/learned.md), <b>blend</b> = the mean of learned and sure, and <b>auto</b> = blend "
             "with an albedo and a normal, else sure "
             "(when run); "
             "<b>oidn</b> = Intel Open Image Denoise (RT filter, HDR, colour + albedo + normal, quality high) "
             f"via pyoidn {html.escape(str(env.get('pyoidn')))}. Metrics: relMSE = mean((x-r)²/(r²+0.01)); PSNR and "
             "SSIM on tonemapped images (x/(1+x), gamma 1/2.2); FLIP = mean HDR-FLIP "
             f"(flip-evaluator {html.escape(str(env.get('flip_evaluator')))}); lower is better for relMSE "
             "and FLIP.</p>"]
    for n in data["notes"]:
        parts.append(f"<div class='note'>Note: {html.escape(n)}</div>")

    summ = data.get("summary") or {}
    if summ.get("findings"):
        parts.append("<h2>Findings</h2>")
        parts += [f"<p class='finding'>{html.escape(f)}</p>" for f in summ["findings"]]
    if summ.get("per_method"):
        rows = []
        for m, pm in summ["per_method"].items():
            rows.append([m, _fmt(pm.get("relmse_reduction_geomean"), 2) + "x",
                         _fmt(pm.get("psnr_gain_mean_db"), 2), _fmt(pm.get("mean_flip"), 4),
                         "-" if m == "noisy" else _fmt(pm.get("median_ms"), 1),
                         _fmt(pm.get("db_per_10ms"), 2) if m != "noisy" else "-"])
        parts.append("<h3>Quality per millisecond</h3>")
        parts.append(_table(["method", "relMSE reduction (geo-mean)", "PSNR gain (dB, mean)", "mean FLIP",
                             "median ms", "dB gained per 10 ms"], rows))
    if summ.get("versus_oidn"):
        rows = [[v["scene"], str(v["spp"]), v["best_atrous"], _fmt(v["atrous_relmse"], 5),
                 _fmt(v["oidn_relmse"], 5), _fmt(v["relmse_ratio"], 2) + "x", _fmt(v["psnr_diff_db"], 2),
                 _fmt(v["speedup"], 1) + "x"] for v in summ["versus_oidn"]]
        parts.append("<h3>Best atrous filter vs OIDN</h3>")
        parts.append("<p>relMSE ratio &gt; 1: OIDN is better by that factor. Speed-up: OIDN's time / the "
                     "atrous filter's time.</p>")
        parts.append(_table(["scene", "spp", "best atrous", "atrous relMSE", "OIDN relMSE",
                             "atrous / OIDN relMSE", "OIDN PSNR advantage (dB)", "atrous speed-up"], rows))

    # Main table, best value per (scene, spp) in bold.
    parts.append("<h2>Results</h2>")
    rows = []
    by_case: Dict[tuple, List[Dict[str, Any]]] = {}
    for r in data["results"]:
        by_case.setdefault((r["scene"], r["spp"]), []).append(r)
    for case, rs in by_case.items():
        best = {k: (min if k in ("relmse", "flip") else max)(
            (x[k] for x in rs if x.get(k) is not None), default=None) for k in ("relmse", "psnr", "ssim", "flip")}
        for r in rs:
            def cell(k, nd):
                s = _fmt(r.get(k), nd)
                return f"<span class='b'>{s}</span>" if r.get(k) is not None and r.get(k) == best[k] else s
            rows.append([r["scene"], str(r["spp"]), r["method"], cell("relmse", 5), cell("psnr", 2),
                         cell("ssim", 4), cell("flip", 4), "-" if r["method"] == "noisy" else _fmt(r["ms"], 1)])
    tbl = _table(["scene", "spp", "method", "relMSE", "PSNR (dB)", "SSIM", "FLIP", "denoise ms"], rows)
    parts.append(tbl.replace("<td><span class='b'>", "<td class='best'><span>"))
    rows = [[sc, str(r["spp"]), _fmt(r["render_ms"], 0), _fmt(r["ms_per_spp"], 2), _fmt(r["floor_relmse"], 5)]
            for sc, r in data["references"].items()]
    parts.append("<h3>References</h3><p>Reference noise floor: mean(var/(r²+0.01)) from the renderer's "
                 "variance of the reference mean; it is included in every relMSE above.</p>")
    parts.append(_table(["scene", "reference spp", "render ms", "ms per spp", "reference noise floor (relMSE)"],
                        rows))

    plots = data.get("plots") or {}
    titles = {"quality_vs_spp": "Quality vs spp", "quality_per_ms": "Quality per millisecond",
              "equal_time": "Equal-time comparison", "runtime_vs_resolution": "Runtime vs resolution",
              "sequence": "Sequence"}
    for key in ("quality_vs_spp", "quality_per_ms"):
        if key in plots:
            parts.append(f"<h2>{titles[key]}</h2>{_plot_img(out_dir / plots[key])}")

    # Images.
    parts.append("<h2>Images</h2><p>Per scene: the reference with the crop shown (the window with the most "
                 "detail), then per input spp the crops (tonemapped) and, below, HDR-FLIP error maps "
                 "(magma: dark = no visible error, bright = large error) with mean FLIP.</p>")
    for sc, im in images.items():
        ref = im["reference"]
        h, w = ref.shape[:2]
        cs = max(16, min(h, w) // 2)
        y, x = choose_crop(ref, cs)
        thumb = _boxed(tonemap(ref), y, x, cs)
        if min(h, w) > 192:
            thumb = _half(thumb)
        ref_id = f"ref-{len(parts)}"
        parts.append(f"<h3>{html.escape(sc)}</h3><div class='strip'><figure>"
                     f"<img src='{data_uri(thumb)}'><figcaption>reference "
                     f"{cfg['ref_spp']} spp (full frame)</figcaption></figure><figure>"
                     f"<img id='{ref_id}' src='{data_uri(tonemap(ref[y:y + cs, x:x + cs]))}'>"
                     f"<figcaption>reference crop</figcaption></figure></div>")
        for spp, per in im["spp"].items():
            res = {r["method"]: r for r in data["results"] if r["scene"] == sc and r["spp"] == spp}
            crops = [("reference", None, ref_id)]
            maps = []
            for m in methods:
                if m not in per:
                    continue
                crops.append((m, tonemap(per[m]["image"][y:y + cs, x:x + cs]),
                              f"relMSE {_fmt(res[m]['relmse'], 4)}"))
                fm = per[m].get("flip_map")
                if fm is not None:
                    maps.append((m, (np.clip(fm[y:y + cs, x:x + cs], 0, 1) * 255 + 0.5).astype(np.uint8),
                                 f"FLIP {_fmt(res[m].get('flip'), 4)}"))

            def fig(n, a, c, palette=0):
                if a is None:  # the scene's reference crop, copied in by the script at the end
                    return f"<figure><img data-ref='{c}'><figcaption>{html.escape(n)}</figcaption></figure>"
                return (f"<figure><img src='{data_uri(a, palette)}'><figcaption>{html.escape(n)} {c}"
                        "</figcaption></figure>")
            parts.append(f"<p><b>{spp} spp</b></p><div class='strip'>" + "".join(fig(*t) for t in crops) + "</div>")
            if maps:
                parts.append("<div class='strip'><figure style='width:202px'></figure>" + "".join(
                    fig(n, a, c, palette=64) for n, a, c in maps) + "</div>")

    et = data.get("equal_time") or []
    if et:
        parts.append("<h2>Equal-time comparison</h2><p>Each denoised N-spp image against the noisy image "
                     "rendered with the same total time: the render time of N spp is modelled as N x the "
                     "reference's measured ms per spp, and the denoiser's median time buys "
                     "round(ms / ms-per-spp) more samples, which were rendered (same seed) and measured. "
                     "Advantage = noisy equal-time relMSE / denoised relMSE (&gt; 1: denoising wins). "
                     "The last column extrapolates (relMSE of pure rendering ~ 1/spp) how many samples "
                     "rendering alone would need to match the denoised relMSE.</p>")
        if "equal_time" in plots:
            parts.append(_plot_img(out_dir / plots["equal_time"]))
        rows = [[r["scene"], str(r["spp"]), r["method"], _fmt(r["denoise_ms"], 1), _fmt(r["extra_spp"], 2),
                 str(r["equal_time_spp"]), _fmt(r["denoised_relmse"], 5), _fmt(r["noisy_equal_time_relmse"], 5),
                 _fmt(r["advantage"], 2) + "x", _fmt(r["noisy_spp_to_match_est"], 0)] for r in et]
        parts.append(_table(["scene", "spp", "method", "denoise ms", "spp that time buys", "equal-time spp",
                             "denoised relMSE", "noisy relMSE at equal time", "advantage",
                             "spp to match (est.)"], rows))

    rt = data.get("runtime_vs_resolution") or []
    if rt:
        parts.append("<h2>Runtime vs resolution</h2>")
        if "runtime_vs_resolution" in plots:
            parts.append(_plot_img(out_dir / plots["runtime_vs_resolution"]))
        rows = [[r["method"], f"{r['width']}x{r['height']}", _fmt(r["ms"], 2)] for r in rt]
        parts.append(_table(["method", "size", "ms (median)"], rows))

    seq = data.get("sequence")
    parts.append("<h2>Sequence (SVGF)</h2>")
    if seq:
        if seq.get("note"):
            parts.append(f"<div class='note'>{html.escape(seq['note'])}</div>")
        parts.append(f"<p>{html.escape(seq['dir'])}: {seq['num_frames']} frames, {seq['width']}x{seq['height']}. "
                     "relMSE: mean over the frames (with a reference); PSNR, SSIM, FLIP: last frame; temporal relMSE: relMSE of "
                     "frame-to-frame differences against the references' differences (flicker).</p>")
        rows = [[m, _fmt(s.get("relmse"), 5), _fmt(s.get("psnr"), 2), _fmt(s.get("ssim"), 4),
                 _fmt(s.get("flip"), 4), _fmt(s.get("temporal_relmse"), 5), _fmt(s.get("ms"), 1)]
                for m, s in seq["summary"].items()]
        parts.append(_table(["method", "relMSE", "PSNR", "SSIM", "FLIP", "temporal relMSE", "ms / frame"], rows))
        if "sequence" in plots:
            parts.append(_plot_img(out_dir / plots["sequence"]))
    else:
        parts.append("<p>No sequence was evaluated (see the notes above).</p>")
    # Each reference crop is embedded once; this copies it into every row that shows it.
    parts.append("<script>document.querySelectorAll('img[data-ref]').forEach(function(i){"
                 "i.src=document.getElementById(i.dataset.ref).src;});</script>")
    parts.append(f"<p style='color:#888'>elapsed {data.get('elapsed_s', 0):.1f} s; raw numbers in "
                 "results.json.</p></body></html>")
    tmp = Path(str(path) + ".tmp")
    tmp.write_text("\n".join(parts), encoding="utf-8")
    tmp.replace(path)


def _plot_img(p: Path) -> str:
    b = Path(p).read_bytes()
    return f"<img class='plot' src='data:image/png;base64,{base64.b64encode(b).decode('ascii')}'>"
