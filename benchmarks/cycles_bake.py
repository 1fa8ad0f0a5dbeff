"""Bakes a level's lightmap with Blender's Cycles, as a user would, for the comparison of
docs/levels.md: Cycles' time at the same error as hemilight on a stand-in level. Runs inside Blender:

  blender -b -P benchmarks/cycles_bake.py -- LEVEL.glb OUT.exr [--size 1024] [--samples 64]
      [--sky R,G,B] [--sun DX,DY,DZ,E[,A]] [--bounces 1] [--threads 2] [--margin 16] [--uv 1] [--seed 0]
      [--position]

LEVEL.glb from hemilight_make_level (lightmap UVs in TEXCOORD_1); --sky and --sun take the values
hemilight_make_level prints for hemilight_bake (the same meaning: the sun's direction of travel in
the glTF's axes (+y up), its irradiance facing it in W/m², its angular radius in radians).

What it sets up:
- the glb through Blender's glTF importer (numpy.bool restored first: Debian's Blender 3.4.1 with
  numpy >= 1.24 needs it), every material replaced by a Diffuse BSDF (Lambert, roughness 0) of the
  glTF base colour, so that the surfaces are what hemilight bakes: one-sided in hemilight, two-sided
  in Cycles (only the side facing the air is lit in both);
- the world: a Background of colour (R, G, B) and strength 1, i.e. radiance (R, G, B) from every
  direction (Blender: a white Background of strength s is radiance s);
- the sun as a Sun lamp of strength E (Blender's sun strength is the irradiance facing it, W/m²),
  pointing along the direction of travel converted to Blender's axes (the importer maps glTF
  (x, y, z) to (x, -z, y)), angle 2 A (Blender's angle is the sun's diameter);
- one float image SIZE x SIZE, the active image node of every material, baked through UV map
  --uv (the importer names TEXCOORD_0 "UVMap" and TEXCOORD_1 "UVMap.001": index 1 by default);
- bake type DIFFUSE, pass filter direct + indirect, colour off: the light arriving at the surface
  divided by pi, E / pi (checked on a plane under a sky of radiance 1: 1.0, E = pi; see
  benchmarks/README.md), written multiplied by pi so that the EXR holds irradiance E like
  hemilight's; diffuse bounces = BOUNCES - 1 (hemilight's bounces count the direct pass:
  --bounces 1 is direct light only), no glossy, transmission or volume bounces, no caustics, no
  clamping, no denoising, adaptive sampling off, SAMPLES samples per texel, Cycles' seed SEED
  (independent runs for a reference's noise estimate);
- render threads fixed at THREADS, CPU;
- margin: MARGIN texels of Blender's "extend" margin (chart borders dilated, as hemilight dilates).

--position bakes instead, through the same UV map, the mean over the samples of each texel of the
shading point's position (an EMIT bake of the position, in Blender's axes: (x, y, z) = glTF's
(x, -z, y)): where Cycles evaluates each texel (benchmarks/cycles_compare.py checks it).

Writes OUT.exr (32-bit float RGB; Blender's image rows: the first scanline is v = 1 of Blender's UV,
which is glTF's v = 0, so the rows are in hemilight's order for a glb: no flip; docs/levels.md) and
prints one line `cycles_bake: import S s, bake S s, save S s, samples N, size S` for the caller.
"""
import math
import sys
import time

import bpy  # noqa: E402  (only inside Blender)


def parse(argv):
    import argparse

    p = argparse.ArgumentParser(prog="cycles_bake.py")
    p.add_argument("glb")
    p.add_argument("out")
    p.add_argument("--size", type=int, default=1024)
    p.add_argument("--samples", type=int, default=64)
    p.add_argument("--sky", default="1,1,1")
    p.add_argument("--sun", default="")
    p.add_argument("--bounces", type=int, default=1)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--margin", type=int, default=16)
    p.add_argument("--uv", type=int, default=1)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--position", action="store_true")
    # "--sun -0.5,..." would read as an option: join every option that takes a value with it first
    takes_value = {"--size", "--samples", "--sky", "--sun", "--bounces", "--threads", "--margin", "--uv", "--seed"}
    joined, i = [], 0
    while i < len(argv):
        if argv[i] in takes_value and i + 1 < len(argv):
            joined.append(argv[i] + "=" + argv[i + 1])
            i += 2
        else:
            joined.append(argv[i])
            i += 1
    return p.parse_args(joined)


def floats(text):
    return [float(x) for x in text.split(",")]


def diffuse_material(mat, image, position=False):
    """Replaces the node tree of `mat` by Diffuse BSDF (glTF base colour) -> Material Output and
    an image node (the bake target) made active; with `position`, by an emission of the shading
    point's position + 1000 (Blender's axes) instead."""
    color = (0.8, 0.8, 0.8, 1.0)
    if mat.use_nodes:
        for n in mat.node_tree.nodes:
            if n.type == "BSDF_PRINCIPLED":
                color = tuple(n.inputs["Base Color"].default_value)
                break
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    if position:
        geo = nodes.new("ShaderNodeNewGeometry")
        add = nodes.new("ShaderNodeVectorMath")
        add.operation = "ADD"
        add.inputs[1].default_value = (1000.0, 1000.0, 1000.0)
        em = nodes.new("ShaderNodeEmission")
        mat.node_tree.links.new(geo.outputs["Position"], add.inputs[0])
        mat.node_tree.links.new(add.outputs[0], em.inputs["Color"])
        mat.node_tree.links.new(em.outputs["Emission"], out.inputs["Surface"])
    else:
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = color
        bsdf.inputs["Roughness"].default_value = 0.0
        mat.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.select = True
    nodes.active = tex


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    a = parse(argv)
    t0 = time.perf_counter()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    import warnings

    import numpy

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if not hasattr(numpy, "bool"):
            numpy.bool = bool  # Blender 3.4's glTF importer uses numpy.bool (removed in numpy 1.24)
    bpy.ops.import_scene.gltf(filepath=a.glb)
    t_import = time.perf_counter() - t0

    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = a.samples
    c.seed = a.seed
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = max(0, a.bounces - 1)
    c.diffuse_bounces = max(0, a.bounces - 1)
    c.glossy_bounces = c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = 0
    c.caustics_reflective = c.caustics_refractive = False
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = a.threads
    scene.view_settings.view_transform = "Standard"

    world = bpy.data.worlds.new("sky")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    sky = floats(a.sky)
    bg.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
    bg.inputs["Strength"].default_value = 1.0

    if a.sun:
        s = floats(a.sun)
        from mathutils import Vector

        d = Vector((s[0], -s[2], s[1])).normalized()  # glTF (x, y, z) -> Blender (x, -z, y)
        lamp = bpy.data.lights.new("sun", type="SUN")
        lamp.energy = s[3]
        lamp.angle = 2.0 * (s[4] if len(s) > 4 else 0.00465)
        obj = bpy.data.objects.new("sun", lamp)
        scene.collection.objects.link(obj)
        obj.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()  # a sun lamp shines along its -Z

    image = bpy.data.images.new("lightmap", a.size, a.size, alpha=False, float_buffer=True)
    meshes = [o for o in scene.objects if o.type == "MESH"]
    for m in bpy.data.materials:
        diffuse_material(m, image, a.position)
    bpy.ops.object.select_all(action="DESELECT")
    for o in meshes:
        if len(o.data.uv_layers) <= a.uv:
            sys.exit(f"cycles_bake: mesh {o.name} has {len(o.data.uv_layers)} UV maps, no map {a.uv}")
        o.data.uv_layers.active_index = a.uv
        o.select_set(True)
    bpy.context.view_layer.objects.active = meshes[0]

    b = scene.render.bake
    b.use_pass_direct = b.use_pass_indirect = True
    b.use_pass_color = False
    b.margin = a.margin
    b.margin_type = "EXTEND"
    b.target = "IMAGE_TEXTURES"
    b.use_clear = True
    t1 = time.perf_counter()
    if a.position:
        bpy.ops.object.bake(type="EMIT", margin=a.margin, use_clear=True)
    else:
        bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT", "INDIRECT"}, margin=a.margin, use_clear=True)
    t_bake = time.perf_counter() - t1

    t2 = time.perf_counter()
    px = numpy.empty(a.size * a.size * 4, dtype=numpy.float32)
    image.pixels.foreach_get(px)
    if a.position:
        px[:] -= 1000.0  # Blender's axes (x, y, z) = glTF (x, -z, y); alpha is not written
    else:
        px[:] *= math.pi  # E / pi -> E (alpha is not written)
    image.pixels.foreach_set(px)
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_mode = "RGB"
    s.color_depth = "32"
    s.exr_codec = "ZIP"
    image.save_render(a.out, scene=scene)
    t_save = time.perf_counter() - t2
    print(f"cycles_bake: import {t_import:.2f} s, bake {t_bake:.2f} s, save {t_save:.2f} s, samples {a.samples}, "
          f"size {a.size}, meshes {len(meshes)}", flush=True)


main()
