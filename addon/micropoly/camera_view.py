"""The world-to-camera matrix of a camera object, as Blender renders it."""

import numpy as np


def view_matrix(camera_object):
    """World to camera for `camera_object` (evaluated), as a float32 numpy
    array. Blender renders a camera without its object's scale (Cycles clears
    it from the camera's matrix), so only location and rotation count; a
    camera scaled to zero along an axis has no orientation there and cannot
    be rendered: ValueError with a message for the artist."""
    m = camera_object.matrix_world.normalized()
    try:
        return np.array(m.inverted(), dtype=np.float32)
    except ValueError:
        raise ValueError(f"camera '{camera_object.name}' is scaled to zero (or its transform is degenerate): "
                         "give it a non-zero scale") from None
