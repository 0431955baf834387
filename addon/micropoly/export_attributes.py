# SPDX-License-Identifier: GPL-3.0-or-later
"""Attribute nodes of type Object and Instancer: one RGBA per object (or
instance) and slot, looked up where Cycles and EEVEE look them up
(Blender's BKE_object_dupli_find_rgba_attribute):

- Object: the object's custom property or property path of that name,
  then its data's (the mesh);
- Instancer: for an instance, its particle system's settings, then the
  Geometry Nodes instance attribute of that name (Blender 4.3 and later:
  read through bpy.types.GeometrySet), then the object that instances it,
  then, as Object, the instanced object and its data.

A number or boolean reads as (v, v, v, 1), a list of up to four numbers as
its values over (0, 0, 0, 1); a name found nowhere reads zero. Slots are
numbered by the material compiler (export_materials.Materials.object_attribute)
before any object is exported, so every object carries all of them."""

import numpy as np


def rgba(owner, name):
    """`owner`'s custom property `name`, else its property path `name`, as
    RGBA; None where neither holds a number, a boolean or up to four
    numbers."""
    if owner is None:
        return None
    try:
        value = owner[name]
    except (KeyError, TypeError):
        try:
            value = owner.path_resolve(name)
        except (ValueError, TypeError, AttributeError):
            return None
    if isinstance(value, str):
        return None
    if isinstance(value, (bool, int, float)):
        v = float(value)
        return (v, v, v, 1.0)
    if hasattr(value, "to_list"):
        value = value.to_list()
    try:
        values = [float(x) for x in value]
    except (TypeError, ValueError):
        return None
    if not 0 < len(values) <= 4:
        return None
    return tuple(values + [0.0, 0.0, 0.0, 1.0][len(values):])


def object_values(slots, obj):
    """(slots, 4): an object's own values (Object type, and Instancer type
    outside instances)."""
    out = np.zeros((len(slots), 4), dtype=np.float32)
    for k, (name, _) in enumerate(slots):
        v = rgba(obj, name) or rgba(getattr(obj, "data", None), name)
        if v is not None:
            out[k] = v
    return out


class InstanceAttributes:
    """Per depsgraph instance, the slots' values. What an instance shares
    with others of its instancer and object (their properties, its
    particle settings') is looked up once per such triple; Geometry Nodes'
    attributes are read as arrays once per instancer, and each instance
    then only picks its row by its persistent id."""

    def __init__(self, slots, warnings):
        self.slots = slots
        self.warnings = warnings
        self._shared = {}     # (particle settings, instancer, object) -> (first, last) arrays and found masks
        self._geometry = {}   # instancer pointer -> (id -> row, {name: (rows, 4) array}) or None

    def values(self, inst):
        """(slots, 4) for depsgraph instance `inst`."""
        if not self.slots:
            return None
        obj = inst.object
        parent = inst.parent if inst.is_instance else None
        psys = inst.particle_system if inst.is_instance else None
        settings = psys.settings if psys is not None else None
        key = (settings.as_pointer() if settings else 0, parent.as_pointer() if parent else 0, obj.as_pointer(),
               obj.data.as_pointer())
        shared = self._shared.get(key)
        if shared is None:
            shared = self._shared[key] = self._lookup(settings, parent, obj)
        first, first_found, last = shared
        geometry = self._geometry_attributes(parent) if parent is not None else None
        if geometry is None:
            return np.where(first_found[:, None], first, last)
        rows, arrays = geometry
        row = rows.get(inst.persistent_id[1]) if rows is not None else inst.persistent_id[1]
        out = np.where(first_found[:, None], first, last)
        for k, (name, dupli) in enumerate(self.slots):
            a = arrays.get(name)
            if dupli and a is not None and not first_found[k] and row is not None and 0 <= row < len(a):
                out[k] = a[row]
        return out

    def _lookup(self, settings, parent, obj):
        """Values found before the Geometry Nodes attributes (the particle
        settings': Instancer only), and after them (the instancer's, then
        the object's own)."""
        n = len(self.slots)
        first = np.zeros((n, 4), dtype=np.float32)
        found = np.zeros(n, dtype=bool)
        last = object_values(self.slots, obj)
        for k, (name, dupli) in enumerate(self.slots):
            if not dupli:
                continue
            v = rgba(settings, name)
            if v is not None:
                first[k], found[k] = v, True
                continue
            v = rgba(parent, name)
            if v is not None:
                last[k] = v
        return first, found, last

    def _geometry_attributes(self, parent):
        """The instancer's Geometry Nodes instance attributes the slots name
        (Instancer type), with the map from an instance's id (its persistent
        id's second entry) to its row, or None where it has none."""
        pointer = parent.as_pointer()
        if pointer in self._geometry:
            return self._geometry[pointer]
        self._geometry[pointer] = None
        names = {name for name, dupli in self.slots if dupli}
        if not names or not any(m.type == "NODES" for m in getattr(parent, "modifiers", ())):
            return None
        import bpy
        geometry_set = getattr(bpy.types, "GeometrySet", None)
        if geometry_set is None:
            self.warnings.append(f"'{parent.name}': Geometry Nodes instance attributes are read from Blender 4.3 "
                                 "on; Attribute nodes of type Instancer read its properties and the object's")
            return None
        geometry = geometry_set.from_evaluated_object(parent)  # owns the point cloud read below
        points = geometry.instances_pointcloud()
        if points is None:
            return None
        arrays = {}
        for name in names & set(points.attributes.keys()):
            arrays[name] = _attribute_rgba(points.attributes[name])
        if not arrays:
            return None
        rows = None
        if "id" in points.attributes:
            ids = np.zeros(len(points.attributes["id"].data), dtype=np.int32)
            points.attributes["id"].data.foreach_get("value", ids)
            rows = dict(zip(ids.tolist(), range(len(ids))))
        self._geometry[pointer] = (rows, arrays)
        return self._geometry[pointer]


def _attribute_rgba(attribute):
    """A geometry attribute's values as (n, 4) RGBA, as Cycles converts
    them to a colour: a number as (v, v, v, 1), a vector as (x, y, z, 1)."""
    n = len(attribute.data)
    kind = attribute.data_type
    out = np.zeros((n, 4), dtype=np.float32)
    out[:, 3] = 1.0
    if kind in ("FLOAT_COLOR", "BYTE_COLOR"):
        attribute.data.foreach_get("color", out.reshape(-1))
    elif kind in ("FLOAT_VECTOR", "FLOAT2"):
        width = 3 if kind == "FLOAT_VECTOR" else 2
        v = np.zeros(n * width, dtype=np.float32)
        attribute.data.foreach_get("vector", v)
        out[:, :width] = v.reshape(n, width)
    elif kind in ("FLOAT", "INT", "BOOLEAN", "INT8"):
        v = np.zeros(n, dtype={"FLOAT": np.float32, "BOOLEAN": bool}.get(kind, np.int32))
        attribute.data.foreach_get("value", v)
        out[:, :3] = v.astype(np.float32)[:, None]
    return out
