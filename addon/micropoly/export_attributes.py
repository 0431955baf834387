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
before any object is exported, so every object carries all of them.

Each slot is (name, kind): "OBJECT", "INSTANCER", or for point clouds,
whose every point is an instance of its own, "POINT" (a geometry attribute
on the points) and "POINT_INFO" (Point Info's values); those two are
filled per point by export_points.py and read zero everywhere else."""

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
    for k, (name, kind) in enumerate(slots):
        if kind not in ("OBJECT", "INSTANCER"):
            continue
        v = rgba(obj, name) or rgba(getattr(obj, "data", None), name)
        if v is not None:
            out[k] = v
    return out


class InstanceAttributes:
    """The slots' values of depsgraph instances. What an instance shares
    with others of its instancer and object (their properties, its
    particle settings') is looked up once per such combination; Geometry
    Nodes' attributes are read as arrays once per instancer. Per instance,
    entry() keeps only which combination and which row it takes (a few
    dictionary lookups); values() builds the arrays with numpy."""

    def __init__(self, slots, warnings):
        self.slots = slots
        self.warnings = warnings
        self._shared = {}     # (settings, instancer, object, data) pointers -> index into _bases
        self._bases = []      # per combination: (slots, 4) values, and which slots the particle settings gave
        self._geometry = {}   # instancer pointer -> index into _instancers, or -1 (no instance attributes)
        self._instancers = []  # (id -> row or None, {name: (rows, 4) array})

    def entry(self, inst):
        """What instance `inst` takes its values from: (combination,
        instancer with attributes or -1, its row there or -1)."""
        obj = inst.object
        parent = inst.parent if inst.is_instance else None
        psys = inst.particle_system if inst.is_instance else None
        settings = psys.settings if psys is not None else None
        key = (settings.as_pointer() if settings else 0, parent.as_pointer() if parent else 0, obj.as_pointer(),
               obj.data.as_pointer())
        shared = self._shared.get(key)
        if shared is None:
            shared = self._shared[key] = len(self._bases)
            first, found, last = self._lookup(settings, parent, obj)
            self._bases.append((np.where(found[:, None], first, last), found))
        geometry = self._geometry_attributes(parent) if parent is not None else -1
        if geometry < 0:
            return shared, -1, -1
        rows = self._instancers[geometry][0]
        pid = inst.persistent_id[1]
        row = rows.get(pid, -1) if rows is not None else pid
        return shared, geometry, row

    def values(self, entries):
        """(instances, slots, 4) for entries from entry()."""
        e = np.asarray(entries, dtype=np.int64).reshape(-1, 3)
        bases = np.stack([b for b, _ in self._bases])
        found = np.stack([f for _, f in self._bases])
        out = bases[e[:, 0]]
        for g, (_, arrays) in enumerate(self._instancers):
            mine = e[:, 1] == g
            for k, (name, kind) in enumerate(self.slots):
                a = arrays.get(name)
                if kind != "INSTANCER" or a is None:
                    continue
                # A value the particle settings give comes first.
                take = mine & ~found[e[:, 0], k] & (e[:, 2] >= 0) & (e[:, 2] < len(a))
                out[take, k] = a[e[take, 2]]
        return out

    def _lookup(self, settings, parent, obj):
        """Values found before the Geometry Nodes attributes (the particle
        settings': Instancer only), and after them (the instancer's, then
        the object's own)."""
        n = len(self.slots)
        first = np.zeros((n, 4), dtype=np.float32)
        found = np.zeros(n, dtype=bool)
        last = object_values(self.slots, obj)
        for k, (name, kind) in enumerate(self.slots):
            if kind != "INSTANCER":
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
        """Index into _instancers of the instancer's Geometry Nodes instance
        attributes that the slots name (Instancer type), with the map from
        an instance's id (its persistent id's second entry) to its row; -1
        where it has none."""
        pointer = parent.as_pointer()
        if pointer in self._geometry:
            return self._geometry[pointer]
        self._geometry[pointer] = -1
        names = {name for name, kind in self.slots if kind == "INSTANCER"}
        if not names or not any(m.type == "NODES" for m in getattr(parent, "modifiers", ())):
            return -1
        import bpy
        geometry_set = getattr(bpy.types, "GeometrySet", None)
        if geometry_set is None:
            self.warnings.append(f"'{parent.name}': Geometry Nodes instance attributes are read from Blender 4.3 "
                                 "on; Attribute nodes of type Instancer read its properties and the object's")
            return -1
        geometry = geometry_set.from_evaluated_object(parent)  # owns the point cloud read below
        points = geometry.instances_pointcloud()
        if points is None:
            return -1
        arrays = {}
        for name in names & set(points.attributes.keys()):
            rgba = attribute_rgba(points.attributes[name])
            if rgba is not None:
                arrays[name] = rgba
        if not arrays:
            return -1
        rows = None
        if "id" in points.attributes:
            ids = np.zeros(len(points.attributes["id"].data), dtype=np.int32)
            points.attributes["id"].data.foreach_get("value", ids)
            rows = dict(zip(ids.tolist(), range(len(ids))))
        self._instancers.append((rows, arrays))
        self._geometry[pointer] = len(self._instancers) - 1
        return self._geometry[pointer]


def attribute_rgba(attribute):
    """A geometry attribute's values as (n, 4) RGBA, as Cycles converts
    them to a colour: a number as (v, v, v, 1), a vector as (x, y, z, 1),
    a 2D vector as (x, y, 0, 1); None for a type it does not read."""
    sizes = {"FLOAT_COLOR": ("color", 4), "BYTE_COLOR": ("color", 4), "FLOAT_VECTOR": ("vector", 3),
             "FLOAT2": ("vector", 2), "FLOAT": ("value", 1), "INT": ("value", 1), "INT8": ("value", 1),
             "BOOLEAN": ("value", 1)}
    kind = attribute.data_type
    if kind not in sizes:
        return None
    prop, size = sizes[kind]
    n = len(attribute.data)
    flat = np.empty(n * size, dtype={"FLOAT": np.float32, "FLOAT_COLOR": np.float32, "BYTE_COLOR": np.float32,
                                     "FLOAT_VECTOR": np.float32, "FLOAT2": np.float32, "BOOLEAN": bool}.get(kind, np.int32))
    attribute.data.foreach_get(prop, flat)
    values = flat.astype(np.float32).reshape(n, size)
    out = np.zeros((n, 4), dtype=np.float32)
    out[:, 3] = 1.0
    if size == 1:
        out[:, :3] = values
    else:
        out[:, :size] = values
    return out


def object_arguments(obj, inst, materials):
    """What a point cloud or curves object brings to add_points / add_curves:
    its first material, ray visibility and Object Info values, as keyword
    arguments (meshes pass the same through add_mesh)."""
    from . import export_mesh

    visible_camera, cast_shadows = export_mesh.ray_visibility(obj)
    slots = [materials.get(slot.material) for slot in obj.material_slots] or [0]
    return dict(material=slots[0], visible_camera=visible_camera, cast_shadows=cast_shadows,
                object_color=list(obj.color), pass_index=float(obj.pass_index),
                random=export_mesh.object_random(obj.name, inst.random_id if inst.is_instance else None),
                attributes=object_values(materials.object_attributes, obj))
