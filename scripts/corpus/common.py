"""Shared helpers of the third-party corpus scripts (render side, run in .venv-corpus).

Modes (sizes, sample counts, seeds) live here so both renderers use the same ones.
"""
import argparse
import json
import os
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# Seeds: noisy renders use one seed per spp, the references an independent one.
SEED_NOISY = {1: 5, 4: 1, 16: 2}
SEED_REF = 1000003
SEED_SEQ = 1          # frame f of a 1-spp sequence uses SEED_SEQ + f
SEED_SEQ_REF = 2000003  # its reference uses SEED_SEQ_REF + f
SEED_SEQ_SPP = 3000001  # frame f at s spp (s > 1: frames_sNNNN/) uses SEED_SEQ_SPP + 1000 s + f


def seq_spp_folder(spp):
    """The folder of a sequence's frames at `spp` (1: frames/, the original layout)."""
    return "frames" if spp == 1 else f"frames_s{spp:04d}"

MODES = {
    # CI-sized: 2 stills per renderer plus a 4-frame sequence, small images, 256-spp references.
    "quick": dict(res=64, spp=[4, 16], ref_spp=256, seq_res=48, seq_frames=4, seq_ref_spp=64, seq_spp=[1]),
    # The corpus proper.
    "full": dict(res=256, spp=[4, 16], ref_spp=2048, seq_res=128, seq_frames=20, seq_ref_spp=2048, seq_spp=[1, 4, 16]),
    # Stills at 1, 4 and 16 spp (issue 47's window-lit rooms): 128x128, 2048-spp references, no sequences.
    "lowspp": dict(res=128, spp=[1, 4, 16], ref_spp=2048, seq_res=0, seq_frames=0, seq_ref_spp=0, seq_spp=[]),
}


# The training split (docs/corpus.md, "Training split"): scenes tr_mi_NN / tr_cy_NN, never the test
# scenes above. Scene k's noisy renders use seed seed_base + 1000 k + spp, its reference
# ref_seed + k (independent of every noisy seed and of the test corpus's seeds).
TRAIN = dict(res=128, spp=[1, 4, 16], ref_spp=1024, seed_base=3000000, ref_seed=4000003)


def parse_train_args(renderer, prefix, count):
    """The training split's command line (--out, --scenes): (output root, names prefix_00.. to render)."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--scenes", default="")
    a = ap.parse_args()
    names = [f"{prefix}_{k:02d}" for k in range(count)]
    if a.scenes:
        names = [n for n in a.scenes.split(",") if n in names]
    return Path(a.out) / renderer, names


def train_jobs(k):
    """(spp, seed, file stem) of training scene k's renders: the noisy ones, then the reference."""
    jobs = [(spp, TRAIN["seed_base"] + 1000 * k + spp, f"spp{spp:04d}") for spp in TRAIN["spp"]]
    jobs.append((TRAIN["ref_spp"], TRAIN["ref_seed"] + k, f"ref{TRAIN['ref_spp']:04d}"))
    return jobs


def exr_channels(path):
    """{part name: [channel names]} of an EXR file, via the OpenEXR Python bindings."""
    import OpenEXR

    out = {}
    with OpenEXR.File(str(path), separate_channels=True) as f:
        for i, p in enumerate(f.parts):
            name = p.name() if p.name() else f"part{i}"
            out[name] = sorted(p.channels.keys())
    return out


def exr_read_all(path):
    """{channel name: 2-D float array} over every part of an EXR (Blender 5 writes one part per pass)."""
    import OpenEXR

    out = {}
    with OpenEXR.File(str(path), separate_channels=True) as f:
        for p in f.parts:
            for k, c in p.channels.items():
                out[k] = c.pixels
    return out


def write_manifest(path, data):
    data = dict(data)
    data["written"] = time.strftime("%Y-%m-%dT%H:%M:%S")
    tmp = Path(str(path) + ".tmp")
    tmp.write_text(json.dumps(data, indent=2) + "\n")
    os.replace(tmp, path)


def done(path):
    return Path(path).exists() and Path(path).stat().st_size > 0


def log(*a):
    print(time.strftime("%H:%M:%S"), *a, flush=True)


def parse_render_args(renderer, quick, stills, named_only=()):
    """The command line both renderers take: (args, mode dict, output root, still names to render).

    --scenes keeps only names of `stills` or `named_only` (stills rendered only when named, kept out
    of --full; the sequence's name is checked by the caller)."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--mode", choices=list(MODES), default="quick")
    ap.add_argument("--out", required=True)
    ap.add_argument("--scenes", default="")
    a = ap.parse_args()
    names = quick if a.mode == "quick" else list(stills)
    if a.scenes:
        names = [n for n in a.scenes.split(",") if n in stills or n in named_only]
    return a, MODES[a.mode], Path(a.out) / renderer, names


def still_jobs(mode):
    """(spp, seed, file stem) of a still's renders: the noisy ones, then the reference."""
    jobs = [(spp, SEED_NOISY[spp], f"spp{spp:04d}") for spp in mode["spp"]]
    jobs.append((mode["ref_spp"], SEED_REF, f"ref{mode['ref_spp']:04d}"))
    return jobs


def merged_render_seconds(man_path, times):
    """The manifest's render_seconds: what an earlier run recorded, updated with this run's `times`."""
    old = {}
    if Path(man_path).exists():
        old = json.loads(Path(man_path).read_text()).get("render_seconds", {})
    old.update({k: round(v, 2) for k, v in times.items()})
    return old
