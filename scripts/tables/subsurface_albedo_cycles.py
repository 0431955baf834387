"""Measures how much light Cycles' random-walk subsurface scattering
(Blender 4.x: the Subsurface Scattering node's Random Walk and Random Walk
(Skin), and the Principled BSDF's subsurface) sends back from a thick flat
slab, as a share of its Color, for each view angle, entry roughness and IOR.

Why: from 4.0 on Cycles starts each walk by refracting the camera ray
through a rough dielectric boundary (at the closure's IOR and roughness; the
Skin method does so for half the walks and enters diffusely for the other
half), then leaves the slab through a Lambertian exit. What comes back is
Lambertian in the light's direction but not the Color: a walk that starts
steep goes deep and is absorbed more, one that starts grazing leaves soon.
For a Color of 0.1 seen head-on the slab returns 0.08, seen at 85 degrees
through a rough boundary 0.14. (Blender 3.x enters diffusely and returns the
Color at every angle, which is why the 3.x closure stays Lambert.)

The setup: slabs 10 deep and 400 long, one per albedo, side by side with
their tops coplanar, each of one grey Color with a radius of 0.1 (a
semi-infinite medium: the result depends on neither); a sun straight down
of strength pi, so a Lambertian surface of albedo A reads A; an
orthographic camera tilted by the view angle about the slabs' width; no
bounces. Each slab's middle columns are averaged (walks that reach a slab's
side leave through it).

Writes kernels/tables/mp_subsurface_table.h (the ratio returned / Color for each
IOR, roughness, view cosine and albedo; about a quarter of an hour on two
cores).
Run with a Python that has the bpy module (4.0 or later):

  build/bpy-4.5.15/bin/python3 scripts/tables/subsurface_albedo_cycles.py -- kernels/tables/mp_subsurface_table.h
"""

import math
import os
import sys
import tempfile

import bpy
import numpy as np

ALBEDOS = [0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0]
COSINES = [0.05] + [k / 8 for k in range(1, 9)]
ROUGHNESS = [k / 4 for k in range(5)]  # the entry's GGX alpha (Cycles' bssrdf->alpha)
ETAS = [0.25, 0.4375, 0.625, 0.8125, 1.0]  # 1 / IOR; Cycles clamps the IOR to [1.01, 3.8]
STRIP = 1.0
LENGTH = 400.0
DEPTH = 10.0
COLUMNS = 12  # pixels across one slab
ROWS = 24
SAMPLES = 512


def slab_material(albedo):
    m = bpy.data.materials.new(f"sss_{albedo}")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    sss = nt.nodes.new("ShaderNodeSubsurfaceScattering")
    sss.inputs["Color"].default_value = (albedo, albedo, albedo, 1.0)
    sss.inputs["Radius"].default_value = (1.0, 1.0, 1.0)
    sss.inputs["Scale"].default_value = 0.1
    nt.links.new(sss.outputs[0], out.inputs["Surface"])
    return m, sss


def build_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    nodes = []
    n = len(ALBEDOS)
    for k, a in enumerate(ALBEDOS):
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=((k - (n - 1) / 2) * STRIP, 0.0, -DEPTH / 2))
        slab = bpy.context.object
        slab.scale = (STRIP, LENGTH, DEPTH)
        material, sss = slab_material(a)
        slab.data.materials.append(material)
        nodes.append(sss)
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    next(n for n in world.node_tree.nodes if n.type == "BACKGROUND").inputs["Strength"].default_value = 0.0
    scene.world = world
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = math.pi
    sun.data.angle = 0.0
    scene.collection.objects.link(sun)
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = n * STRIP
    cam.data.clip_start = 0.1
    cam.data.clip_end = 1000.0
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.engine = "CYCLES"
    scene.cycles.samples = SAMPLES
    scene.cycles.max_bounces = 0
    scene.cycles.use_denoising = False
    scene.cycles.seed = 7
    scene.render.resolution_x = n * COLUMNS
    scene.render.resolution_y = ROWS
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    return scene, cam, nodes


def set_closure(nodes, method, alpha, eta):
    for sss in nodes:
        sss.falloff = method
        sss.inputs["IOR"].default_value = 1.0 / eta
        if "Roughness" in sss.inputs:  # Skin has none: its refracted half's is 1
            sss.inputs["Roughness"].default_value = alpha


def measure(scene, cam, cosine):
    theta = math.acos(cosine)
    cam.location = (0.0, -50.0 * math.sin(theta), 50.0 * math.cos(theta))
    cam.rotation_euler = (theta, 0.0, 0.0)
    path = os.path.join(tempfile.gettempdir(), f"sss_albedo_{os.getpid()}.exr")
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    px = np.array(img.pixels[:], dtype=np.float64).reshape(ROWS, len(ALBEDOS) * COLUMNS, 4)[..., 0]
    bpy.data.images.remove(img)
    os.remove(path)
    mid = slice(COLUMNS // 4, COLUMNS - COLUMNS // 4)
    return [px[:, k * COLUMNS:(k + 1) * COLUMNS][:, mid].mean() / a for k, a in enumerate(ALBEDOS)]


def header(walk, skin, version):
    """The table's header text: walk[eta][roughness][cosine][albedo] and
    skin[eta][cosine][albedo], ratios returned / Color."""
    out = ["/* Generated by scripts/tables/subsurface_albedo_cycles.py from Cycles " + version + " (" + str(SAMPLES),
           " * samples): what its random-walk subsurface scattering returns from a thick",
           " * flat slab as a share of its Color, under a lamp and with no bounces, for",
           " * each albedo (mp_sss_albedo_axis), view cosine (0.05, then 1/8 .. 1 in",
           " * eighths), entry roughness (GGX alpha 0 .. 1 in quarters) and 1 / IOR",
           " * (0.25 .. 1 in 4 steps; Cycles clamps the IOR to [1.01, 3.8]). Read by",
           " * mp_subsurface.h. Compiles as OpenCL C and C++. */",
           "#ifndef MP_SUBSURFACE_TABLE_H", "#define MP_SUBSURFACE_TABLE_H", "", '#include "core/mp_compat.h"', "",
           f"#define MP_SSS_ALBEDOS {len(ALBEDOS)}", f"#define MP_SSS_COSINES {len(COSINES)}",
           f"#define MP_SSS_ROUGHNESS {len(ROUGHNESS)}", f"#define MP_SSS_ETAS {len(ETAS)}", "",
           "MP_CONSTANT float mp_sss_albedo_axis[MP_SSS_ALBEDOS] = {" + ", ".join(f"{a:.2f}f" for a in ALBEDOS) + "};",
           "", "/* Random Walk: [1 / IOR][roughness][view cosine][albedo]. */",
           f"MP_CONSTANT float mp_sss_walk[{len(ETAS) * len(ROUGHNESS) * len(COSINES) * len(ALBEDOS)}] = {{"]
    for e, eta in enumerate(ETAS):
        for k, alpha in enumerate(ROUGHNESS):
            out.append(f"  /* 1 / IOR {eta}, roughness {alpha} */")
            out += ["  " + ", ".join(f"{r:.4f}f" for r in row) + "," for row in walk[e][k]]
    out += ["};", "", "/* Random Walk (Skin), roughness 1 on its refracted half: [1 / IOR][view cosine][albedo]. */",
            f"MP_CONSTANT float mp_sss_skin[{len(ETAS) * len(COSINES) * len(ALBEDOS)}] = {{"]
    for e, eta in enumerate(ETAS):
        out.append(f"  /* 1 / IOR {eta} */")
        out += ["  " + ", ".join(f"{r:.4f}f" for r in row) + "," for row in skin[e]]
    out += ["};", "", "#endif", ""]
    return "\n".join(out)


def main():
    path = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "kernels/tables/mp_subsurface_table.h"
    scene, cam, nodes = build_scene()
    walk, skin = [], []
    for eta in ETAS:
        walk.append([])
        for alpha in ROUGHNESS:
            set_closure(nodes, "RANDOM_WALK", alpha, eta)
            walk[-1].append([measure(scene, cam, c) for c in COSINES])
        set_closure(nodes, "RANDOM_WALK_SKIN", 1.0, eta)
        skin.append([measure(scene, cam, c) for c in COSINES])
    with open(path, "w") as f:
        f.write(header(walk, skin, bpy.app.version_string))


if __name__ == "__main__":
    main()
