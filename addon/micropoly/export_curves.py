# SPDX-License-Identifier: GPL-3.0-or-later
"""Curves objects (the hair curves of Blender 3.3 and later, and Geometry
Nodes' curves where they evaluate to Curves) -> round tubes: positions,
radii and each curve's first point read with foreach_get and handed over in
one call; the native side turns each curve's points, Catmull-Rom keys as
Cycles reads hair, into Bezier tubes (native/src/scene/curves.h). Every
curve reads its object's Object Info and Attribute values. With motion
blur, the object's transform and points at each step (export_motion.py)
move the tubes."""

import numpy as np

from . import export_attributes, export_mesh


def export_curves(native_scene, materials, inst, matrix, warnings, motion=None):
    """Adds the curves `inst` renders; returns whether anything was added."""
    obj = inst.object
    curves = obj.data
    count, points = len(curves.curves), len(curves.points)
    if count == 0 or points == 0:
        return False
    visible_camera, cast_shadows = export_mesh.ray_visibility(obj)
    if not visible_camera and not cast_shadows:
        return False
    positions = np.empty(points * 3, dtype=np.float32)
    curves.attributes["position"].data.foreach_get("vector", positions)
    radius = curves.attributes.get("radius")
    radii = np.empty(points, dtype=np.float32)
    if radius is not None and radius.domain == "POINT" and radius.data_type == "FLOAT":
        radius.data.foreach_get("value", radii)
    else:
        radii.fill(0.0)  # as Cycles: curves without radii are not seen
    offsets = np.empty(count + 1, dtype=np.int32)
    curves.curve_offset_data.foreach_get("value", offsets)
    kinds = curves.attributes.get("curve_type")
    if kinds is not None:
        types = np.empty(count, dtype=np.int8 if kinds.data_type == "INT8" else np.int32)
        kinds.data.foreach_get("value", types)
        if np.any(types != 0):  # 0: Catmull-Rom
            warnings.append(f"curves '{obj.name}': Bezier, NURBS and poly curves render through their points as "
                            "Catmull-Rom curves")
    moving = {}
    if motion is not None and not inst.is_instance:
        empty = np.zeros(0, dtype=np.float32)
        matrices, steps = motion.matrices.get(obj.name), motion.points.get(obj.name)
        moving = dict(motion_points=empty if steps is None else steps,
                      motion_object_to_world=empty if matrices is None else matrices)
    skipped = native_scene.add_curves(obj.name, positions.reshape(-1, 3), radii, offsets, object_to_world=matrix,
                                      **export_attributes.object_arguments(obj, inst, materials), **moving)
    if skipped:
        warnings.append(f"curves '{obj.name}': {skipped} curves with fewer than 2 points, or a point or radius that "
                        "is not finite, are skipped")
    return skipped < count
