"""The world-lighting benchmark. Run with Blender (or a Python with bpy):

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/world_bench.py -- [--rib-only] [--quick]

Scene: Suzanne and a torus with Subdivision Surface on a floor (the scene
of tests/blender/test_world.py), Principled roughness 0.3, 1920x1080 and
16 samples, in three lightings:
  world_hdri    lit only by Blender's forest.exr studio light (its world
                program baked, 16 shadowed directions: the default);
  world_lights4 a black world and four lights casting soft shadows (sun,
                point, spot, area);
  world_none    a black world and no lights (what both add to).

Default: F12 of world_hdri by Micropoly on its default device and by Cycles
(direct light only, as in the tests, and its default light paths), 16
samples each, one run each, wall time printed.
--rib-only: writes the three scenes as RIB (bench/out/world_*.rib) for the
CLI's per-stage timings (bench/bench.py world)."""

import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
W, H = (480, 270) if "--quick" in args else (1920, 1080)
SAMPLES = 16


def hdri_world(scene):
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    env = nodes.new("ShaderNodeTexEnvironment")
    folder = bpy.utils.system_resource("DATAFILES", path="studiolights/world")
    env.image = bpy.data.images.load(os.path.join(folder, "forest.exr"), check_existing=True)
    links.new(env.outputs["Color"], nodes["Background"].inputs["Color"])


def build_scene(lighting):
    scene = ru.reset_scene()
    ru.add_suzanne_torus_floor(lambda name, color: ru.principled_material(name, color, 0.3))
    if lighting == "hdri":
        hdri_world(scene)
    else:
        scene.world.color = (0.0, 0.0, 0.0)
    if lighting == "lights4":
        ru.add_sun(scene, (0.6, 0.2, 0.8), energy=3.0)
        ru.add_aimed_light(scene, "POINT", (2.5, -2.0, 3.0), (0.0, 0.0, 0.5), 800.0, shadow_soft_size=0.25)
        ru.add_aimed_light(scene, "SPOT", (-3.0, -2.0, 3.5), (0.0, 0.0, 0.5), 1000.0, shadow_soft_size=0.25)
        ru.add_aimed_light(scene, "AREA", (0.0, 3.0, 3.0), (0.0, 0.0, 0.5), 500.0, size=0.25)
        for obj in scene.objects:
            if obj.type == "LIGHT":
                ru.set_cast_shadow(obj.data, True)
    ru.add_camera(scene, (0.0, -6.0, 3.2), (0.2, 0.0, 0.4), lens=40.0)
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = W, H, 100
    r.film_transparent = False
    scene.micropoly.samples = SAMPLES
    return scene


def export_ribs():
    ru.enable_addon()
    for lighting in ("hdri", "lights4", "none"):
        ru.write_bench_rib(build_scene(lighting), f"world_{lighting}")


def side_by_side():
    ru.enable_addon()
    print(f"world_hdri, {W}x{H}, {SAMPLES} samples, F12 wall time, one run each")
    scene = build_scene("hdri")
    scene.render.engine = "MICROPOLY"
    print(f"Micropoly: {ru.f12_seconds(scene):.2f} s")
    scene = build_scene("hdri")
    ru.setup_cycles(scene, samples=SAMPLES)
    print(f"Cycles, direct light (max bounces 0), adaptive subdivision 1 px: {ru.f12_seconds(scene):.2f} s")
    scene = build_scene("hdri")
    ru.setup_cycles(scene, samples=SAMPLES)
    c = scene.cycles
    c.max_bounces, c.diffuse_bounces, c.glossy_bounces, c.transmission_bounces = 12, 4, 4, 12
    print(f"Cycles, default light paths, adaptive subdivision 1 px: {ru.f12_seconds(scene):.2f} s")


if "--rib-only" in args:
    export_ribs()
else:
    side_by_side()
