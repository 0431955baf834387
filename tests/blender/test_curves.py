"""Hair curves in Blender (run by blender -b, or a Python with the bpy
module), rendered in each of Cycles' curve shapes (round tubes for 3D
Curves, ribbons facing each view for Rounded Ribbons) and compared with
Cycles' direct light in the same shape: one thick strand under a sun
(PSNR >= 35 dB over pixels both cover, IoU >= 0.98); a combed field of 500
tapering strands 1 to 3 pixels wide, whose silhouettes match (alpha IoU
>= 0.95); and the same field 0.1 pixel wide, whose coverage (the alpha
summed) is within 3 % of Cycles'.
The field's shading is reported, not asserted: strands a few pixels wide
and thinner shade darker than Cycles' (docs/blender.md, "Curves").
Last, the field instanced on the vertices of a grid (fur on scattered
patches): one prototype and an instance per vertex, drawing the
silhouettes Cycles' 3D Curves draws (IoU >= 0.98) and the image the same
copies made real objects draw (>= 50 dB).
Exits non-zero on failure."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import render_utils as ru  # noqa: E402

RESULTS = []
W, H = 320, 240
CYCLES_SAMPLES = 128
CURVES, KEYS = 500, 8  # what curves_random_add makes, in every version tested


def check(name, condition, detail=""):
    RESULTS.append(bool(condition))
    print(f"{'ok  ' if condition else 'FAIL'} {name}" + (f": {detail}" if detail else ""))


def hair_scene(root_radius, tip_radius):
    """A 25 x 20 grid of strands rising 0.8 from the floor, bending along x,
    tapering from root_radius to tip_radius. Returns the scene and the hair."""
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -3.2, 1.4), (0.0, 0.0, 0.35))
    ru.add_sun(scene, (math.radians(40), 0.0, math.radians(30)))
    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 0.0, 0.0))
    bpy.context.object.name = "Floor"
    bpy.context.object.data.materials.append(ru.diffuse_material("Floor", (0.6, 0.6, 0.6)))
    bpy.ops.object.curves_random_add()
    hair = bpy.context.active_object
    hair.name = "Hair"
    hair.location = (0.0, 0.0, 0.0)
    hair.data.materials.append(ru.diffuse_material("Hair", (0.7, 0.45, 0.2)))
    curves = hair.data
    assert (len(curves.curves), len(curves.points)) == (CURVES, CURVES * KEYS)
    gx, gy = np.meshgrid(np.linspace(-1.0, 1.0, 25), np.linspace(-0.8, 0.8, 20))
    t = np.linspace(0.0, 1.0, KEYS)
    pos = np.empty((CURVES, KEYS, 3), dtype=np.float32)
    pos[..., 0] = gx.reshape(-1, 1) + 0.25 * t ** 2
    pos[..., 1] = gy.reshape(-1, 1) + 0.05 * np.sin(7.0 * gx.reshape(-1, 1)) * t
    pos[..., 2] = 0.8 * t
    radii = np.broadcast_to(root_radius + (tip_radius - root_radius) * t, (CURVES, KEYS)).astype(np.float32)
    curves.attributes["position"].data.foreach_set("vector", pos.reshape(-1))
    curves.attributes["radius"].data.foreach_set("value", np.ascontiguousarray(radii).reshape(-1))
    curves.update_tag()
    return scene, hair


def set_shape(scene, shape):
    if hasattr(scene, "cycles_curves"):
        scene.cycles_curves.shape = shape


def compare(name, ref, got, min_psnr=None, min_iou=0.98):
    both = (ref[..., 3] > 0.999) & (got[..., 3] > 0.999)
    iou = ru.iou(ref[..., 3], got[..., 3])
    a, b = ref[both][:, :3], got[both][:, :3]
    p = ru.psnr(a, b, peak=float(a.max())) if both.sum() > 100 else 0.0
    ok = iou >= min_iou and both.sum() > 1000 and (min_psnr is None or p >= min_psnr)
    check(f"{name}", ok, f"{p:.1f} dB over {int(both.sum())} covered pixels, alpha IoU {iou:.4f}")


def main():
    from micropoly import export

    scene, hair = hair_scene(0.012, 0.004)
    exported = export.export_scene(bpy.context.evaluated_depsgraph_get())
    check("curves: one patch set", exported.scene.patch_set_count == 1, f"{exported.scene.patch_set_count} patch sets")
    # One strand 0.15 thick running through the frame (its ends, which
    # Cycles 3.4 and 4.x draw differently, out of sight), the rest far
    # aside, over no floor.
    curves = hair.data
    pos = np.zeros((CURVES, KEYS, 3), np.float32)
    pos[..., 2] = np.linspace(-1.5, 2.5, KEYS)
    pos[1:, :, 0] = 5.0
    radii = np.zeros((CURVES, KEYS), np.float32)
    radii[0] = 0.15
    curves.attributes["position"].data.foreach_set("vector", pos.reshape(-1))
    curves.attributes["radius"].data.foreach_set("value", radii.reshape(-1))
    curves.update_tag()
    bpy.data.objects["Floor"].hide_render = True
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    for shape, name in (("THICK", "3D Curves"), ("RIBBONS", "Rounded Ribbons")):
        set_shape(scene, shape)
        compare(f"a thick strand against Cycles' {name}", ru.render_passes(scene, "CYCLES", W, H)["rgba"],
                ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"], min_psnr=35.0)
    # The field over no floor: silhouettes against both shapes.
    scene, hair = hair_scene(0.012, 0.004)
    bpy.data.objects["Floor"].hide_render = True
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    for shape, name in (("THICK", "3D Curves"), ("RIBBONS", "Rounded Ribbons")):
        set_shape(scene, shape)
        compare(f"strands 1 to 3 pixels wide: silhouettes against Cycles' {name}",
                ru.render_passes(scene, "CYCLES", W, H)["rgba"],
                ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"], min_iou=0.95)
    # Strands 0.1 pixel wide (about 135 pixels a unit there), over no floor:
    # what each pixel holds of them is its alpha.
    scene, hair = hair_scene(0.00037, 0.00037)
    bpy.data.objects["Floor"].hide_render = True
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    for shape, name in (("THICK", "3D Curves"), ("RIBBONS", "Rounded Ribbons")):
        set_shape(scene, shape)
        got = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"][..., 3]
        ref = ru.render_passes(scene, "CYCLES", W, H)["rgba"][..., 3]
        check(f"0.1-pixel strands: coverage against Cycles' {name}", abs(got.sum() / ref.sum() - 1.0) <= 0.03,
              f"alpha summed {got.sum():.1f} against {ref.sum():.1f}")

    scene, hair = hair_scene(0.012, 0.004)
    bpy.data.objects["Floor"].hide_render = True
    points = scatter_curves(hair)
    exported = export.export_scene(bpy.context.evaluated_depsgraph_get())
    # (The viewport's depsgraph, exported here, keeps the original too; F12's hides it.)
    got = (exported.scene.prototype_count, exported.scene.instance_count)
    check("instanced curves: one prototype, an instance per vertex", got == (1, points) and points >= 16,
          f"{points} vertices, exported {got}")
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    set_shape(scene, "THICK")
    instanced = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
    compare("instanced curves: silhouettes against Cycles' 3D Curves", ru.render_passes(scene, "CYCLES", W, H)["rgba"],
            instanced)
    # The same copies made real objects, each exported on its own.
    bpy.ops.object.select_all(action="DESELECT")
    bpy.data.objects["Scatter"].select_set(True)
    bpy.context.view_layer.objects.active = bpy.data.objects["Scatter"]
    bpy.ops.object.duplicates_make_real()
    bpy.data.objects["Scatter"].instance_type = "NONE"
    hair.hide_render = True
    exported = export.export_scene(bpy.context.evaluated_depsgraph_get())
    check("the copies made real: a patch set each", exported.scene.patch_set_count >= points,
          f"{exported.scene.patch_set_count} patch sets")
    compare("instanced curves against the same copies made real", ru.render_passes(scene, "MICROPOLY", W, H,
                                                                                      samples=16)["rgba"],
            instanced, min_psnr=50.0, min_iou=0.999)
    return 0 if all(RESULTS) else 1


def scatter_curves(hair):
    """The hair, at 0.35 of its size, placed on each vertex of a grid
    (instancing by vertices: the hair itself is then not rendered). Returns
    how many."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=4, size=2.0, location=(0.0, 0.0, 0.0))
    grid = bpy.context.object
    grid.name = "Scatter"
    grid.instance_type = "VERTS"
    hair.scale = (0.35, 0.35, 0.35)
    hair.parent = grid
    return len(grid.data.vertices)


ru.run_test(main)
