"""Hair benchmark: a head (a sphere) with particle hair, N strands
interpolated from N / 10 guides (9 points each, about a pixel wide at
1920x1080), Principled Hair by melanin under a sun with shadows, F12 in
Micropoly (16 spp) and in Cycles (16 spp, direct light) in one run; writes
the scene as bench/out/hair_<N>.rib for micropoly-render (the GPU figures).

  MICROPOLY_ADDON_DIR=build/addons MICROPOLY_CLI=build/micropoly-render BLENDER_USER_SCRIPTS=build \\
      blender -b --factory-startup --python bench/hair_bench.py -- [--strands N] [--rounds R]

Prints each round's F12 seconds and the medians."""

import math
import os
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def arg(name, default):
    return args[args.index(name) + 1] if name in args else default


STRANDS = int(arg("--strands", "20000"))
ROUNDS = int(arg("--rounds", "1"))


def hair_scene():
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -2.2, 0.6), (0.0, 0.0, 0.3))
    ru.add_sun(scene, (math.radians(40), 0.0, math.radians(30)), energy=3.0)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, segments=48, ring_count=24, location=(0.0, 0.0, 0.3))
    head = bpy.context.active_object
    head.data.materials.append(ru.diffuse_material("Skin", (0.8, 0.6, 0.5)))
    m, out = ru.empty_material("Hair")
    bsdf = m.node_tree.nodes.new("ShaderNodeBsdfHairPrincipled")
    bsdf.parametrization = "MELANIN"
    if hasattr(bsdf, "model"):
        bsdf.model = "CHIANG"
    bsdf.inputs["Melanin"].default_value = 0.4
    m.node_tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    head.data.materials.append(m)
    settings = bpy.data.particles.new("Hair")
    settings.type = "HAIR"
    settings.count = max(STRANDS // 10, 1)
    settings.hair_length = 0.3
    settings.child_type = "INTERPOLATED"
    settings.rendered_child_count = 10
    settings.render_step = settings.display_step = 3
    settings.root_radius, settings.tip_radius, settings.radius_scale = 1.0, 0.2, 0.004
    settings.material = 2
    head.modifiers.new("Hair", "PARTICLE_SYSTEM")
    head.particle_systems[0].settings = settings
    scene.render.resolution_x, scene.render.resolution_y = 1920, 1080
    scene.render.resolution_percentage = 100
    scene.micropoly.samples = 16
    ru.setup_cycles(scene, samples=16, shadows=True)
    return scene


def main():
    scene = hair_scene()
    os.makedirs(os.path.join(HERE, "out"), exist_ok=True)
    from micropoly import operators

    operators.export_rib(bpy.context.evaluated_depsgraph_get(), os.path.join(HERE, "out", f"hair_{STRANDS}.rib"))
    times = {"MICROPOLY": [], "CYCLES": []}
    for _ in range(ROUNDS):
        for engine in times:
            scene.render.engine = engine
            times[engine].append(ru.f12_seconds(scene))
            print(f"{engine} {STRANDS} strands: F12 {times[engine][-1]:.2f} s", flush=True)
    mp, cy = statistics.median(times["MICROPOLY"]), statistics.median(times["CYCLES"])
    print(f"RESULT {STRANDS} strands at 1920x1080, 16 spp: Micropoly F12 {mp:.2f} s, Cycles {cy:.2f} s "
          f"({mp / cy:.2f} of Cycles' time)", flush=True)


ru.enable_addon()
ru.run_test(lambda: main() or 0)
