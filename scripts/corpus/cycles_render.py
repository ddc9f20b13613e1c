"""Blender Cycles (bpy wheel) part of the third-party corpus. Run by render.py inside .venv-corpus:

    .venv-corpus/bin/python scripts/corpus/cycles_render.py --mode quick|full --out out/corpus/quick

Scenes are built from scratch with bpy (factory settings, empty file), nothing is downloaded.
Layout written, as a Blender user has it: one OPEN_EXR_MULTILAYER file per render (float32, ZIP)
with the passes Combined, Denoising Data, Normal, Position, Z, Emission, Object Index, Material
Index and Vector. Cycles on the CPU, denoiser off, adaptive sampling off, fixed seeds.
"""
import math
import sys
import time
from pathlib import Path

import numpy as np

from common import (SEED_SEQ, SEED_SEQ_REF, SEED_SEQ_SPP, seq_spp_folder, done, exr_channels, merged_render_seconds,  # noqa: E402
                    exr_read_all,
                    log, parse_render_args, still_jobs, write_manifest)

import bpy  # noqa: E402
from mathutils import Vector  # noqa: E402


# ---------------------------------------------------------------- scene building helpers
def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    return sc


def material(name, kind, color=(0.8, 0.8, 0.8), rough=0.5, strength=10.0, tex=None, index=0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.pass_index = index
    nt = m.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    if kind == "emission":
        s = nt.nodes.new("ShaderNodeEmission")
        s.inputs["Color"].default_value = (*color, 1)
        s.inputs["Strength"].default_value = strength
        nt.links.new(s.outputs[0], out.inputs["Surface"])
        return m
    if kind == "glass":
        s = nt.nodes.new("ShaderNodeBsdfGlass")
        s.inputs["Color"].default_value = (*color, 1)
        s.inputs["Roughness"].default_value = rough
        s.inputs["IOR"].default_value = 1.5
        nt.links.new(s.outputs[0], out.inputs["Surface"])
        return m
    s = nt.nodes.new("ShaderNodeBsdfPrincipled")
    s.inputs["Base Color"].default_value = (*color, 1)
    s.inputs["Roughness"].default_value = rough
    s.inputs["Metallic"].default_value = 1.0 if kind == "metal" else 0.0
    if tex is not None:
        tex(nt, s)
    nt.links.new(s.outputs[0], out.inputs["Surface"])
    return m


def tex_checker(c1, c2, scale):
    def f(nt, s):
        t = nt.nodes.new("ShaderNodeTexChecker")
        t.inputs["Color1"].default_value = (*c1, 1)
        t.inputs["Color2"].default_value = (*c2, 1)
        t.inputs["Scale"].default_value = scale
        nt.links.new(t.outputs["Color"], s.inputs["Base Color"])
    return f


def tex_detail(scale_checker, scale_noise, c1=(0.8, 0.75, 0.6), c2=(0.1, 0.12, 0.15)):
    """Fine detail: a small checker multiplied by multi-octave noise, plus noise-driven roughness."""
    def f(nt, s):
        ch = nt.nodes.new("ShaderNodeTexChecker")
        ch.inputs["Color1"].default_value = (*c1, 1)
        ch.inputs["Color2"].default_value = (*c2, 1)
        ch.inputs["Scale"].default_value = scale_checker
        no = nt.nodes.new("ShaderNodeTexNoise")
        no.inputs["Scale"].default_value = scale_noise
        no.inputs["Detail"].default_value = 8.0
        mix = nt.nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        mix.blend_type = "MULTIPLY"
        mix.inputs["Factor"].default_value = 0.8
        nt.links.new(ch.outputs["Color"], mix.inputs[6])
        nt.links.new(no.outputs["Color"], mix.inputs[7])
        nt.links.new(mix.outputs[2], s.inputs["Base Color"])
        nt.links.new(no.outputs["Fac"], s.inputs["Roughness"])
    return f


def tex_brick(scale):
    def f(nt, s):
        b = nt.nodes.new("ShaderNodeTexBrick")
        b.inputs["Scale"].default_value = scale
        b.inputs["Color1"].default_value = (0.6, 0.25, 0.15, 1)
        b.inputs["Color2"].default_value = (0.45, 0.2, 0.12, 1)
        b.inputs["Mortar"].default_value = (0.8, 0.8, 0.75, 1)
        nt.links.new(b.outputs["Color"], s.inputs["Base Color"])
    return f


_obj_index = [0]


def add(kind, mat, loc=(0, 0, 0), rot=(0, 0, 0), scale=(1, 1, 1), smooth=True, **kw):
    ops = {"sphere": bpy.ops.mesh.primitive_uv_sphere_add, "cube": bpy.ops.mesh.primitive_cube_add,
           "plane": bpy.ops.mesh.primitive_plane_add, "cylinder": bpy.ops.mesh.primitive_cylinder_add,
           "monkey": bpy.ops.mesh.primitive_monkey_add, "torus": bpy.ops.mesh.primitive_torus_add}
    if kind == "sphere":
        kw.setdefault("segments", 64)
        kw.setdefault("ring_count", 32)
    ops[kind](location=loc, rotation=rot, **kw)
    o = bpy.context.active_object
    o.scale = scale
    if smooth and kind in ("sphere", "cylinder", "monkey", "torus"):
        for p in o.data.polygons:
            p.use_smooth = True
    if kind == "monkey":
        mod = o.modifiers.new("subd", "SUBSURF")
        mod.levels = mod.render_levels = 2
    o.data.materials.append(mat)
    _obj_index[0] += 1
    o.pass_index = _obj_index[0]
    return o


def wire(p0, p1, r, mat):
    p0, p1 = Vector(p0), Vector(p1)
    d = p1 - p0
    o = add("cylinder", mat, loc=(p0 + p1) / 2, radius=r, depth=d.length, vertices=12)
    o.rotation_mode = "QUATERNION"
    o.rotation_quaternion = d.to_track_quat("Z", "Y")
    return o


def camera(sc, loc, target, lens=35.0):
    cam = bpy.data.objects.get("Camera")
    if cam is None:
        cd = bpy.data.cameras.new("Camera")
        cd.sensor_fit = "HORIZONTAL"
        cam = bpy.data.objects.new("Camera", cd)
        sc.collection.objects.link(cam)
        sc.camera = cam
    cam.data.lens = lens
    cam.location = loc
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = (Vector(target) - Vector(loc)).to_track_quat("-Z", "Y")
    return cam


def world_constant(sc, color, strength=1.0):
    w = bpy.data.worlds.new("World")
    sc.world = w
    w.use_nodes = True
    bg = w.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1)
    bg.inputs["Strength"].default_value = strength


def world_sky(sc, sun_elev_deg, sun_rot_deg, strength=1.0):
    """Procedural sky texture (Blender's default physical sky model) + a matching sun lamp."""
    w = bpy.data.worlds.new("World")
    sc.world = w
    w.use_nodes = True
    nt = w.node_tree
    sky = nt.nodes.new("ShaderNodeTexSky")
    try:
        sky.sun_disc = False  # the sun is the lamp below (cleaner sampling than a sky disc)
    except AttributeError:
        pass
    sky.sun_elevation = math.radians(sun_elev_deg)
    sky.sun_rotation = math.radians(sun_rot_deg)
    nt.links.new(sky.outputs["Color"], nt.nodes["Background"].inputs["Color"])
    nt.nodes["Background"].inputs["Strength"].default_value = strength
    ld = bpy.data.lights.new("Sun", "SUN")
    ld.energy = 4.0
    ld.angle = math.radians(0.54)
    sun = bpy.data.objects.new("Sun", ld)
    sc.collection.objects.link(sun)
    # the sun shines from (elev, rot): its -Z axis points away from that direction
    el, ro = math.radians(sun_elev_deg), math.radians(sun_rot_deg)
    to_sun = Vector((math.sin(ro) * math.cos(el), -math.cos(ro) * math.cos(el), math.sin(el)))
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = (-to_sun).to_track_quat("-Z", "Y")
    return sky.sky_type


# ---------------------------------------------------------------- scenes (Blender: z up)
def scene_glass_mirror(sc):
    floor = material("floor", "diffuse", tex=tex_checker((0.8, 0.8, 0.75), (0.08, 0.08, 0.1), 12), index=1)
    add("plane", floor, scale=(5, 5, 1))
    add("monkey", material("glass", "glass", rough=0.0, index=2), loc=(-0.6, 0, 0.55), rot=(0.3, 0, 0.5),
        scale=(0.5, 0.5, 0.5))
    add("sphere", material("roughmetal", "metal", color=(0.95, 0.64, 0.54), rough=0.3, index=3),
        loc=(0.65, 0.4, 0.42), radius=0.42)
    # mirror at the back, tilted
    add("plane", material("mirror", "metal", color=(0.97, 0.97, 0.97), rough=0.0, index=4),
        loc=(0.2, 1.6, 1.0), rot=(math.radians(80), 0, math.radians(-15)), scale=(1.4, 1.0, 1))
    # visible area light: an emissive panel in view, facing the scene
    add("plane", material("panel", "emission", color=(1.0, 0.95, 0.85), strength=30, index=5),
        loc=(-1.3, 1.0, 1.9), rot=(math.radians(-120), 0, math.radians(-30)), scale=(0.5, 0.3, 1))
    world_constant(sc, (0.12, 0.12, 0.14))
    camera(sc, (0.3, -3.6, 1.5), (0, 0.2, 0.55), lens=32)
    return "glass monkey (subdivided), mirror, rough copper, checker floor, visible emissive panel", \
        "world constant (0.12, 0.12, 0.14)"


def scene_sunsky_thin(sc):
    add("plane", material("ground", "diffuse", tex=tex_detail(60, 20), index=1), scale=(30, 30, 1))
    metal = material("alu", "metal", color=(0.91, 0.92, 0.92), rough=0.35, index=2)
    add("cylinder", metal, loc=(-0.9, 0.3, 0.5), radius=0.3, depth=1.0, vertices=64)
    add("sphere", material("gold", "metal", color=(1.0, 0.77, 0.34), rough=0.12, index=3), loc=(0.8, 0.6, 0.4),
        radius=0.4)
    add("torus", material("glass", "glass", rough=0.05, index=4), loc=(0.0, -0.4, 0.25),
        rot=(math.radians(70), 0, 0.3), major_radius=0.35, minor_radius=0.1)
    # thin geometry: a fence of 16 mm wires (< 1 px at 256x256) and two rails (24 and 10 mm)
    wm = material("wire", "metal", color=(0.6, 0.6, 0.62), rough=0.4, index=5)
    for i in range(21):
        x = -1.6 + 0.16 * i
        wire((x, 1.3, 0), (x, 1.3, 1.1), 0.008, wm)
    wire((-1.7, 1.3, 1.1), (1.7, 1.3, 1.1), 0.012, wm)
    wire((-1.7, 1.3, 0.55), (1.7, 1.3, 0.55), 0.005, wm)
    sky = world_sky(sc, 35, 140)
    camera(sc, (0.4, -3.8, 1.3), (0, 0.3, 0.5), lens=35)
    return f"sky texture ({sky}) + sun lamp, rough aluminium/gold, glass torus, wire fence (10-24 mm wide, about 0.5-1 px), " \
        "fine procedural ground", "sky texture where nothing is hit"


def scene_interior(sc):
    wall = material("wall", "diffuse", color=(0.7, 0.68, 0.62), rough=0.8, index=1)
    W, D, H = 2.0, 2.0, 2.6
    add("plane", material("floor", "diffuse", tex=tex_checker((0.55, 0.4, 0.3), (0.35, 0.25, 0.18), 8), index=2),
        scale=(W, D, 1))
    add("plane", wall, loc=(0, 0, H), rot=(math.pi, 0, 0), scale=(W, D, 1))
    add("plane", wall, loc=(0, D, H / 2), rot=(math.pi / 2, 0, 0), scale=(W, H / 2, 1))
    add("plane", wall, loc=(0, -D, H / 2), rot=(-math.pi / 2, 0, 0), scale=(W, H / 2, 1))
    add("plane", material("blue", "diffuse", color=(0.3, 0.45, 0.6), index=3), loc=(-W, 0, H / 2),
        rot=(0, math.pi / 2, 0), scale=(H / 2, D, 1))
    # right wall (x = +W) with a window y in [-1.0, 0.6], z in [0.7, 2.0]
    y0, y1, z0, z1 = -1.0, 0.6, 0.7, 2.0

    def rwall(ya, yb, za, zb):
        add("plane", wall, loc=(W, (ya + yb) / 2, (za + zb) / 2), rot=(0, -math.pi / 2, 0),
            scale=((zb - za) / 2, (yb - ya) / 2, 1))
    rwall(-D, y0, 0, H)
    rwall(y1, D, 0, H)
    rwall(y0, y1, 0, z0)
    rwall(y0, y1, z1, H)
    add("cube", material("sofa", "diffuse", color=(0.6, 0.15, 0.1), index=4), loc=(-1.3, 1.2, 0.3),
        scale=(0.6, 0.5, 0.3))
    add("sphere", material("copper", "metal", color=(0.95, 0.64, 0.54), rough=0.25, index=5),
        loc=(-0.3, 0.6, 0.35), radius=0.35)
    add("cube", material("table", "diffuse", color=(0.8, 0.8, 0.75), index=6), loc=(0.6, -0.3, 0.4),
        scale=(0.35, 0.35, 0.4))
    sky = world_sky(sc, 30, 70)  # the sun shines in through the window (from +x, 30 degrees up)
    camera(sc, (-1.6, -1.85, 1.3), (0.4, 0.9, 0.8), lens=20)
    return f"closed room lit by sun + sky ({sky}) through a window in the right wall (mostly indirect)", \
        "sky texture seen through the window"


def scene_textures_box(sc):
    add("plane", material("floor", "diffuse", tex=tex_detail(120, 40), index=1), scale=(4, 4, 1))
    add("plane", material("bricks", "diffuse", tex=tex_brick(12), index=2), loc=(0, 1.5, 1.5),
        rot=(math.pi / 2, 0, 0), scale=(4, 1.5, 1))
    add("cube", material("checker", "diffuse", tex=tex_checker((0.9, 0.9, 0.9), (0.05, 0.05, 0.05), 40), index=3),
        loc=(-0.8, 0.2, 0.4), rot=(0, 0, 0.5), scale=(0.4, 0.4, 0.4))
    add("sphere", material("steel", "metal", color=(0.75, 0.75, 0.78), rough=0.2, index=4), loc=(0.7, 0.0, 0.45),
        radius=0.45)
    wm = material("hair", "diffuse", color=(0.9, 0.85, 0.6), index=5)
    for i in range(30):  # thin "grass" blades: 8 mm wires (about 0.6 px) fanning out in front
        a = -0.6 + 1.2 * i / 29
        wire((-0.3 + 0.02 * i, -1.0, 0), (-0.3 + 0.02 * i + 0.5 * math.sin(a), -1.0 + 0.1 * math.cos(a), 0.7),
             0.004, wm)
    ld = bpy.data.lights.new("Key", "AREA")
    ld.energy = 300
    ld.size = 1.0
    key = bpy.data.objects.new("Key", ld)
    sc.collection.objects.link(key)
    key.location = (2.0, -2.0, 3.0)
    key.rotation_mode = "QUATERNION"
    key.rotation_quaternion = (Vector((0, 0, 0.3)) - key.location).to_track_quat("-Z", "Y")
    world_constant(sc, (0.05, 0.06, 0.08))
    camera(sc, (0.2, -3.4, 1.4), (0, 0.3, 0.5), lens=35)
    sc.cycles.pixel_filter_type = "BOX"
    return "fine procedural textures (120x checker*noise floor, bricks, 40x checker cube), 8 mm blades, " \
        "steel sphere, area lamp; BOX pixel filter", "world constant (0.05, 0.06, 0.08)"


def scene_orbit(sc, nframes):
    add("plane", material("floor", "diffuse", tex=tex_checker((0.7, 0.7, 0.7), (0.15, 0.15, 0.18), 10), index=1),
        scale=(5, 5, 1))
    add("sphere", material("glass", "glass", index=2), loc=(-0.5, 0, 0.45), radius=0.45)
    add("sphere", material("copper", "metal", color=(0.95, 0.64, 0.54), rough=0.15, index=3), loc=(0.55, 0.3, 0.4),
        radius=0.4)
    mover = add("cube", material("blue", "diffuse", color=(0.2, 0.5, 0.8), index=4), loc=(0.2, -0.7, 0.25),
                scale=(0.25, 0.25, 0.25))
    add("plane", material("panel", "emission", color=(1, 1, 0.95), strength=8, index=5), loc=(0, 0, 2.6),
        rot=(math.pi, 0, 0), scale=(0.8, 0.8, 1))
    world_constant(sc, (0.05, 0.05, 0.06))
    cam = camera(sc, (0, -3.3, 1.4), (0, 0, 0.4), lens=35)
    sc.frame_start, sc.frame_end = 1, nframes
    for f in range(nframes):
        ang = math.radians(-30 + 60 * f / max(1, nframes - 1))
        loc = Vector((3.3 * math.sin(ang), -3.3 * math.cos(ang), 1.4))
        cam.location = loc
        cam.rotation_quaternion = (Vector((0, 0, 0.4)) - loc).to_track_quat("-Z", "Y")
        cam.keyframe_insert("location", frame=f + 1)
        cam.keyframe_insert("rotation_quaternion", frame=f + 1)
        mover.location = (0.2 + 0.6 * f / max(1, nframes - 1), -0.7, 0.25)  # the box slides along +x
        mover.keyframe_insert("location", frame=f + 1)
    for o in (cam, mover):
        for fc in o.animation_data.action.fcurves if hasattr(o.animation_data.action, "fcurves") else []:
            for k in fc.keyframe_points:
                k.interpolation = "LINEAR"
    return "glass + copper spheres, sliding box, checker floor, overhead emissive panel; camera orbits 60 degrees", \
        "world constant (0.05, 0.05, 0.06)"


def scene_turntable(sc, nframes):
    """A product turntable: static camera, objects turning; glass, polished copper, a visible softbox."""
    add("plane", material("floor", "diffuse", tex=tex_checker((0.6, 0.6, 0.6), (0.2, 0.2, 0.22), 8), index=1),
        scale=(5, 5, 1))
    add("plane", material("backdrop", "diffuse", color=(0.55, 0.5, 0.45), index=2), loc=(0, 2.2, 1.5),
        rot=(math.pi / 2, 0, 0), scale=(5, 2, 1))
    pivot = bpy.data.objects.new("Turntable", None)
    sc.collection.objects.link(pivot)
    disc = add("cylinder", material("disc", "metal", color=(0.7, 0.7, 0.72), rough=0.35, index=3), loc=(0, 0, 0.05),
               scale=(1.3, 1.3, 0.05), vertices=96)
    monkey = add("monkey", material("glass", "glass", index=4), loc=(-0.5, 0, 0.6), rot=(0, 0, -0.5),
                 scale=(0.45, 0.45, 0.45))
    torus = add("torus", material("copper", "metal", color=(0.95, 0.64, 0.54), rough=0.1, index=5),
                loc=(0.6, 0.1, 0.45), rot=(math.pi / 2, 0, 0.4), major_radius=0.35, minor_radius=0.12)
    for o in (disc, monkey, torus):
        o.parent = pivot
    add("plane", material("softbox", "emission", color=(1, 0.97, 0.92), strength=14, index=6), loc=(1.9, 1.3, 1.7),
        rot=(math.radians(70), 0, math.radians(-130)), scale=(0.5, 0.35, 1))
    add("plane", material("key", "emission", color=(1, 1, 1), strength=5, index=7), loc=(-2.0, -1.8, 3.0),
        rot=(math.radians(-40), math.radians(-35), 0), scale=(1.0, 1.0, 1))  # out of view
    world_constant(sc, (0.03, 0.03, 0.035))
    camera(sc, (0.2, -4.1, 1.8), (0.1, 0.2, 0.5), lens=35)
    sc.frame_start, sc.frame_end = 1, nframes
    for f in range(nframes):
        pivot.rotation_euler = (0, 0, math.radians(90 * f / max(1, nframes - 1)))
        pivot.keyframe_insert("rotation_euler", frame=f + 1)
    act = pivot.animation_data.action
    for fc in act.fcurves if hasattr(act, "fcurves") else []:
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"
    return "turntable: glass Suzanne, polished copper torus and a brushed disc turning 90 degrees on a checker " \
        "floor before a backdrop, a visible softbox and a key light out of view; static camera", \
        "world constant (0.03, 0.03, 0.035)"


def scene_studio(sc):
    """Issue 47's highlights: a glossy red ball and a chrome ball under a small key light out of
    view (their highlights a few pixels across, far brighter than anything around) and a visible
    emissive panel, on a grey floor and backdrop."""
    world_constant(sc, (0.02, 0.02, 0.025))
    floor = material("floor", "diffuse", (0.5, 0.5, 0.5), 0.6)
    add("plane", floor, loc=(0, 0, 0), scale=(6, 6, 1))
    add("plane", floor, loc=(0, 3, 2), rot=(math.radians(90), 0, 0), scale=(6, 3, 1))
    add("sphere", material("red", "diffuse", (0.6, 0.08, 0.05), 0.08, index=2), loc=(-0.7, 0, 0.6), radius=0.6)
    add("sphere", material("chrome", "metal", (0.9, 0.9, 0.9), 0.06, index=3), loc=(0.8, -0.4, 0.5), radius=0.5)
    add("plane", material("panel", "emission", (1, 0.95, 0.9), strength=25.0, index=4), loc=(0, 1.5, 2.6),
        rot=(math.radians(70), 0, 0), scale=(0.6, 0.25, 1))
    bpy.ops.object.light_add(type="AREA", location=(-2.5, -2, 3.5))
    key = bpy.context.active_object
    key.data.energy, key.data.size = 300, 0.3
    key.rotation_mode = "QUATERNION"
    key.rotation_quaternion = (Vector((0, 0, 0.5)) - key.location).to_track_quat("-Z", "Y")
    camera(sc, (0, -5.5, 1.6), (0, 0, 0.8), lens=40)
    return ("glossy red ball (roughness 0.08) and chrome ball (0.06) under a small key light out of view: "
            "specular highlights of a few pixels; visible emissive panel (strength 25)"), \
        "world constant (0.02, 0.02, 0.025)"


STILLS = {
    "cy_glass_mirror": scene_glass_mirror,
    "cy_sunsky_thin": scene_sunsky_thin,
    "cy_interior": scene_interior,
    "cy_textures_box": scene_textures_box,
}
QUICK = ["cy_glass_mirror", "cy_sunsky_thin"]
# Stills rendered only when named (--scenes; kept out of --full, whose figures they would change).
NAMED_ONLY = {"cy_studio": scene_studio}
# The sequences: cy_orbit in every mode (the CI subset renders it at 48x48), cy_turntable in --full.
SEQUENCES = {"cy_orbit": scene_orbit, "cy_turntable": scene_turntable}
QUICK_SEQUENCES = ["cy_orbit"]


# ---------------------------------------------------------------- render settings
def configure(sc, res, spp, seed):
    sc.render.resolution_x = sc.render.resolution_y = res
    sc.render.resolution_percentage = 100
    sc.render.threads_mode = "FIXED"
    sc.render.threads = 2
    sc.render.use_motion_blur = False  # the Vector pass needs it off
    c = sc.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = seed
    c.use_animated_seed = False
    vl = sc.view_layers[0]
    vl.use_pass_combined = True
    vl.use_pass_z = True
    vl.use_pass_normal = True
    vl.use_pass_position = True
    vl.use_pass_emit = True
    vl.use_pass_object_index = True
    vl.use_pass_material_index = True
    vl.use_pass_vector = True
    vl.cycles.denoising_store_passes = True
    im = sc.render.image_settings
    try:
        im.media_type = "MULTI_LAYER_IMAGE"  # Blender 5: multilayer EXR is a media type
        im.file_format = "OPEN_EXR"
    except (AttributeError, TypeError):
        im.file_format = "OPEN_EXR_MULTILAYER"
    im.color_depth = "32"
    im.exr_codec = "ZIP"


def render_to(sc, path):
    t = time.time()
    tmp = Path(str(path) + ".part.exr")
    sc.render.filepath = str(tmp)
    bpy.ops.render.render(write_still=True)
    tmp.rename(path)
    return time.time() - t


def settings_record(sc):
    c = sc.cycles
    return {"pixel_filter": c.pixel_filter_type, "filter_width_px": round(c.filter_width, 3),
            "max_bounces": c.max_bounces, "diffuse_bounces": c.diffuse_bounces, "glossy_bounces": c.glossy_bounces,
            "transmission_bounces": c.transmission_bounces, "caustics_reflective": c.caustics_reflective,
            "caustics_refractive": c.caustics_refractive, "blur_glossy": round(c.blur_glossy, 3),
            "sample_clamp_direct": c.sample_clamp_direct, "sample_clamp_indirect": c.sample_clamp_indirect,
            "light_tree": getattr(c, "use_light_tree", None), "device": c.device,
            "adaptive_sampling": c.use_adaptive_sampling, "denoising": c.use_denoising,
            "file_format": sc.render.image_settings.file_format,
            "media_type": getattr(sc.render.image_settings, "media_type", None)}


CONVENTIONS = {
    "parts": "a MULTI-PART EXR: one part per pass, part name '<ViewLayer>.<Pass>' (e.g. 'ViewLayer.Combined'), "
             "channels inside it fully qualified '<ViewLayer>.<Pass>.<Channel>' (e.g. 'ViewLayer.Combined.R')",
    "color": "Combined.R/G/B/A: linear radiance, A = alpha (1 where the world is seen too: film not transparent)",
    "normal": "Normal.X/Y/Z: WORLD-space shading normal (z up); Denoising Normal: also world space",
    "albedo": "Denoising Albedo.R/G/B: Cycles' denoising albedo (passes through perfect specular to the next "
              "diffuse-ish hit)",
    "depth": "Depth.Z: camera-space depth along the view axis (view z, NOT ray distance; depth_check in the "
             "manifest measures it), 1e10 where the world is seen; Denoising Depth.Z: same definition",
    "position": "Position.X/Y/Z: world-space first-hit position (0 on the background)",
    "emission": "Emission.R/G/B: emission seen directly (the visible panel), 0 elsewhere",
    "ids": "'Object Index.X' = object pass_index (1.. per object, 0 background), 'Material Index.X' = material "
           "pass_index (1.. per material)",
    "vector": "Vector.X/Y/Z/W: pixel-space motion (see vector_check in the sequence manifest for which pair "
              "points to the previous frame and its sign)",
    "world": "Blender z up; camera looks down its -Z",
}


def check_depth(path, cam_loc, cam_fwd):
    """Which depth definition the Depth pass uses: compare with |P - cam| and with (P - cam).fwd."""
    ch = exr_read_all(path)
    z = ch["ViewLayer.Depth.Z"].astype(np.float64)
    p = np.stack([ch[f"ViewLayer.Position.{c}"] for c in "XYZ"], -1).astype(np.float64)
    hit = z < 1e5
    d = p - np.array(cam_loc)
    dist = np.linalg.norm(d, axis=-1)
    axial = d @ np.array(cam_fwd)
    return {"median_abs_vs_distance": float(np.median(np.abs(z - dist)[hit])),
            "median_abs_vs_view_z": float(np.median(np.abs(z - axial)[hit])),
            "background_value": float(z[~hit][0]) if (~hit).any() else None}


def vector_check(path, sc, frame_prev):
    """Compares the Vector pass with the motion implied by Position and the previous frame's camera."""
    from bpy_extras.object_utils import world_to_camera_view
    ch = exr_read_all(path)
    v = np.stack([ch[f"ViewLayer.Vector.{c}"] for c in "XYZW"], -1).astype(np.float64)
    p = np.stack([ch[f"ViewLayer.Position.{c}"] for c in "XYZ"], -1).astype(np.float64)
    ob = ch["ViewLayer.Object Index.X"]
    h, w = ob.shape
    cur = sc.frame_current
    rng = np.random.default_rng(0)
    ys, xs = np.nonzero(ob == 1)  # the static floor: camera motion only
    pick = rng.choice(len(ys), size=min(200, len(ys)), replace=False)
    sc.frame_set(frame_prev)
    exp = []
    for i in pick:
        y, x = ys[i], xs[i]
        q = world_to_camera_view(sc, sc.camera, Vector(p[y, x]))
        # blender image: rows stored bottom-up in EXR? EXR rows are top-down; ndc y is up
        px, py = q.x * w, (1 - q.y) * h
        exp.append((px - (x + 0.5), py - (y + 0.5)))
    sc.frame_set(cur)
    exp = np.array(exp)
    got = v[ys[pick], xs[pick]]
    res = {}
    for name, (a, b) in {"XY": (0, 1), "ZW": (2, 3)}.items():
        for sx in (1, -1):
            for sy in (1, -1):
                err = np.median(np.abs(got[:, a] * sx - exp[:, 0]) + np.abs(got[:, b] * sy - exp[:, 1]))
                res[f"{'+' if sx > 0 else '-'}{name[0]},{'+' if sy > 0 else '-'}{name[1]}"] = round(float(err), 4)
    best = min(res, key=res.get)
    return {"expected": "offset (x right, y down, pixels) from the current pixel to the previous frame's position",
            "median_error_px_by_mapping": res, "best": best,
            "median_expected_magnitude_px": round(float(np.median(np.linalg.norm(exp, axis=1))), 3)}


def main():
    a, mode, root, names = parse_render_args("cycles", QUICK, STILLS, NAMED_ONLY)
    res = mode["res"]
    version = bpy.app.version_string
    for name in names:
        d = root / name
        d.mkdir(parents=True, exist_ok=True)
        files, times = {}, {}
        what = bg = settings = None
        for spp, seed, stem in still_jobs(mode):
            _obj_index[0] = 0
            sc = reset()
            what, bg = {**STILLS, **NAMED_ONLY}[name](sc)
            configure(sc, res, spp, seed)
            if name == "cy_textures_box":
                sc.cycles.pixel_filter_type = "BOX"
            settings = settings_record(sc)
            target = d / f"{stem}.exr"
            if not done(target):
                log(f"cycles {name} {stem} ...")
                times[stem] = render_to(sc, target)
                log(f"cycles {name} {stem} {times[stem]:.1f}s")
            files[stem] = {"spp": spp, "seed": seed, "file": target.name, "channels": exr_channels(target)}
        cam = sc.camera
        bpy.context.view_layer.update()  # matrix_world is stale until the depsgraph is evaluated
        fwd = cam.matrix_world.to_3x3() @ Vector((0, 0, -1))
        man_path = d / "manifest.json"
        write_manifest(man_path, {
            "scene": name, "renderer": "blender-cycles", "version": version, "description": what,
            "resolution": [res, res], "layout": "blender-multilayer-exr", "files": files,
            "reference": f"ref{mode['ref_spp']:04d}", "settings": settings, "render_seconds": merged_render_seconds(man_path, times),
            "conventions": CONVENTIONS, "background": bg,
            "depth_check": check_depth(d / f"ref{mode['ref_spp']:04d}.exr", list(cam.location), list(fwd)),
            "camera": {"location": list(cam.location), "forward": list(fwd), "lens_mm": cam.data.lens,
                       "sensor_width_mm": cam.data.sensor_width},
        })

    seqs = QUICK_SEQUENCES if a.mode == "quick" else list(SEQUENCES) if mode["seq_frames"] else []
    for seq in seqs:
        if not a.scenes or seq in a.scenes.split(","):
            render_sequence(seq, mode, root, version)


def render_sequence(name, mode, root, version):
    n, sres, rspp = mode["seq_frames"], mode["seq_res"], mode["seq_ref_spp"]
    d = root / name
    kinds = [("frames", seq_spp_folder(s), s, SEED_SEQ if s == 1 else SEED_SEQ_SPP + 1000 * s)
             for s in mode["seq_spp"]] + [("ref", "ref", rspp, SEED_SEQ_REF)]
    for _, folder, _, _ in kinds:
        (d / folder).mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    frames, checks = [], {}
    for kind, folder, spp, seed0 in kinds:
        _obj_index[0] = 0
        sc = reset()
        what, bg = SEQUENCES[name](sc, n)
        for f in range(n):
            configure(sc, sres, spp, seed0 + f)
            sc.frame_set(f + 1)
            target = d / folder / f"{f:04d}.exr"
            if not done(target):
                if kind == "ref":
                    log(f"cycles {name} frame {f} ref ...")
                render_to(sc, target)
            if kind == "ref" and f in (1, n - 1):
                checks[f] = vector_check(target, sc, f)  # frame_set numbering is f+1: previous is f
        settings = settings_record(sc)
    for f in range(n):
        frames.append({"frame": f, "blender_frame": f + 1, "file": f"frames/{f:04d}.exr",
                       "reference": f"ref/{f:04d}.exr", "seed": SEED_SEQ + f, "ref_seed": SEED_SEQ_REF + f})
    log(f"cycles {name} {n} frames {time.time() - t0:.1f}s")
    write_manifest(d / "manifest.json", {
        "scene": name, "renderer": "blender-cycles", "version": version, "description": what,
        "resolution": [sres, sres], "spp": 1, "reference_spp": rspp, "layout": "blender-multilayer-exr-sequence",
        "spp_folders": {str(s): seq_spp_folder(s) for s in mode["seq_spp"]},
        "frames": frames, "settings": settings, "channels": exr_channels(d / "frames" / "0000.exr"),
        "conventions": CONVENTIONS, "vector_check": {str(k): v for k, v in checks.items()}, "background": bg,
    })


if __name__ == "__main__":
    main()
