"""python -m atrous.blender FILE.py: writes the add-on file Blender installs (docs/blender.md)."""
import sys

from . import write_addon_file


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1 or args[0] in ("-h", "--help") or not args[0].endswith(".py"):
        print("usage: python -m atrous.blender ADDON_FILE.py\n"
              "Writes the add-on file for Blender's Preferences > Add-ons > Install from Disk "
              "(the atrous package must be installed into Blender's Python: docs/blender.md).",
              file=sys.stderr if args[:1] not in (["-h"], ["--help"]) else sys.stdout)
        return 0 if args[:1] in (["-h"], ["--help"]) else 2
    print(write_addon_file(args[0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
