"""Shadows of thin things against Cycles' direct light: five leaves (flattened
ellipsoids 12 cm long and 4 mm thick) stacked 3 cm apart over a 30 m
ground, under a sun 11.4 degrees wide, so the sun's maps span the ground
and their coarse levels, which soft shadows search for occluders, have
texels as large as a leaf. Each leaf must shade the one below as Cycles
does (PSNR over covered pixels, normalised to the 99th percentile).

The figure reached is 27.0 dB (22.8 dB when micropolygons smaller than a
coarse level's texel fell between its samples); the aim is 30 dB
(docs/pipeline.md, Shadows' limits).

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python tests/blender/test_thin_shadows.py

MICROPOLY_TEST_OUTPUT=folder saves Cycles | Micropoly | difference x4 there.
"""
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_utils as ru  # noqa: E402

OUTPUT = os.environ.get("MICROPOLY_TEST_OUTPUT")
W, H = 200, 150
MIN_DB = 25.0


def leaves(ground=30.0, sun_degrees=11.4):
    scene = ru.reset_scene()
    for k in range(5):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=32, ring_count=16,
                                             location=(0.035 * k - 0.07, 0.0, 0.03 * k))
        leaf = bpy.context.object
        leaf.scale = (0.06, 0.035, 0.002)
        leaf.rotation_euler = (0.1 * (k % 2), 0.05, 0.5 * k)
        bpy.ops.object.shade_smooth()
        leaf.data.materials.append(ru.diffuse_material(f"leaf{k}", (0.2, 0.6, 0.15)))
    bpy.ops.mesh.primitive_plane_add(size=ground, location=(0.0, 0.0, -0.6))
    bpy.context.object.data.materials.append(ru.diffuse_material("ground", (0.5, 0.45, 0.35)))
    sun = ru.add_sun(scene, (math.radians(10.0), math.radians(-25.0), 0.0), energy=3.0)
    sun.data.angle = math.radians(sun_degrees)
    ru.set_cast_shadow(sun.data, True)
    ru.add_camera(scene, (0.03, -0.32, 0.3), (0.0, 0.0, 0.05), lens=40.0)
    return scene


def main():
    ru.enable_addon()
    scene = leaves()
    ru.setup_cycles(scene, samples=256, shadows=True)
    cycles = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    micro = ru.render_passes(leaves(), "MICROPOLY", W, H, samples=16)["rgba"]
    ru.save_side_by_side(OUTPUT, "thin_leaves", cycles, micro)
    both = (cycles[..., 3] > 0.999) & (micro[..., 3] > 0.999)
    ref, got = cycles[both][:, :3], micro[both][:, :3]
    db = ru.psnr(got, ref, peak=float(np.percentile(ref, 99)))
    print(f"thin leaves under an 11.4 degree sun over a 30 m ground: {db:.2f} dB over {int(both.sum())} pixels")
    failures = [] if db >= MIN_DB else [f"thin leaves {db:.2f} dB < {MIN_DB}"]
    return ru.verdict(failures, "thin leaves shade one another")


ru.run_test(main)
