# SPDX-License-Identifier: GPL-3.0-or-later
"""Point clouds (Geometry Nodes' points, Point Cloud objects) -> spheres, the
shape Cycles gives points: positions and radii read with foreach_get, handed
over in one call; the native side places one shared unit sphere per point
(native/src/scene/points.h). A point without a radius attribute has Cycles'
0.01. Every point reads its cloud's Object Info and Attribute values, and
its own in the slots of kind "POINT" (the cloud's attributes, which
Attribute nodes of type Geometry read) and "POINT_INFO" (Point Info: its
random number, Cycles' hash of its number, and its radius in world units).
With motion blur, each point moves with the cloud's transform and its own
position at every step (export_motion.py)."""

import numpy as np

from . import export_attributes, export_curves, export_mesh, export_motion


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
    moving = {}
    steps = motion.clouds.get(export_motion.instance_key(inst)) if motion is not None else None
    if steps is not None:
        matrices, points = steps
        empty = np.zeros(0, dtype=np.float32)
        moving = dict(motion_points=empty if points is None else points,
                      motion_object_to_world=empty if matrices is None else matrices)
    args = export_attributes.object_arguments(obj, inst, materials)
    slots = materials.object_attributes
    if any(kind in ("POINT", "POINT_INFO") for _, kind in slots):
        values = np.repeat(args.pop("attributes")[None], count, axis=0)
        for k, (name, kind) in enumerate(slots):
            if kind == "POINT_INFO":
                values[:, k, 0] = export_mesh.random_from_ids(export_mesh.hash_uint2(np.arange(count), 0)
                                                              .astype(np.int64))
                values[:, k, 1] = radii * export_curves.transform_scale(matrix)
                values[:, k, 2] = 1.0
            elif kind == "POINT":
                attr = pointcloud.attributes.get(name)
                rgba = export_attributes.attribute_rgba(attr) if attr is not None and attr.domain == "POINT" else None
                if rgba is not None:
                    values[:, k] = rgba
        args["point_attributes"] = values
    skipped = native_scene.add_points(obj.name, positions, radii, object_to_world=matrix, **args, **moving)
    if skipped:
        warnings.append(f"point cloud '{obj.name}': {skipped} points with a position or radius that is not finite "
                        "and positive are skipped")
    return skipped < count
