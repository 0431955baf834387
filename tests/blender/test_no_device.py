"""Run with OCL_ICD_VENDORS pointing at an empty folder, so no OpenCL driver
is found: F12 must stop with a clear error, not crash or hang."""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

scene = ru.reset_scene()
bpy.ops.mesh.primitive_cube_add()
ru.add_camera(scene, (0, -5, 0), (0, 0, 0))
scene.render.engine = "MICROPOLY"
scene.render.resolution_x, scene.render.resolution_y = 32, 24
try:
    bpy.ops.render.render()
    message = None
except RuntimeError as e:
    message = str(e)
ok = message is not None and "no OpenCL device" in message
print(f"{'ok  ' if ok else 'FAIL'} a missing OpenCL device is reported: {message}")
print(f"{int(ok)} passed, {int(not ok)} failed")
sys.stdout.flush()
os._exit(0 if ok else 1)
