"""Measures the directional albedo of Cycles' microfiber sheen (Blender 4.x's
Principled sheen, Zeltner et al. 2022: an LTC lobe fitted to a volumetric
fibre layer) with a furnace: a plane wearing nothing but sheen under a
uniform white world, seen by an orthographic camera at a fixed angle, with
no bounces: every pixel's radiance is the lobe's albedo at that view
cosine. One render per view cosine; the plane is cut into strips of the 9
sheen roughnesses (coplanar, so none hides the world from another).

Prints the 9 x 9 table tests/native/test_closures.cpp holds (rows of view
cosine 0.02, 0.125 .. 1, columns of roughness 0.05, 0.125 .. 1): the lobe
the kernels evaluate (fitted to lamp-lit renders by
scripts/tables/sheen_ltc_cycles.py) must integrate to it. The module also lends
its scene to that script. Run with a Python that has the bpy module (4.0 or later):

  build/bpy-4.5.15/bin/python3 scripts/tables/sheen_albedo_cycles.py
"""

import math
import os
import tempfile

import bpy
import numpy as np

COSINES = [0.02] + [k / 8 for k in range(1, 9)]
ROUGHNESS = [0.05] + [k / 8 for k in range(1, 9)]
STRIP = 2.0  # width of one roughness's strip
LENGTH = 400.0  # the plane's extent away from the camera: it fills the frame even edge-on
W, H = 180, 60


def sheen_material(roughness):
    m = bpy.data.materials.new(f"sheen_{roughness}")
    m.use_nodes = True
    p = next(n for n in m.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    p.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    p.inputs["Specular IOR Level"].default_value = 0.0
    p.inputs["Sheen Weight"].default_value = 1.0
    p.inputs["Sheen Roughness"].default_value = roughness
    p.inputs["Sheen Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
    return m


def build_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    n = len(ROUGHNESS)
    for k, r in enumerate(ROUGHNESS):
        x = (k - (n - 1) / 2) * STRIP
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(x, 0.0, 0.0))
        plane = bpy.context.object
        plane.scale = (STRIP, LENGTH, 1.0)
        plane.data.materials.append(sheen_material(r))
    world = bpy.data.worlds.new("white")
    world.use_nodes = True
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = n * STRIP
    cam.data.clip_start, cam.data.clip_end = 1.0, 2000.0
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.samples = 256
    c.use_denoising = False
    c.max_bounces = 0
    c.use_adaptive_sampling = False
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = W, H, 100
    scene.render.film_transparent = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.view_settings.view_transform = "Standard"
    return scene, cam


def measure(scene, cam, cosine):
    theta = math.acos(cosine)
    distance = 500.0
    cam.location = (0.0, -distance * math.sin(theta), distance * math.cos(theta))
    cam.rotation_euler = (theta, 0.0, 0.0)
    path = os.path.join(tempfile.gettempdir(), "sheen_furnace.exr")
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    px = np.array(img.pixels[:], dtype=np.float64).reshape(H, W, 4)
    bpy.data.images.remove(img)
    per = W // len(ROUGHNESS)
    # The middle half of each strip, away from its neighbours' pixels.
    return [float(px[:, k * per + per // 4: (k + 1) * per - per // 4, 0].mean()) for k in range(len(ROUGHNESS))]


def main():
    scene, cam = build_scene()
    table = np.array([measure(scene, cam, nv) for nv in COSINES])
    np.set_printoptions(precision=4, suppress=True)
    print(table)
    print(",".join(f"{x:.4f}f" for x in table.flatten()))


if __name__ == "__main__":
    main()
    os._exit(0)
