"""Micropoly against Cycles on scenes built here (run by blender -b, or by a
Python with the bpy module). Cycles renders with adaptive subdivision at a
dicing rate of 1 px for subdivided objects, no bounces and light shadows off,
so its image is direct lighting only, the quantity Micropoly computes.

Checks: silhouettes (alpha > 0.5) intersection-over-union >= 0.98;
Combined PSNR >= 30 dB over pixels both cover fully; Depth within 1% and
Normal within 0.05 (median over covered pixels). Exits non-zero on failure."""

import math
import os
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import render_utils as ru  # noqa: E402

W, H = 160, 120
CYCLES_SAMPLES = 128


def suzanne(scene, subdivided=True, location=(0.0, 0.0, 0.0), smooth=False):
    bpy.ops.mesh.primitive_monkey_add(size=2.0, location=location)
    obj = bpy.context.object
    if subdivided:
        obj.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    if subdivided or smooth:
        bpy.ops.object.shade_smooth()
    obj.data.materials.append(ru.diffuse_material("grey", (0.8, 0.8, 0.8)))
    return obj


def floor(scene, size=8.0, z=-1.0):
    bpy.ops.mesh.primitive_plane_add(size=size, location=(0.0, 0.0, z))
    bpy.context.object.data.materials.append(ru.diffuse_material("floor", (0.5, 0.6, 0.4)))


def light(scene, kind, location=(2.0, -4.0, 3.0), target=(0.0, 0.0, 0.0), energy=500.0, **props):
    return ru.add_aimed_light(scene, kind, location, target, energy, **props)


def compare(name, scene, checks, min_psnr=30.0):
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES)
    cycles = ru.render_passes(scene, "CYCLES", W, H, cycles_data=True)
    micro = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)
    a, b = cycles["rgba"][..., 3], micro["rgba"][..., 3]
    both = (a > 0.999) & (b > 0.999)
    metrics = {"iou": ru.iou(a, b), "covered": int(both.sum())}
    if "psnr" in checks:
        ref, got = cycles["rgba"][both][:, :3], micro["rgba"][both][:, :3]
        metrics["psnr"] = ru.psnr(ref, got, peak=float(ref.max()))
        metrics["mean_ratio"] = float(got.mean() / max(ref.mean(), 1e-9))
    if micro["depth"] is None:
        checks = checks - {"passes"}  # this Blender's passes are read back in another way
    if "passes" in checks:
        metrics["depth_rel"] = float(np.median(np.abs(micro["depth"][both] / cycles["depth"][both] - 1.0)))
        metrics["normal_err"] = float(np.median(np.linalg.norm(micro["normal"][both] - cycles["normal"][both], axis=-1)))
    failures = []
    if metrics["iou"] < 0.98:
        failures.append(f"silhouette IoU {metrics['iou']:.4f} < 0.98")
    if metrics["covered"] < 500:
        failures.append(f"only {metrics['covered']} covered pixels: the scene is not in view")
    if "psnr" in checks and metrics["psnr"] < min_psnr:
        failures.append(f"PSNR {metrics['psnr']:.2f} dB < {min_psnr:g}")
    if "passes" in checks:
        if metrics["depth_rel"] > 0.01:
            failures.append(f"Depth differs by {metrics['depth_rel']:.4f} (median relative)")
        if metrics["normal_err"] > 0.05:
            failures.append(f"Normal differs by {metrics['normal_err']:.4f} (median)")
    shown = ", ".join(f"{k} {v:.4f}" if isinstance(v, float) else f"{k} {v}" for k, v in metrics.items())
    print(f"{'FAIL' if failures else 'ok  '} {name}: {shown}" + ("".join(f"\n     {f}" for f in failures)))
    return not failures


def case_subdivided_suzanne():
    scene = ru.reset_scene()
    suzanne(scene)
    light(scene, "POINT")
    ru.add_camera(scene, (0.5, -6.0, 1.0), (0, 0, 0))
    return compare("subdivided Suzanne, point light", scene, {"psnr", "passes"})


def case_polygon_mesh():
    scene = ru.reset_scene()
    suzanne(scene, subdivided=False)
    floor(scene)
    light(scene, "SUN", energy=3.0)
    ru.add_camera(scene, (3.0, -5.0, 2.5), (0, 0, -0.3))
    return compare("polygon Suzanne and floor, sun light", scene, {"psnr", "passes"})


def case_smooth_polygon_mesh():
    # Shade Smooth without subdivision: Blender's corner normals, interpolated
    # across each face, shade it and fill the Normal pass, as in Cycles.
    scene = ru.reset_scene()
    suzanne(scene, subdivided=False, smooth=True)
    light(scene, "POINT", energy=800.0)
    ru.add_camera(scene, (1.5, -5.5, 1.5), (0, 0, 0))
    return compare("smooth-shaded polygon Suzanne, point light", scene, {"psnr", "passes"})


def case_orthographic():
    scene = ru.reset_scene()
    suzanne(scene)
    light(scene, "SPOT", location=(1.0, -4.0, 3.0), energy=800.0, spot_size=math.radians(50), spot_blend=0.3)
    ru.add_camera(scene, (2.0, -6.0, 2.0), (0, 0, 0), ortho_scale=4.0)
    return compare("orthographic camera, spot light", scene, {"psnr", "passes"})


def case_shifted_camera():
    scene = ru.reset_scene()
    suzanne(scene)
    floor(scene)
    light(scene, "AREA", location=(0.0, -3.0, 3.0), energy=300.0, shape="RECTANGLE", size=1.5, size_y=0.7)
    ru.add_camera(scene, (0.5, -6.0, 1.5), (0, 0, 0), shift=(0.15, -0.1))
    return compare("shifted camera, rectangular area light", scene, {"psnr", "passes"})


def case_disk_light():
    scene = ru.reset_scene()
    suzanne(scene)
    light(scene, "AREA", location=(-2.0, -3.0, 2.0), energy=400.0, shape="DISK", size=1.2)
    ru.add_camera(scene, (0.5, -6.0, 1.0), (0, 0, 0))
    return compare("disk area light", scene, {"psnr"})


def case_instances():
    """A collection instanced three times and a linked duplicate (one mesh,
    several objects): every instance must render, where Cycles shows it."""
    scene = ru.reset_scene()
    collection = bpy.data.collections.new("Source")
    scene.collection.children.link(collection)
    obj = suzanne(scene)
    for c in list(obj.users_collection):
        c.objects.unlink(obj)
    collection.objects.link(obj)
    collection.hide_render = False
    for i, x in enumerate((-3.0, 0.0, 3.0)):
        empty = bpy.data.objects.new(f"instance{i}", None)
        empty.instance_type = "COLLECTION"
        empty.instance_collection = collection
        empty.location = (x, 2.0 * i, 0.0)
        scene.collection.objects.link(empty)
    duplicate = bpy.data.objects.new("duplicate", obj.data)
    duplicate.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    duplicate.location = (0.0, -2.0, 1.8)
    scene.collection.objects.link(duplicate)
    # The source collection itself stays out of the view layer, as usual for instancing.
    scene.view_layers[0].layer_collection.children["Source"].exclude = True
    light(scene, "SUN", energy=3.0)
    ru.add_camera(scene, (0.0, -14.0, 4.0), (0.0, 1.5, 0.0))
    return compare("collection instances and linked duplicates, sun light", scene, set())


def case_missing_materials():
    """Materials Cycles makes itself: an object without a material (Cycles'
    default surface), one whose material has its nodes off (a Diffuse BSDF
    of the viewport colour; the viewport's metallic and roughness, set here
    to stand out, are not rendered), and a face whose slot is empty."""
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -7.0, 3.0), (0.0, 0.0, 0.0))
    ru.add_sun(scene, (0.7, 0.0, 0.6), energy=3.0)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(-1.2, 0.0, 0.0))
    bpy.ops.object.shade_smooth()
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(1.2, 0.0, 0.0))
    bpy.ops.object.shade_smooth()
    old = bpy.data.materials.new("no nodes")
    old.use_nodes = False
    old.diffuse_color = (0.8, 0.35, 0.1, 1.0)
    old.metallic, old.roughness = 0.7, 0.2
    bpy.context.object.data.materials.append(old)
    bpy.ops.mesh.primitive_cube_add(size=1.2, location=(0.0, 1.8, -0.2))
    cube = bpy.context.object
    cube.data.materials.append(ru.diffuse_material("blue", (0.1, 0.2, 0.8)))
    cube.data.materials.append(None)
    for i, polygon in enumerate(cube.data.polygons):
        polygon.material_index = i % 2
    return compare("no material, nodes off, an empty slot; sun light", scene, {"psnr"}, min_psnr=38.0)


CASES = [case_missing_materials, case_instances, case_subdivided_suzanne, case_polygon_mesh, case_smooth_polygon_mesh, case_orthographic, case_shifted_camera, case_disk_light]


def main():
    print(f"Blender {bpy.app.version_string}")
    ok = True
    for case in CASES:
        try:
            ok = case() and ok
        except Exception:
            traceback.print_exc()
            ok = False
    print("all cases agree with Cycles" if ok else "some cases disagree with Cycles")
    return 0 if ok else 1


if __name__ == "__main__":
    ru.run_test(main)
