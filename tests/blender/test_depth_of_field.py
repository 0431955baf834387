"""Depth of field against Cycles (direct light, no bounces, no denoising, the
camera's own Depth of Field settings):

  - three subdivided Suzannes before, at and behind the focus distance on
    a floor, lit by a sun, through a round aperture, a 6-blade aperture
    (turned 10 degrees) and a round one focused by a focus object: Combined
    PSNR over the whole frame (transparent film, so silhouettes count)
    >= 36 dB. Mutation checks: the same scene rendered by Micropoly with
    Depth of Field off, and with half the aperture, must miss it;
  - the blur extent: a card far behind the focus with a straight vertical
    edge; the width of its alpha ramp (5% to 95%, averaged over rows) is
    within 1 px of Cycles'.

MICROPOLY_TEST_OUTPUT=folder writes each case's images there (Cycles,
Micropoly and their difference x4, side by side).
Run: blender -b --factory-startup --python tests/blender/test_depth_of_field.py"""
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_utils as ru  # noqa: E402

W, H = 240, 180
THRESHOLD_DB = 36.0
MICROPOLY_SPP = 64
CYCLES_SAMPLES = 512
OUTPUT = os.environ.get("MICROPOLY_TEST_OUTPUT")


def suzanne(location, color, name):
    bpy.ops.mesh.primitive_monkey_add(size=0.9, location=location, rotation=(math.radians(10), 0.0, math.radians(-20)))
    obj = bpy.context.object
    obj.name = name
    obj.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    ru.shade_smooth(obj)
    obj.data.materials.append(ru.diffuse_material(name, color))
    return obj


def three_depths_scene(blades=0, rotation=0.0, focus_object=False):
    """Suzannes about 2, 3.2 and 5.5 m from the camera, focused on the middle
    one's origin, f/0.15 with a 50 mm lens (aperture radius 16.7 cm):
    circles of confusion about 21 px across in front and 14 px behind."""
    scene = ru.reset_scene()
    near = suzanne((-0.55, -2.7, 0.05), (0.8, 0.3, 0.2), "near")
    focus = suzanne((0.05, -1.4, 0.0), (0.3, 0.7, 0.3), "focus")
    suzanne((0.9, 0.9, 0.2), (0.3, 0.4, 0.8), "far")
    near.scale = (0.7, 0.7, 0.7)
    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0.0, 0.0, -0.6))
    bpy.context.object.data.materials.append(ru.diffuse_material("floor", (0.6, 0.6, 0.55)))
    cam = ru.add_camera(scene, (0.0, -4.6, 0.6), (0.05, -1.4, 0.0), lens=50.0)
    dof = cam.data.dof
    dof.use_dof = True
    dof.aperture_fstop = 0.15
    dof.aperture_blades = blades
    dof.aperture_rotation = rotation
    if focus_object:
        dof.focus_object = focus
        dof.focus_distance = 100.0  # must be ignored
    else:
        dof.focus_distance = (cam.location - focus.location).length
    ru.add_sun(scene, (math.radians(40), 0.0, math.radians(-30)), energy=3.0)
    return scene


def edge_scene():
    """A card 9 m away, focus at 2 m, its left edge vertical in the frame."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=4.0, location=(2.0, 9.0, 0.0), rotation=(math.radians(90), 0.0, 0.0))
    bpy.context.object.data.materials.append(ru.diffuse_material("card", (0.8, 0.8, 0.8)))
    cam = ru.add_camera(scene, (0.0, 0.0, 0.0), (0.0, 9.0, 0.0), lens=50.0)
    cam.data.dof.use_dof = True
    cam.data.dof.aperture_fstop = 0.5
    cam.data.dof.focus_distance = 2.0
    ru.add_sun(scene, (math.radians(90), 0.0, 0.0), energy=3.0)
    return scene


def render_both(scene, name):
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES)
    cycles = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    micro = ru.render_passes(scene, "MICROPOLY", W, H, samples=MICROPOLY_SPP)["rgba"]
    ru.save_side_by_side(OUTPUT, name, cycles, micro)
    return cycles, micro


def frame_psnr(a, b):
    return ru.psnr(a, b, peak=1.0)


def case_three_depths(name, **kwargs):
    scene = three_depths_scene(**kwargs)
    cycles, micro = render_both(scene, name)
    db = frame_psnr(cycles, micro)
    failures = []
    if db < THRESHOLD_DB:
        failures.append(f"PSNR {db:.2f} dB < {THRESHOLD_DB}")
    # Mutations: no depth of field, and half the aperture.
    cam = scene.camera.data
    cam.dof.use_dof = False
    sharp = ru.render_passes(scene, "MICROPOLY", W, H, samples=MICROPOLY_SPP)["rgba"]
    cam.dof.use_dof = True
    cam.dof.aperture_fstop *= 2.0
    half = ru.render_passes(scene, "MICROPOLY", W, H, samples=MICROPOLY_SPP)["rgba"]
    db_sharp, db_half = frame_psnr(cycles, sharp), frame_psnr(cycles, half)
    for what, value in (("without depth of field", db_sharp), ("with half the aperture", db_half)):
        if value >= THRESHOLD_DB:
            failures.append(f"{what} Micropoly still reaches {value:.2f} dB: the case cannot tell")
    print(f"{'FAIL' if failures else 'ok  '} {name}: PSNR {db:.2f} dB; no depth of field {db_sharp:.2f} dB, "
          f"half the aperture {db_half:.2f} dB" + "".join(f"\n     {f}" for f in failures))
    return not failures


def case_blur_extent():
    scene = edge_scene()
    cycles, micro = render_both(scene, "edge")
    wc, wm = ru.ramp_width(cycles[..., 3]), ru.ramp_width(micro[..., 3])
    cam = scene.camera.data
    # The circle of confusion Cycles' thin lens gives this edge: diameter in
    # pixels = focal length in pixels x aperture diameter x |1/F - 1/d|.
    focal_px = cam.lens / cam.sensor_width * W
    diameter = focal_px * (2 * cam.lens * 1e-3 / (2 * cam.dof.aperture_fstop)) * abs(1 / 2.0 - 1 / 9.0)
    ok = abs(wc - wm) <= 1.0 and wc > 0.5 * diameter
    print(f"{'ok  ' if ok else 'FAIL'} blur extent: 5-95% ramp {wm:.2f} px, Cycles {wc:.2f} px "
          f"(circle of confusion {diameter:.2f} px)")
    return ok


def case_viewport():
    """Through the camera, the viewport's render shows the camera's depth of
    field: its view (viewport.view_from_camera) renders the alpha F12 renders,
    and does not without the lens."""
    from micropoly import _native, export, viewport

    scene = three_depths_scene()
    f12 = ru.render_passes(scene, "MICROPOLY", W, H, samples=MICROPOLY_SPP)["rgba"]
    depsgraph = bpy.context.evaluated_depsgraph_get()
    renderer = _native.Renderer()

    def through_camera(lens):
        view = viewport.view_from_camera(scene, depsgraph, W, H)
        if not lens:
            view.lens_camera = None
        exported = export.export_scene(depsgraph, view=view)
        return np.asarray(renderer.render(exported.scene)["rgba"])

    db = ru.psnr(f12[..., 3], through_camera(True)[..., 3], peak=1.0)
    db_sharp = ru.psnr(f12[..., 3], through_camera(False)[..., 3], peak=1.0)
    ok = db >= 40.0 and db_sharp < 30.0
    print(f"{'ok  ' if ok else 'FAIL'} viewport through the camera: alpha against F12 {db:.2f} dB "
          f"(>= 40), without the lens {db_sharp:.2f} dB (< 30)")
    return ok


def case_panels_shown():
    """The camera's Depth of Field panels are shown for Micropoly."""
    ru.reset_scene()
    missing = [name for name in ("DATA_PT_camera_dof", "DATA_PT_camera_dof_aperture")
               if "MICROPOLY" not in getattr(bpy.types, name).COMPAT_ENGINES]
    print(f"{'FAIL' if missing else 'ok  '} Depth of Field panels for Micropoly" + (f": missing {missing}" if missing else ""))
    return not missing


def main():
    results = [
        case_panels_shown(),
        case_viewport(),
        case_three_depths("round aperture"),
        case_three_depths("6 blades turned 10 degrees", blades=6, rotation=math.radians(10)),
        case_three_depths("focus object", focus_object=True),
        case_blur_extent(),
    ]
    return 0 if all(results) else 1


ru.run_test(main)
