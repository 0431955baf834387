"""Run with OCL_ICD_VENDORS pointing at an empty folder, so no OpenCL driver
is found: F12 must stop with a clear error, not crash or hang; the viewport
session must report the same instead of rendering, and close cleanly."""

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

# The Rendered viewport's session, driven as view_update/view_draw drive it.
from micropoly import export, viewport  # noqa: E402

depsgraph = bpy.context.evaluated_depsgraph_get()
view = viewport.view_from_camera(scene, depsgraph, 64, 48)
session = viewport.ViewportSession("")
session.request(export.export_scene(depsgraph, view=view), view, 4, 1.0)
idle = session.wait_idle(30.0)
error = session.error()
session.close()
ok_view = idle and error is not None and "no OpenCL device" in error and session.image() is None
print(f"{'ok  ' if ok_view else 'FAIL'} the viewport session reports it and stays idle: {error}")
failed = int(not ok) + int(not ok_view)
print(f"{2 - failed} passed, {failed} failed")
sys.stdout.flush()
os._exit(0 if failed == 0 else 1)
