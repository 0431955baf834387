# SPDX-License-Identifier: GPL-3.0-or-later
"""Point clouds (Geometry Nodes' points, Point Cloud objects) -> spheres, the
shape Cycles gives points: positions and radii read with foreach_get, handed
over in one call; the native side places one shared unit sphere per point
(native/src/scene/points.h). A point without a radius attribute has Cycles'
0.01. Every point reads its cloud's Object Info and Attribute values."""

import numpy as np

from . import export_attributes, export_mesh


def _attribute(pointcloud, name, width, prop):
    """A point attribute as an (n, width) float32 array, or None."""
    attr = pointcloud.attributes.get(name)
    if attr is None or attr.domain != "POINT":
        return None
    out = np.empty(len(pointcloud.points) * width, dtype=np.float32)
    try:
        attr.data.foreach_get(prop, out)
    except (AttributeError, RuntimeError, TypeError):
        return None  # another type under this name (an integer "radius")
    return out.reshape(-1, width)


def export_point_cloud(native_scene, materials, inst, matrix, warnings, motion=None):
    """Adds the cloud `inst` renders; returns whether anything was added."""
    obj = inst.object
    pointcloud = obj.data
    count = len(pointcloud.points)
    if count == 0:
        return False
    visible_camera, cast_shadows = export_mesh.ray_visibility(obj)
    if not visible_camera and not cast_shadows:
        return False
    positions = _attribute(pointcloud, "position", 3, "vector")
    if positions is None:
        warnings.append(f"point cloud '{obj.name}' has no positions; it is skipped")
        return False
    radii = _attribute(pointcloud, "radius", 1, "value")
    radii = np.full(count, 0.01, dtype=np.float32) if radii is None else radii.reshape(-1)
    if motion is not None:
        warnings.append(f"point cloud '{obj.name}': points render at the shutter's centre, without motion blur")
    skipped = native_scene.add_points(obj.name, positions, radii, object_to_world=matrix,
                                      **export_attributes.object_arguments(obj, inst, materials))
    if skipped:
        warnings.append(f"point cloud '{obj.name}': {skipped} points with a position or radius that is not finite "
                        "and positive are skipped")
    return skipped < count
