"""Builds an lfgen export (blender_scene.json + meshes/*.obj beside this file) in Blender and
renders one light-field view with Cycles: colour (linear EXR) or planar depth (Z pass, 32-bit EXR).

    blender -b -P scene.py -- --view 40 --out cam040.exr [--depth] [--spp 64] [--threads N]

Written by `lfgen export --to blender`; works with Debian's blender 3.4 and the PyPI bpy wheel.
Settings follow lfgen's: box filter of width 1, view transform Standard, no dithering, no
denoising, no adaptive sampling, no clamping, equal bounce limits.
"""

import argparse
import json
import os
import sys

import bpy
from mathutils import Matrix, Vector

HERE = os.path.dirname(os.path.abspath(__file__))


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="scene.py")
    p.add_argument("--view", type=int, required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--depth", action="store_true", help="planar depth (Z pass) at 1 spp")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--threads", type=int, default=0)
    return p.parse_args(argv)


def set_input(node, names, value):
    """Sets the first input that exists (socket names differ between Blender 3.x and 4.x)."""
    for n in names:
        if n in node.inputs:
            node.inputs[n].default_value = value
            return


def make_material(m):
    mat = bpy.data.materials.new(m["name"])
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    out = nodes["Material Output"]
    bsdf = nodes["Principled BSDF"]
    color = (*m["color"], 1.0)
    if m["kind"] == "glass":
        nodes.remove(bsdf)
        bsdf = nodes.new("ShaderNodeBsdfGlass")
        bsdf.distribution = "SHARP"
        bsdf.inputs["Color"].default_value = color
        bsdf.inputs["IOR"].default_value = m["ior"]
        links.new(bsdf.outputs[0], out.inputs["Surface"])
        return mat
    if m["kind"] == "diffuse":
        # Lambert (Cycles' Diffuse BSDF at roughness 0), plus front-side emission and alpha.
        nodes.remove(bsdf)
        shader = nodes.new("ShaderNodeBsdfDiffuse")
        shader.inputs["Color"].default_value = color
        shader.inputs["Roughness"].default_value = 0.0
        if max(m["emission"]) > 0.0:
            emit = nodes.new("ShaderNodeEmission")
            emit.inputs["Color"].default_value = (*m["emission"], 1.0)
            links.new(front_side(nodes, links), emit.inputs["Strength"])
            add = nodes.new("ShaderNodeAddShader")
            links.new(shader.outputs[0], add.inputs[0])
            links.new(emit.outputs[0], add.inputs[1])
            shader = add
        if m["opacity"] < 1.0:
            mix = nodes.new("ShaderNodeMixShader")
            mix.inputs["Fac"].default_value = m["opacity"]
            links.new(nodes.new("ShaderNodeBsdfTransparent").outputs[0], mix.inputs[1])
            links.new(shader.outputs[0], mix.inputs[2])
            shader = mix
        links.new(shader.outputs[0], out.inputs["Surface"])
        return mat
    set_input(bsdf, ["Base Color"], color)
    set_input(bsdf, ["Roughness"], m["roughness"])
    set_input(bsdf, ["Metallic"], m["metallic"])
    set_input(bsdf, ["Specular", "Specular IOR Level"], 0.5)
    set_input(bsdf, ["Alpha"], m["opacity"])
    if m["opacity"] < 1.0:
        mat.blend_method = "BLEND"
    if max(m["emission"]) > 0.0:
        # lfgen's emitters shine from their front side only: strength = 1 - backfacing.
        set_input(bsdf, ["Emission", "Emission Color"], (*m["emission"], 1.0))
        links.new(front_side(nodes, links), bsdf.inputs["Emission Strength"])
    return mat


def front_side(nodes, links):
    """1 on the front side, 0 on the back (lfgen's emitters shine from their front only)."""
    geo = nodes.new("ShaderNodeNewGeometry")
    front = nodes.new("ShaderNodeMath")
    front.operation = "SUBTRACT"
    front.inputs[0].default_value = 1.0
    links.new(geo.outputs["Backfacing"], front.inputs[1])
    return front.outputs[0]


def import_obj(path):
    before = set(bpy.data.objects)
    full = os.path.join(HERE, path)
    if hasattr(bpy.ops.wm, "obj_import"):
        bpy.ops.wm.obj_import(filepath=full, forward_axis="NEGATIVE_Z", up_axis="Y")
    else:
        bpy.ops.import_scene.obj(filepath=full, axis_forward="-Z", axis_up="Y")
    objs = [o for o in bpy.data.objects if o not in before]
    for o in objs:
        # No shadow-terminator offsets (Cycles' default geometry offset 0.1 moves shadow-ray
        # origins of smooth-shaded low-poly faces off the triangle and brightens them; lfgen
        # spawns its rays from the triangle itself).
        for owner in (o, getattr(o, "cycles", None)):
            for name in ("shadow_terminator_geometry_offset", "shadow_terminator_offset"):
                if owner is not None and hasattr(owner, name):
                    setattr(owner, name, 0.0)
    return objs


def add_light(l):
    data = bpy.data.lights.new("light", l["type"])
    power = max(l["color"])
    if power > 0:
        data.color = tuple(c / power for c in l["color"])
    if l["type"] == "SUN":
        data.energy = power
    else:
        data.energy = power * l["power_scale"]
        data.shadow_soft_size = 0.0
    if l["type"] == "SPOT":
        data.spot_size = l["spot_size"]
        data.spot_blend = l["spot_blend"]
    obj = bpy.data.objects.new("light", data)
    if "location" in l:
        obj.location = l["location"]
    if "direction" in l:
        obj.rotation_euler = Vector(l["direction"]).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.collection.objects.link(obj)


def add_camera(data, c):
    cam = bpy.data.cameras.new(c["name"])
    cam.sensor_fit = "AUTO"
    cam.sensor_width = data["sensor_mm"]
    cam.lens = data["focal_mm"]
    cam.shift_x = c["shift_x"]
    cam.shift_y = c["shift_y"]
    cam.clip_start = 1e-3
    cam.clip_end = 1e4
    obj = bpy.data.objects.new(c["name"], cam)
    rot = Matrix(c["rotation"]).to_4x4()
    rot.translation = Vector(c["location"])
    obj.matrix_world = rot
    bpy.context.scene.collection.objects.link(obj)
    return obj


def settings(scene, data, args):
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = 1 if args.depth else args.spp
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.pixel_filter_type = "BOX"
    scene.render.filter_size = 1.0
    cy.seed = 1
    n = data["max_bounces"]
    for k in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
              "volume_bounces", "transparent_max_bounces"):
        setattr(cy, k, n if k != "transparent_max_bounces" else 64)
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.dither_intensity = 0.0
    scene.render.resolution_x, scene.render.resolution_y = data["resolution"]
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    if args.threads:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = args.threads
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR_MULTILAYER" if args.depth else "OPEN_EXR"
    img.color_depth = "32"
    img.exr_codec = "ZIP"
    scene.view_layers[0].use_pass_z = args.depth


def build(data, args):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    mats = [make_material(m) for m in data["materials"]]
    for o in data["objects"]:
        m = data["materials"][o["material"]]
        for obj in import_obj(o["mesh"]):
            obj.data.materials.clear()
            obj.data.materials.append(mats[o["material"]])
            # Depth: only surfaces that hide what is behind them in lfgen's HCI depth; cut-out
            # patterns are not exported to Blender, so those objects are left out too.
            obj.hide_render = args.depth and m["depth"] != "solid"
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*data["environment"], 1)
    scene.world = world
    for l in data["lights"]:
        add_light(l)
    cams = {c["view"]: c for c in data["cameras"]}
    if args.view not in cams:
        sys.exit(f"view {args.view} was not exported (exported: {sorted(cams)})")
    scene.camera = add_camera(data, cams[args.view])
    settings(scene, data, args)
    return scene


def main():
    args = parse_args()
    with open(os.path.join(HERE, "blender_scene.json")) as f:
        data = json.load(f)
    scene = build(data, args)
    scene.render.filepath = os.path.abspath(args.out)
    bpy.ops.render.render(write_still=True)


main()
