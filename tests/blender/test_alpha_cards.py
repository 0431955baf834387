"""Alpha-cut cards against Cycles: a 2 m plane whose Principled Alpha is
Voronoi Distance > 0.35 (scale 4, Generated coordinates), black world.
Glowing (Emission, no base colour or specular, so only its coverage
differs between views), lying flat and seen from above, it sets the figure;
turned in two orientations and seen along its normal and 30, 60, 75 and 80
degrees from it, each view must come within 1 dB of that figure
(whole-frame RGBA, normalised to the 99th percentile), with no transparent
pixel inside what Cycles shows opaque (a speck). Lit by a sun over a floor,
the card and its shadow, holes included, must agree with Cycles' direct
light.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python tests/blender/test_alpha_cards.py

MICROPOLY_TEST_OUTPUT=folder saves Cycles | Micropoly | difference x4 there.
"""
import math
import os
import sys

import bpy
import numpy as np
from mathutils import Euler, Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_utils as ru  # noqa: E402

OUTPUT = os.environ.get("MICROPOLY_TEST_OUTPUT")
W = H = 320
ORIENTATIONS = [(1.3, 0.0, 0.3), (0.4, 0.9, -0.7)]
VIEWS = [0.0, 30.0, 60.0, 75.0, 80.0]


def card_material(glowing):
    m = bpy.data.materials.new("card")
    m.use_nodes = True
    nt = m.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    colour = (0.8, 0.45, 0.15, 1.0)
    if glowing:
        bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        bsdf.inputs["Specular IOR Level" if "Specular IOR Level" in bsdf.inputs else "Specular"].default_value = 0.0
        bsdf.inputs["Emission Color" if "Emission Color" in bsdf.inputs else "Emission"].default_value = colour
        if "Emission Strength" in bsdf.inputs:
            bsdf.inputs["Emission Strength"].default_value = 1.0
    else:
        bsdf.inputs["Base Color"].default_value = colour
    voronoi = nt.nodes.new("ShaderNodeTexVoronoi")
    voronoi.inputs["Scale"].default_value = 4.0
    cut = nt.nodes.new("ShaderNodeMath")
    cut.operation = "GREATER_THAN"
    cut.inputs[1].default_value = 0.35
    nt.links.new(voronoi.outputs["Distance"], cut.inputs[0])
    nt.links.new(cut.outputs[0], bsdf.inputs["Alpha"])
    if hasattr(m, "blend_method"):
        m.blend_method = "CLIP"
    return m


def card_scene(rotation, view_degrees, floor=False):
    """The card turned by `rotation`, the camera on its front side along its
    normal, tilted `view_degrees` about the card's x axis; glowing, or lit by
    a sun over a floor."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=2.0, rotation=rotation)
    bpy.context.object.data.materials.append(card_material(glowing=not floor))
    turn = Euler(rotation).to_matrix()
    normal, x = turn @ Vector((0.0, 0.0, 1.0)), turn @ Vector((1.0, 0.0, 0.0))
    eye = (Matrix.Rotation(math.radians(view_degrees), 3, x) @ normal).normalized() * 4.5
    ru.add_camera(scene, tuple(eye), (0.0, 0.0, 0.0), lens=50.0)
    if floor:
        sun = ru.add_sun(scene, (math.radians(25.0), math.radians(10.0), 0.0), energy=3.0)
        sun.data.angle = math.radians(1.0)
        ru.set_cast_shadow(sun.data, True)
        bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0.0, 0.0, -1.2))
        bpy.context.object.data.materials.append(ru.diffuse_material("floor", (0.6, 0.6, 0.6)))
    return scene


def render_pair(rotation, view, floor=False):
    scene = card_scene(rotation, view, floor)
    ru.setup_cycles(scene, samples=128, shadows=floor)
    cycles = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    micro = ru.render_passes(card_scene(rotation, view, floor), "MICROPOLY", W, H, samples=16)["rgba"]
    return cycles, micro


def frame_db(cycles, micro):
    peak = max(float(np.percentile(cycles[..., :3], 99)), 1e-6)
    return ru.psnr(micro, cycles, peak=peak)


def specks(cycles, micro):
    """Pixels Micropoly leaves mostly transparent where Cycles' whole 5 x 5
    neighbourhood is opaque."""
    opaque = cycles[..., 3] > 0.999
    inside = opaque.copy()
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            inside &= np.roll(np.roll(opaque, dy, axis=0), dx, axis=1)
    inside[:2, :] = inside[-2:, :] = False
    inside[:, :2] = inside[:, -2:] = False
    return int((inside & (micro[..., 3] < 0.5)).sum())


def main():
    ru.enable_addon()
    failures = []
    cycles, micro = render_pair((0.0, 0.0, 0.0), 0.0)
    ru.save_side_by_side(OUTPUT, "card_flat", cycles, micro)
    flat = frame_db(cycles, micro)
    print(f"flat card seen from above: {flat:.2f} dB, {specks(cycles, micro)} specks")
    for rotation in ORIENTATIONS:
        for view in VIEWS:
            cycles, micro = render_pair(rotation, view)
            db, n = frame_db(cycles, micro), specks(cycles, micro)
            name = f"card_{rotation[0]:g}_{rotation[1]:g}_{rotation[2]:g}_{view:g}"
            ru.save_side_by_side(OUTPUT, name, cycles, micro)
            ok = db >= flat - 1.0 and n == 0
            print(f"{'ok  ' if ok else 'FAIL'} turned {rotation}, {view:g} degrees from the normal: {db:.2f} dB "
                  f"(flat {flat:.2f}), {n} specks")
            if not ok:
                failures.append(f"{name}: {db:.2f} dB against the flat {flat:.2f}, {n} specks")
    # The card's shadow on a floor: its holes let the sun through as in Cycles.
    cycles, micro = render_pair(ORIENTATIONS[0], 30.0, floor=True)
    ru.save_side_by_side(OUTPUT, "card_shadow", cycles, micro)
    floor = (cycles[..., 3] > 0.999) & (micro[..., 3] > 0.999)
    shadow_db = ru.psnr(micro[floor][:, :3], cycles[floor][:, :3], peak=float(np.percentile(cycles[floor][:, :3], 99)))
    print(f"{'ok  ' if shadow_db >= 25.0 else 'FAIL'} the card over a floor, its shadow included: {shadow_db:.2f} dB")
    if shadow_db < 25.0:
        failures.append(f"card over a floor: {shadow_db:.2f} dB < 25")
    return ru.verdict(failures, "alpha-cut cards agree with Cycles in every orientation")


ru.run_test(main)
