"""Alpha-cut cards against Cycles: a 2 m plane whose Principled Alpha is
Voronoi Distance > 0.35 (scale 4, Generated coordinates), black world.
Glowing (Emission, no base colour or specular, so only its coverage
differs between views), lying flat and seen from above, then turned in two
orientations and seen along its normal and 30, 60, 75 and 80 degrees from
it, and the same cut made by a Mix Shader of a Transparent BSDF and the
Principled BSDF (as older leaf materials are made), turned and seen along
its normal: every view must reach 40 dB (whole-frame RGBA, normalised to the 99th
percentile) with no transparent pixel inside what Cycles shows opaque (a
speck), and the holes Micropoly cuts must not depend on the orientation:
seen along its normal, each turned card's holes cover the flat card's
areas within 1%. (A figure relative to the flat view's would measure
Cycles at this agreement: its own holes change area by up to 0.5% when the
card turns, where Micropoly's stay within sampling noise.) Lit by a sun
over a floor, the card and its shadow, holes included, must agree with
Cycles' direct light.

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


def card_material(glowing, mixed=False):
    """Principled Alpha fed by the cut, or (`mixed`) the cut mixing a
    Transparent BSDF with the Principled BSDF, as older materials do."""
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
    if mixed:
        output = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(cut.outputs[0], mix.inputs[0])
        nt.links.new(nt.nodes.new("ShaderNodeBsdfTransparent").outputs[0], mix.inputs[1])
        nt.links.new(bsdf.outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], output.inputs["Surface"])
    else:
        nt.links.new(cut.outputs[0], bsdf.inputs["Alpha"])
    if hasattr(m, "blend_method"):
        m.blend_method = "CLIP"
    return m


def card_scene(rotation, view_degrees, floor=False, mixed=False):
    """The card turned by `rotation`, the camera on its front side along its
    normal, tilted `view_degrees` about the card's x axis; glowing, or lit by
    a sun over a floor."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=2.0, rotation=rotation)
    bpy.context.object.data.materials.append(card_material(glowing=not floor, mixed=mixed))
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


def render_pair(rotation, view, floor=False, mixed=False):
    scene = card_scene(rotation, view, floor, mixed)
    ru.setup_cycles(scene, samples=128, shadows=floor)
    cycles = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    micro = ru.render_passes(card_scene(rotation, view, floor, mixed), "MICROPOLY", W, H, samples=16)["rgba"]
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


def hole_areas(alpha, reach=2):
    """The areas in pixels of the card's holes, smallest first: each
    transparent region (alpha < 0.5) that touches no border of the image,
    measured as its transparency (1 - alpha) summed over it and the pixels
    within `reach` of it, so that its edge pixels count by their coverage."""
    clear = alpha < 0.5
    h, w = clear.shape
    seen = np.zeros_like(clear)
    areas = []
    for y0, x0 in zip(*np.nonzero(clear)):
        if seen[y0, x0]:
            continue
        seen[y0, x0] = True
        stack, pixels, border = [(y0, x0)], [], False
        while stack:
            y, x = stack.pop()
            pixels.append((y, x))
            border |= y in (0, h - 1) or x in (0, w - 1)
            for y2, x2 in ((y + 1, x), (y - 1, x), (y, x + 1), (y, x - 1)):
                if 0 <= y2 < h and 0 <= x2 < w and clear[y2, x2] and not seen[y2, x2]:
                    seen[y2, x2] = True
                    stack.append((y2, x2))
        if border:
            continue
        region = np.zeros_like(clear)
        ys, xs = np.array(pixels).T
        for dy in range(-reach, reach + 1):
            for dx in range(-reach, reach + 1):
                region[np.clip(ys + dy, 0, h - 1), np.clip(xs + dx, 0, w - 1)] = True
        areas.append(round(float((1.0 - alpha[region]).sum()), 1))
    return sorted(areas)


def main():
    ru.enable_addon()
    failures = []
    views = [((0.0, 0.0, 0.0), 0.0, False)] + [(rotation, view, False) for rotation in ORIENTATIONS for view in VIEWS]
    # The same cut made by mixing in a Transparent BSDF, turned and seen along its normal.
    views.append((ORIENTATIONS[0], 0.0, True))
    flat_holes = None
    for rotation, view, mixed in views:
        cycles, micro = render_pair(rotation, view, mixed=mixed)
        db, n = frame_db(cycles, micro), specks(cycles, micro)
        name = f"card_{rotation[0]:g}_{rotation[1]:g}_{rotation[2]:g}_{view:g}" + ("_mixed" if mixed else "")
        ru.save_side_by_side(OUTPUT, name, cycles, micro)
        ok, holes = db >= 40.0 and n == 0, ""
        if view == 0.0:
            areas = hole_areas(micro[..., 3])
            if flat_holes is None:
                flat_holes = areas
            same = len(areas) == len(flat_holes) and all(abs(a - b) <= 0.01 * b for a, b in zip(areas, flat_holes))
            ok = ok and same
            holes = f", hole areas {areas} (flat {flat_holes})"
        print(f"{'ok  ' if ok else 'FAIL'} turned {rotation}, {view:g} degrees from the normal"
              f"{', a Transparent BSDF mixed in' if mixed else ''}: {db:.2f} dB, "
              f"{n} specks{holes}")
        if not ok:
            failures.append(f"{name}: {db:.2f} dB (needs 40), {n} specks{holes}")
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
