"""Shared by the Python tests."""

import numpy as np


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """Row-major world-to-camera matrix, camera looking down -Z (Blender's convention)."""
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.identity(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m.astype(np.float32)
