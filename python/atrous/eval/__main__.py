"""python -m atrous.eval [SUBCOMMAND] ... (also the `atrous-eval` command): the one entry point of the evaluations (docs/eval.md).

    scenes      the built-in scenes against OIDN: quality, equal time, runtime, report.html
                (the default: `python -m atrous.eval --quick` is `... scenes --quick`)
    corpus      other renderers' stills (the third-party corpus of scripts/corpus): noisy, OIDN, atrous
    held-out    the learned filter on the training set's held-out scenes against EAW, SURE and OIDN
    sequences   SVGF against the per-frame filters on rendered animations, with temporal error
    cli-scenes  the built-in scenes through the CLI (atrous render / denoise / compare)
    speed       EAW, SURE and learned (atrous bench --json) against OIDN in one process: JSON

Each subcommand's --help has its flags; run them from the repository root (their defaults are its
out/ and build/). The C++ benchmark programs (atrous bench, build/bench/*) time the kernels; speed
runs atrous bench beside OIDN.
"""
import sys

SUBCOMMANDS = {
    "scenes": "atrous.eval",
    "corpus": "atrous.eval.corpus",
    "held-out": "atrous.eval.heldout",
    "sequences": "atrous.eval.sequences",
    "cli-scenes": "atrous.eval.cli_scenes",
    "speed": "atrous.eval.speed",
}


def run(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in ("-h", "--help") and len(argv) == 1:
        print(__doc__.strip())
        return 0
    name = argv[0] if argv and argv[0] in SUBCOMMANDS else "scenes"
    rest = argv[1:] if argv and argv[0] in SUBCOMMANDS else argv
    import importlib

    rc = importlib.import_module(SUBCOMMANDS[name]).main(rest)
    return 0 if rc is None else rc


if __name__ == "__main__":
    sys.exit(run())
