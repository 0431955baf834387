"""Occlusion culling in Blender (run by blender -b, or a Python with the bpy
module): F12 with Render > Bound & Split > Occlusion Culling on and off gives
the same image (PSNR >= 60 dB over the frame, alpha identical) on a camera
inside nested subdivided shells, on displaced surfaces behind a wall with a
small hole, and on a semi-transparent surface in front of an opaque one;
with it on, the hidden shells are culled (the renderer's own statistics,
from the exported scene). Exits non-zero on failure."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import render_utils as ru  # noqa: E402

RESULTS = []
W, H = 200, 150


def check(name, condition, detail=""):
    RESULTS.append(bool(condition))
    print(f"{'ok  ' if condition else 'FAIL'} {name}" + (f": {detail}" if detail else ""))


def material(name, color, alpha=1.0):
    """A Principled BSDF of `color` and `alpha`."""
    m, out = ru.empty_material(name)
    bsdf = m.node_tree.nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Alpha"].default_value = alpha
    m.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return m


def subdivided(obj, levels=2):
    mod = obj.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = mod.render_levels = levels
    return obj


def shells_scene(count):
    """The camera inside `count` nested subdivided cubes, each a colour."""
    scene = ru.reset_scene()
    for k in range(count):
        bpy.ops.mesh.primitive_cube_add(size=4.0 + 0.4 * k)
        obj = subdivided(bpy.context.object)
        obj.name = f"Shell{k}"
        obj.data.materials.append(material(f"Shell{k}", (0.2 + 0.7 * k / max(count - 1, 1), 0.5, 0.3)))
    ru.add_camera(scene, (0.3, -0.2, 0.1), (1.0, 2.0, 0.4))
    ru.add_sun(scene, (math.radians(40), 0.0, math.radians(30)))
    bpy.ops.object.light_add(type="POINT", location=(0.5, 0.5, 1.0))
    bpy.context.object.data.energy = 200.0
    return scene


def hole_scene():
    """A displaced plane seen through a 0.1 m hole in a wall."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 0.0, 0.0))
    ground = subdivided(bpy.context.object, 3)
    mat = ru.add_noise_displacement(material("Displaced", (0.8, 0.6, 0.2)), 3.0, 0.3)
    ground.data.materials.append(mat)
    # The wall: a 2 x 2 m plane at height 2 with a square hole, as four quads.
    h = 0.05
    verts = [(-1, -1), (1, -1), (1, 1), (-1, 1), (-h, -h), (h, -h), (h, h), (-h, h)]
    faces = [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    mesh = bpy.data.meshes.new("Wall")
    mesh.from_pydata([(x, y, 2.0) for x, y in verts], [], faces)
    wall = bpy.data.objects.new("Wall", mesh)
    scene.collection.objects.link(wall)
    wall.data.materials.append(material("Wall", (0.2, 0.3, 0.8)))
    ru.add_camera(scene, (0.0, 0.0, 6.0), (0.0, 0.0, 0.0), lens=60.0)
    ru.add_sun(scene, (math.radians(20), 0.0, 0.0))
    scene.micropoly.use_shadows = False  # lit through the hole, so that its colour shows
    return scene


def transparent_scene():
    """A half-transparent plane in front of an opaque one in front of a third."""
    scene = ru.reset_scene()
    for name, z, color, alpha in (("Back", -1.0, (0.9, 0.1, 0.1), 1.0), ("Middle", 0.0, (0.1, 0.9, 0.1), 1.0),
                                  ("Front", 1.0, (0.1, 0.1, 0.9), 0.5)):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=1.5, location=(0.0, 0.0, z))
        obj = subdivided(bpy.context.object, 1)
        obj.name = name
        obj.data.materials.append(material(name, color, alpha))
    ru.add_camera(scene, (0.0, 0.0, 8.0), (0.0, 0.0, 0.0))
    ru.add_sun(scene, (math.radians(10), 0.0, 0.0))
    return scene


def f12(scene, culling):
    scene.micropoly.use_occlusion_culling = culling
    return ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]


def native_stats(scene):
    """The renderer's statistics for the scene as F12 exports it."""
    from micropoly import _native, export, preferences
    depsgraph = bpy.context.evaluated_depsgraph_get()
    exported = export.export_scene(depsgraph)
    renderer = _native.Renderer(preferences.device_selector(bpy.context))
    return renderer.render(exported.scene)["stats"]


def compare(name, scene):
    off, on = f12(scene, False), f12(scene, True)
    psnr = ru.psnr(on[..., :3], off[..., :3], peak=1.0)
    check(f"{name}: culling on and off give the same image", psnr >= 60.0, f"PSNR {psnr:.1f} dB")
    check(f"{name}: the same alpha", np.array_equal(on[..., 3], off[..., 3]))
    return on


def main():
    ru.enable_addon()
    scene = shells_scene(6)
    compare("six nested shells", scene)
    scene.render.resolution_x, scene.render.resolution_y = W, H
    scene.micropoly.use_occlusion_culling = True
    on = native_stats(scene)
    scene.micropoly.use_occlusion_culling = False
    off = native_stats(scene)
    check("six nested shells: hidden sub-patches are culled", on["subpatches_occluded"] > 0,
          f"{on['subpatches_occluded']} culled")
    check("six nested shells: culling dices under half the micropolygons", on["micropolygons"] * 2 < off["micropolygons"],
          f"{on['micropolygons']:,} against {off['micropolygons']:,}; depth complexity {on['depth_complexity']:.2f} "
          f"against {off['depth_complexity']:.2f}")

    scene = hole_scene()
    on = compare("displaced plane through a hole", scene)
    centre = on[H // 2, W // 2]
    check("the hole shows the displaced plane", centre[0] > centre[2], f"centre {centre[:3]}")

    scene = transparent_scene()
    on = compare("half-transparent sphere in front", scene)
    centre = on[H // 2, W // 2]
    check("the opaque sphere shows through the transparent one", centre[1] > 0.1 and centre[1] > centre[0],
          f"centre {centre[:3]}")
    return 0 if all(RESULTS) else 1


ru.run_test(main)
