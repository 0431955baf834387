# SPDX-License-Identifier: GPL-3.0-or-later
"""Curves objects (the hair curves of Blender 3.3 and later, and Geometry
Nodes' curves where they evaluate to Curves) -> round tubes: positions,
radii and each curve's first point read with foreach_get and handed over in
one call; the native side turns each curve's points, Catmull-Rom keys as
Cycles reads hair, into Bezier tubes (native/src/scene/curves.h). Every
curve reads its object's Object Info and Attribute values. With motion
blur, the object's transform and points at each step (export_motion.py)
move the tubes.

What the materials read per point travels in their UV layers
(point_layers): Hair Info's intercept, length, random and thickness (as
Cycles computes them: the intercept is the arc length along the keys'
polyline over its whole, the random Cycles' hash of the curve's number),
attributes on the point and curve domains, and the UV of the curve's root
(the first 2D vector attribute on curves, as Cycles takes it)."""

import numpy as np

from . import export_attributes, export_mesh


def hair_info(positions, offsets, radii, scale, first_curve=0):
    """(points, 4): Hair Info's (intercept, length, random, thickness) at
    each point of curves `offsets` (object space; `scale` turns a radius
    into world units; curves are numbered from `first_curve`)."""
    counts = np.diff(offsets)
    step = np.zeros(len(positions), dtype=np.float64)
    step[1:] = np.linalg.norm(np.diff(positions.astype(np.float64), axis=0), axis=1)
    step[offsets[:-1][counts > 0]] = 0.0  # a curve starts from nothing
    run = np.cumsum(step)
    start = np.repeat(run[offsets[:-1][counts > 0]], counts[counts > 0])
    along = run - start
    length = np.repeat(np.add.reduceat(step, offsets[:-1][counts > 0]) if len(step) else step,
                       counts[counts > 0])
    out = np.empty((len(positions), 4), dtype=np.float32)
    out[:, 0] = np.divide(along, length, out=np.zeros_like(along), where=length > 0.0)
    out[:, 1] = length
    curve = np.repeat(np.arange(len(counts), dtype=np.int64) + first_curve, counts)
    out[:, 2] = export_mesh.random_from_ids(export_mesh.hash_uint2(curve, 0).astype(np.int64))
    out[:, 3] = 2.0 * radii * scale
    return out


def point_layers(names, count, hair, attribute, uv):
    """(layers, count, 2): the UV layers the materials read (names as
    export_mesh._uv_layers takes them), from per-point arrays: `hair`
    (count, 4) Hair Info values, attribute(name) an attribute's (count, 4)
    RGBA or None, uv(name) a UV map's (count, 2) or None. Trailing layers
    the curves have nothing for are left out (they read zero)."""
    layers, attributes = [], {}
    for name in names:
        values = None
        if isinstance(name, tuple) and name[0] == "hair":
            values = hair[:, 2 * name[1]:2 * name[1] + 2]
        elif isinstance(name, tuple) and name[0] == "attribute":
            if name[1] not in attributes:
                attributes[name[1]] = attribute(name[1])
            if attributes[name[1]] is not None:
                values = attributes[name[1]][:, 2 * name[2]:2 * name[2] + 2]
        elif not isinstance(name, tuple):
            values = uv(name)
        layers.append(values)
    while layers and layers[-1] is None:
        layers.pop()
    out = np.zeros((len(layers), count, 2), dtype=np.float32)
    for k, values in enumerate(layers):
        if values is not None:
            out[k] = values
    return out


def transform_scale(matrix):
    """How a transform scales a radius: the cube root of its volume change,
    as Cycles scales curve radii when it applies an object's transform."""
    return float(abs(np.linalg.det(np.asarray(matrix, dtype=np.float64)[:3, :3])) ** (1.0 / 3.0))


def _curve_attribute(curves, name, counts):
    """(points, 4) RGBA of the curves' attribute `name` on the point or
    curve domain (a curve's value on each of its points), or None."""
    layer = curves.attributes.get(name)
    if layer is None or layer.domain not in ("POINT", "CURVE"):
        return None
    rgba = export_attributes.attribute_rgba(layer)
    if rgba is None or layer.domain == "POINT":
        return rgba
    return np.repeat(rgba, counts, axis=0)


def _curve_uv(curves, name, counts):
    """(points, 2): UV map `name` of curves, a 2D vector attribute of that
    name; "" (the material's default UV) is the first one on the curve
    domain, the UV of the curve's root on its surface. None for none."""
    if not name:
        name = next((a.name for a in curves.attributes if a.domain == "CURVE" and a.data_type == "FLOAT2"), None)
    rgba = _curve_attribute(curves, name, counts) if name else None
    return None if rgba is None else rgba[:, :2]


def ribbons(scene):
    """Whether strands render as ribbons facing each view, Cycles' Rounded
    Ribbons (its default), rather than as round tubes, its 3D Curves."""
    return getattr(getattr(scene, "cycles_curves", None), "shape", "RIBBONS") == "RIBBONS"


def export_curves(native_scene, materials, inst, matrix, warnings, motion=None, as_ribbons=True):
    """Adds the curves `inst` renders (as ribbons or tubes: `as_ribbons`);
    returns whether anything was added."""
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
            # Cycles reads the same points the same way (its hair export takes
            # the control points whatever the type).
            warnings.append(f"curves '{obj.name}': Bezier, NURBS and poly curves render as Cycles renders them, "
                            "Catmull-Rom curves through their points (handles and weights are not read)")
    moving = {}
    if motion is not None and not inst.is_instance:
        empty = np.zeros(0, dtype=np.float32)
        matrices, steps = motion.matrices.get(obj.name), motion.points.get(obj.name)
        moving = dict(motion_points=empty if steps is None else steps,
                      motion_object_to_world=empty if matrices is None else matrices)
    positions = positions.reshape(-1, 3)
    counts = np.diff(offsets)
    layers = point_layers(materials.uv_names, points,
                          hair_info(positions, offsets, radii, transform_scale(matrix)),
                          lambda name: _curve_attribute(curves, name, counts),
                          lambda name: _curve_uv(curves, name, counts))
    skipped = native_scene.add_curves(obj.name, positions, radii, offsets, object_to_world=matrix,
                                      point_layers=layers, ribbons=as_ribbons,
                                      **export_attributes.object_arguments(obj, inst, materials), **moving)
    if skipped:
        warnings.append(f"curves '{obj.name}': {skipped} curves with fewer than 2 points, or a point or radius that "
                        "is not finite, are skipped")
    return skipped < count
