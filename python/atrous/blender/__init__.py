"""Blender add-on: denoise a rendered Cycles animation with atrous's sequence denoiser
(docs/blender.md).

Blender writes an animation as numbered Multi-Layer EXR files (render0001.exr, ...) with the
passes a denoiser needs (Denoising Data: albedo and normal; Vector: motion). The add-on's operator
(Properties > Output > "Denoise Animation (atrous)", or Render > "Denoise Animation (atrous)")
hands those files, as Blender wrote them, to :func:`atrous.denoise_sequence` and writes
the denoised frames under the rendered frames' names (render0001.exr ..., + .png and preview.mp4)
into a folder beside them.

This module does not import bpy: :func:`register` and :func:`unregister` load the Blender classes
(atrous.blender.addon) when Blender calls them. ``python -m atrous.blender FILE.py`` writes the small
add-on file that Blender's "Install from Disk" takes; it imports this package, which must be
installed into Blender's own Python (docs/blender.md).
"""
from __future__ import annotations

import os
from typing import Union

bl_info = {
    "name": "atrous denoiser",
    "author": "atrous",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "Properties > Output > Denoise Animation (atrous); Render menu",
    "description": "Denoises a rendered Cycles animation (Multi-Layer EXR frames) with atrous's sequence denoiser",
    "category": "Render",
}

ADDON_FILE = '''"""atrous denoiser for Blender: the add-on file Blender installs (docs/blender.md).
The add-on itself is the atrous package's atrous.blender, which must be installed into Blender's Python."""
bl_info = {bl_info!r}


def register():
    from atrous.blender import register as _register
    _register()


def unregister():
    from atrous.blender import unregister as _unregister
    _unregister()
'''


def register() -> None:
    """Registers the operator, its settings (scene.atrous), the Output panel and the Render menu entry."""
    from . import addon

    addon.register()


def unregister() -> None:
    from . import addon

    addon.unregister()


def write_addon_file(path: Union[str, "os.PathLike[str]"]) -> str:
    """Writes the add-on file for Blender's Preferences > Add-ons > Install from Disk; returns its path."""
    path = os.fspath(path)
    with open(path, "w", encoding="utf-8") as f:
        f.write(ADDON_FILE.format(bl_info=bl_info))
    return path
