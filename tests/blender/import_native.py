"""Run by `blender -b --python`: the native module imports in Blender's own
Python and renders a small scene there. Exits non-zero on failure."""

import os
import sys
import traceback

try:
    sys.path.insert(0, os.environ["MICROPOLY_ADDON_DIR"])
    import numpy as np
    from micropoly import _native

    scene = _native.Scene()
    scene.settings.width, scene.settings.height, scene.settings.samples = 32, 32, 4
    eye = np.identity(4, dtype=np.float32)
    eye[2, 3] = -3.0  # world to camera: the camera sits at z = 3 looking down -Z
    scene.set_camera(eye, fov_degrees=60.0)
    points = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float32)
    scene.add_mesh("quad", points, np.array([4], dtype=np.int32), np.arange(4, dtype=np.int32))
    result = _native.Renderer().render(scene)
    coverage = float(result["rgba"][..., 3].sum())
    print(f"micropoly._native {_native.__version__} in Python {sys.version.split()[0]}: coverage {coverage:.1f}")
    assert coverage > 100.0
except Exception:
    traceback.print_exc()
    sys.exit(1)
sys.exit(0)
