"""The Blender classes of the atrous add-on (atrous.blender registers them): the settings
(scene.atrous), the operators atrous.denoise_animation and atrous.denoise_still, the Output
properties panel and the Render menu entries. Imported only inside Blender (or with the bpy module). No `from __future__ import
annotations` here: Blender reads the property annotations as objects."""

import os
import re
from typing import List, Optional, Tuple

import bpy

import atrous


def _method_items() -> List[Tuple[str, str, str]]:
    seq = [(r["name"], r["name"], r["summary"]) for r in atrous.sequence_methods()]
    still = [(r["name"], f"{r['name']} (each frame alone)", r["summary"]) for r in atrous.denoise_methods()]
    return seq + still


def _still_items() -> List[Tuple[str, str, str]]:
    return [(r["name"], r["name"], r["summary"]) for r in atrous.denoise_methods()]


# Blender keeps the strings of an EnumProperty's items: made once, at import.
_METHODS = _method_items()
_STILL = _still_items()


class AtrousSettings(bpy.types.PropertyGroup):
    method: bpy.props.EnumProperty(
        name="Method", items=_METHODS, default=atrous.SEQUENCE_METHODS[0],
        description="A sequence method: each frame with the frames around it or before it (the first, "
                    "the default); a still method: each frame alone")
    spatial: bpy.props.EnumProperty(
        name="Spatial", items=_STILL, default=atrous.names.DEFAULT,
        description="The still method: what a sequence method that ends with one runs (on "
                    "its average), and what denoises the Render Result (the default, auto: by the passes given)")
    output: bpy.props.StringProperty(
        name="Output", subtype="DIR_PATH", default="",
        description="Folder for the denoised frames, named as the rendered ones (render0001.exr ...; empty: FRAMES_denoised beside the rendered frames' folder)")
    preview: bpy.props.BoolProperty(
        name="Preview video", default=True,
        description="Also write PNG previews and preview.mp4 (when ffmpeg is on PATH)")
    last_result: bpy.props.StringProperty(name="Last result", default="")


def is_multilayer(scene) -> bool:
    im = scene.render.image_settings
    return getattr(im, "media_type", None) == "MULTI_LAYER_IMAGE" or im.file_format == "OPEN_EXR_MULTILAYER"


def frame_pattern(scene) -> str:
    """The rendered frames as a pattern the atrous reader takes (DIR/render####.exr), from the path
    Blender writes frame_start to (render.frame_path: the output path with its '#' run or four
    appended digits)."""
    start = scene.frame_start
    path = bpy.path.abspath(scene.render.frame_path(frame=start))
    folder, name = os.path.split(path)
    runs = [m for m in re.finditer(r"\d+", name) if int(m.group()) == start]
    if not runs:
        raise ValueError(f"cannot find the frame number {start} in the output file name {path}")
    m = runs[-1]
    return os.path.join(folder, name[:m.start()] + "#" * len(m.group()) + name[m.end():])


def view_layer_of(context) -> str:
    """The view layer to read when the frames hold several (the active one), else "" (the only one)."""
    used = [v for v in context.scene.view_layers if v.use]
    return context.view_layer.name if len(used) > 1 else ""


def output_folder(scene, pattern: str) -> str:
    """The Output folder, or beside the frames' folder: FRAMES_denoised (a folder inside the
    frames' own is refused: its frame files would read as frames of the input next time)."""
    s = scene.atrous
    if s.output:
        return bpy.path.abspath(s.output)
    frames = os.path.normpath(os.path.dirname(pattern))
    return frames + "_denoised"


def denoise_animation(context, on_frame=None) -> dict:
    """Denoises the scene's rendered animation (frame_start .. frame_end) as the operator does;
    returns atrous.denoise_sequence's report. Raises ValueError for what the user must change."""
    scene = context.scene
    if not is_multilayer(scene):
        raise ValueError("set Output > Media Type to Multi-Layer EXR (Blender 5; File Format OpenEXR MultiLayer "
                         "before 5) with the Denoising Data and Vector passes of the view layer on, render the "
                         "animation, then denoise it")
    s = scene.atrous
    if scene.frame_step > 1 and s.method in atrous.SEQUENCE_METHODS:
        raise ValueError(f"Frame Step is {scene.frame_step}: the {s.method} method joins neighbouring frames, "
                         "which needs every frame (set Frame Step to 1, or pick a still method)")
    pattern = frame_pattern(scene)
    out = output_folder(scene, pattern)
    return atrous.denoise_sequence(pattern, out, method=s.method, spatial=s.spatial, layer=view_layer_of(context),
                                   start=scene.frame_start, end=scene.frame_end, step=scene.frame_step,
                                   pngs=s.preview, preview=s.preview, device="auto", on_frame=on_frame)


class ATROUS_OT_denoise_animation(bpy.types.Operator):
    """Denoise the rendered animation (Multi-Layer EXR frames) with atrous"""

    bl_idname = "atrous.denoise_animation"
    bl_label = "Denoise Animation (atrous)"
    bl_options = {"REGISTER"}

    def execute(self, context):
        wm = context.window_manager
        scene = context.scene
        total = max(1, (scene.frame_end - scene.frame_start) // max(1, scene.frame_step) + 1)
        done = [0]

        def progress(frame: dict) -> None:
            done[0] += 1
            wm.progress_update(done[0])
            print(f"atrous: {frame['position']}/{frame['count']} {frame['line']}")

        wm.progress_begin(0, total)
        try:
            report = denoise_animation(context, on_frame=progress)
        except (ValueError, RuntimeError) as e:
            scene.atrous.last_result = f"failed: {e}"
            self.report({"ERROR"}, f"atrous: {e}")
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        frames = report["frames"]
        out = os.path.dirname(frames[0]["output"]) if frames else ""
        used = scene.atrous.method
        if frames and frames[0]["method_used"] != used:
            used += f", then {frames[0]['method_used']}"
        msg = f"{len(frames)} frames denoised ({used}) into {out}"
        for note in report["notes"]:
            print("atrous:", note)
        scene.atrous.last_result = msg
        self.report({"INFO"}, f"atrous: {msg}")
        return {"FINISHED"}


RESULT_IMAGE = "atrous denoised"


def _set_multilayer(im) -> dict:
    """Switches image settings to float OpenEXR MultiLayer; returns what to restore."""
    old = {"file_format": im.file_format, "color_depth": im.color_depth, "exr_codec": im.exr_codec}
    if hasattr(im, "media_type"):  # Blender 5: MultiLayer is a media type
        old["media_type"] = im.media_type
        im.media_type = "MULTI_LAYER_IMAGE"
    try:
        im.file_format = "OPEN_EXR_MULTILAYER"
    except TypeError:  # a Blender whose multilayer format is OPEN_EXR under the media type
        im.file_format = "OPEN_EXR"
    im.color_depth = "32"
    return old


def _restore(im, old: dict) -> None:
    if "media_type" in old:
        im.media_type = old["media_type"]
    im.file_format = old["file_format"]
    im.color_depth = old["color_depth"]
    if old["file_format"].startswith("OPEN_EXR"):
        im.exr_codec = old["exr_codec"]


def denoise_still(context) -> "bpy.types.Image":
    """Denoises the Render Result (with its passes: Denoising Data for the albedo and normal) into
    the image "atrous denoised" (and OUTPUT/still.exr when the Output folder is set); returns it.
    Raises ValueError for what the user must change."""
    import tempfile

    import numpy as np

    scene = context.scene
    result = bpy.data.images.get("Render Result")
    if result is None:
        raise ValueError("render an image first (F12): there is no Render Result")
    with tempfile.TemporaryDirectory(prefix="atrous_") as tmp:
        path = os.path.join(tmp, "render.exr")
        im = scene.render.image_settings
        old = _set_multilayer(im)
        try:
            result.save_render(filepath=path, scene=scene)
        except RuntimeError as e:  # no pixels yet
            raise ValueError(f"render an image first (F12): the Render Result cannot be saved ({e})") from e
        finally:
            _restore(im, old)
        if not os.path.isfile(path):
            raise ValueError("the Render Result has no pixels: render an image first (F12)")
        bufs = atrous.read_buffers(path, layer=view_layer_of(context))
    s = scene.atrous
    out = atrous.denoise(**bufs, method=s.spatial, device="auto")
    h, w = out.shape[:2]
    img = bpy.data.images.get(RESULT_IMAGE)
    if img is None or tuple(img.size) != (w, h):
        if img is not None:
            bpy.data.images.remove(img)
        img = bpy.data.images.new(RESULT_IMAGE, w, h, alpha=True, float_buffer=True)
    rgba = np.ones((h, w, 4), np.float32)
    rgba[..., :3] = out[::-1]  # Blender's rows go bottom-up
    img.pixels.foreach_set(rgba.ravel())
    img.update()
    if s.output:
        folder = bpy.path.abspath(s.output)
        os.makedirs(folder, exist_ok=True)
        atrous.write_image(os.path.join(folder, "still.exr"), out)
    return img


class ATROUS_OT_denoise_still(bpy.types.Operator):
    """Denoise the Render Result (an F12 render with its Denoising Data passes) with atrous"""

    bl_idname = "atrous.denoise_still"
    bl_label = "Denoise Render Result (atrous)"
    bl_options = {"REGISTER"}

    def execute(self, context):
        try:
            img = denoise_still(context)
        except (ValueError, RuntimeError) as e:
            context.scene.atrous.last_result = f"failed: {e}"
            self.report({"ERROR"}, f"atrous: {e}")
            return {"CANCELLED"}
        msg = f"Render Result denoised ({context.scene.atrous.spatial}) into the image '{img.name}'"
        context.scene.atrous.last_result = msg
        self.report({"INFO"}, f"atrous: {msg}")
        return {"FINISHED"}


class ATROUS_PT_denoise(bpy.types.Panel):
    bl_label = "Denoise Animation (atrous)"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "output"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        s = context.scene.atrous
        layout.prop(s, "method")
        layout.prop(s, "spatial")
        layout.prop(s, "output")
        layout.prop(s, "preview")
        if not is_multilayer(context.scene):
            layout.label(text="Needs Media Type: Multi-Layer EXR", icon="ERROR")
        layout.operator(ATROUS_OT_denoise_animation.bl_idname)
        layout.operator(ATROUS_OT_denoise_still.bl_idname)
        if s.last_result:
            layout.label(text=s.last_result)


def _menu(self, context):
    self.layout.operator(ATROUS_OT_denoise_animation.bl_idname)
    self.layout.operator(ATROUS_OT_denoise_still.bl_idname)


_CLASSES = (AtrousSettings, ATROUS_OT_denoise_animation, ATROUS_OT_denoise_still, ATROUS_PT_denoise)


def _render_menu() -> Optional[type]:
    return getattr(bpy.types, "TOPBAR_MT_render", None)


def register() -> None:
    for c in _CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Scene.atrous = bpy.props.PointerProperty(type=AtrousSettings)
    menu = _render_menu()
    if menu is not None:
        menu.append(_menu)


def unregister() -> None:
    menu = _render_menu()
    if menu is not None:
        menu.remove(_menu)
    del bpy.types.Scene.atrous
    for c in reversed(_CLASSES):
        bpy.utils.unregister_class(c)
