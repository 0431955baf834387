"""Motion blur and depth of field: what they cost. Run with Blender (or a
Python with bpy):

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/blur_bench.py -- [--rib-only] [--quick]

Scene: the six subdivided Suzannes of bench/blender_bench.py (floor, sun,
point and area light casting shadows), 1920x1080, 16 samples, three ways:
  blur_static  as it is;
  blur_motion  each Suzanne moving 1.2 m per frame (alternately along x and
               y) and turning 40 degrees per frame, linear keys, Render >
               Motion Blur with a shutter of 0.5 frames centred on the frame
               (3 motion steps);
  blur_dof     the camera's Depth of Field at f/1.4, focused on the middle
               of the scene (the second row's Suzanne).
Default: F12 of each by Micropoly (PoCL) and by Cycles (the same settings,
its default light paths and adaptive subdivision at 1 px), one render each,
interleaved; wall times and ratios printed.
--rib-only: writes the three as RIB (bench/out/blur_*.rib) for the CLI's
per-stage timings and sample-test counts (bench/bench.py blur)."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))

import bpy  # noqa: E402

import blender_bench as bb  # noqa: E402
import render_utils as ru  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
W, H = (480, 270) if "--quick" in args else (1920, 1080)
SAMPLES = 16
KINDS = ("static", "motion", "dof")


def build_scene(kind):
    scene = bb.build_scene()
    scene.render.resolution_x, scene.render.resolution_y = W, H
    for obj in scene.objects:
        if obj.type == "LIGHT":
            ru.set_cast_shadow(obj.data, True)
    suzannes = sorted((o for o in scene.objects if o.type == "MESH" and o.name.startswith("Suzanne")),
                      key=lambda o: o.name)
    if kind == "motion":
        for i, obj in enumerate(suzannes):
            axis = i % 2
            start = obj.location.copy()
            obj.location[axis] = start[axis] - 1.2
            obj.rotation_euler.z -= math.radians(40)
            obj.keyframe_insert("location", frame=1)
            obj.keyframe_insert("rotation_euler", frame=1)
            obj.location[axis] = start[axis] + 1.2
            obj.rotation_euler.z += math.radians(80)
            obj.keyframe_insert("location", frame=3)
            obj.keyframe_insert("rotation_euler", frame=3)
            for curve in obj.animation_data.action.fcurves:
                for key in curve.keyframe_points:
                    key.interpolation = "LINEAR"
        r = scene.render
        r.use_motion_blur = True
        r.motion_blur_shutter = 0.5
        owner = r if hasattr(r, "motion_blur_position") else scene.cycles
        owner.motion_blur_position = "CENTER"
        scene.frame_set(2)
    elif kind == "dof":
        cam = scene.camera
        dof = cam.data.dof
        dof.use_dof = True
        dof.aperture_fstop = 1.4
        dof.focus_distance = (cam.location - suzannes[4].location).length
    return scene


def export_ribs():
    ru.enable_addon()
    for kind in KINDS:
        scene = build_scene(kind)
        scene.micropoly.samples = SAMPLES
        ru.write_bench_rib(scene, f"blur_{kind}")


def side_by_side():
    ru.enable_addon()
    print(f"six Suzannes, {W}x{H}, {SAMPLES} samples, F12 wall time, one run each")
    print("| scene | Micropoly s | Cycles s | Cycles / Micropoly |")
    print("|---|---|---|---|")
    for kind in KINDS:
        scene = build_scene(kind)
        scene.render.engine = "MICROPOLY"
        scene.micropoly.samples = SAMPLES
        micro = ru.f12_seconds(scene)
        scene = build_scene(kind)
        ru.setup_cycles(scene, samples=SAMPLES, shadows=True)
        c = scene.cycles
        c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 12, 4, 4  # Cycles' defaults
        cycles = ru.f12_seconds(scene)
        print(f"| {kind} | {micro:.2f} | {cycles:.2f} | {cycles / micro:.1f}x |", flush=True)


if __name__ == "__main__":
    if "--rib-only" in args:
        export_ribs()
    else:
        side_by_side()
    sys.stdout.flush()
    os._exit(0)  # the bpy module can hang in its exit handlers
