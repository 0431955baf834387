# SPDX-License-Identifier: GPL-3.0-or-later
"""Depsgraph instances (Geometry Nodes' Instance on Points, particle systems,
collection instances, instancing by vertices or faces) and linked duplicates
(objects that share one mesh) -> Scene prototypes and instances (scene.h).

Each distinct mesh (or Curves object's curves) becomes one prototype,
exported once; every instance then
costs only its matrix and Object Info values, gathered in numpy arrays and
handed over in one call per prototype. Two placements share a prototype when
they render the same mesh with the same material slots and ray visibility:
the same evaluated mesh data, or, for objects rendered as the limit surface
of their cage (a Subdivision Surface modifier alone), the same cage with the
same boundary and crease settings (Cycles keys its geometry by the data too,
not by the object that places it).
"""

import numpy as np

from . import export_curves, export_mesh, export_motion


class InstanceTable:
    """Prototypes by what they share, and each prototype's placements as
    lists that become numpy arrays in flush(). Per placement only its
    matrix and random id are read; what an object brings (its prototype,
    colour, pass index) is looked up once per object and mesh data (the
    depsgraph may hand one temporary object several meshes)."""

    def __init__(self, motion=None, attributes=None):
        self._prototypes = {}  # key -> prototype index, or None (nothing to render)
        self._objects = {}     # (object, data) pointers -> (prototype, colour, pass index, name's random id, visibility)
        # prototype -> ([matrix rows], [random ids], [colours], [pass indices], visibility, [motion or None],
        # [where Attribute nodes' values come from: InstanceAttributes.entry])
        self._placed = {}
        # Attribute nodes of type Object and Instancer (export_attributes.InstanceAttributes), or None.
        self._attributes = attributes
        # Depsgraph instances that move over the shutter (export_motion.Motion.instances).
        self._moving = motion.instances if motion is not None else {}

    @staticmethod
    def key(obj, shared_data=False):
        """What a placement of `obj` shares its prototype by, or None where
        the object is exported on its own (shared_data: only where it
        renders a cage or an evaluated mesh other objects may share: not a
        mesh its own modifiers or shape keys made). Curves: their evaluated
        data."""
        slots = tuple(slot.material.name_full if slot.material else "" for slot in obj.material_slots)
        if obj.type == "CURVES":
            return ("curves", obj.data.as_pointer()), slots, export_mesh.ray_visibility(obj)
        subsurf, only = export_mesh.subdivision_modifier(obj)
        if subsurf is not None and only:
            if obj.original.data.shape_keys is not None:
                return None if shared_data else (obj.data.as_pointer(), obj.original.name_full, slots)
            data = ("cage", obj.original.data.name_full, subsurf.boundary_smooth, subsurf.use_creases)
        elif shared_data and any(m.show_render for m in obj.original.modifiers):
            return None
        else:
            data = obj.data.as_pointer()
        return data, slots, export_mesh.ray_visibility(obj)

    def add(self, native_scene, materials, meshes, inst, warnings, depsgraph, key=None):
        """Places `inst` (a depsgraph instance of a mesh, or an object that
        shares its mesh: `key`); returns False when its mesh has nothing to
        render."""
        obj = inst.object
        pointers = (obj.as_pointer(), obj.data.as_pointer())
        entry = self._objects.get(pointers)
        if entry is None:
            key = key if key is not None else self.key(obj)
            if key not in self._prototypes:
                identity = np.identity(4, dtype=np.float32)
                if obj.type == "CURVES":
                    made = export_curves.export_curves(native_scene, materials, inst, identity, warnings,
                                                       as_ribbons=export_curves.ribbons(depsgraph.scene))
                    self._prototypes[key] = native_scene.patch_set_to_prototype(-1, obj.name) if made else None
                else:
                    made = export_mesh.export_object(native_scene, materials, meshes, obj, identity, warnings,
                                                     is_instance=True, depsgraph=depsgraph)
                    self._prototypes[key] = native_scene.mesh_to_prototype(-1, obj.name) if made else None
            entry = (self._prototypes[key], tuple(obj.color), float(obj.pass_index),
                     export_mesh.name_random_id(obj.name), key[-1])
            self._objects[pointers] = entry
        proto = entry[0]
        if proto is None:
            return False
        placed = self._placed.get(proto)
        if placed is None:
            placed = self._placed[proto] = ([], [], [], [], entry[4], [], [])
        m = inst.matrix_world
        placed[0].append((*m[0], *m[1], *m[2], *m[3]))
        placed[1].append(inst.random_id if inst.is_instance else entry[3])
        placed[2].append(entry[1])
        placed[3].append(entry[2])
        if self._moving and inst.is_instance:
            placed[5].append(self._moving.get(export_motion.instance_key(inst)))
        if self._attributes is not None and self._attributes.slots:
            placed[6].append(self._attributes.entry(inst))
        return True

    def flush(self, native_scene):
        """Hands every prototype's instances to the scene."""
        for proto, (matrices, ids, colours, passes, (camera, shadows), moving, attributes) in self._placed.items():
            placed = np.asarray(matrices, dtype=np.float32).reshape(-1, 4, 4)
            native_scene.add_instances(
                proto, placed, random=export_mesh.random_from_ids(np.asarray(ids, dtype=np.int64)),
                object_color=np.asarray(colours, dtype=np.float32),
                pass_index=np.asarray(passes, dtype=np.float32), visible_camera=camera, cast_shadows=shadows,
                motion_object_to_world=self._motion(placed, moving),
                attributes=self._attributes.values(attributes) if attributes else np.zeros(0, np.float32))
        self._placed.clear()

    @staticmethod
    def _motion(placed, moving):
        """(instances, steps, 4, 4) matrices over the shutter where any
        instance of the prototype moves (the others hold still at their
        own), else an empty array."""
        steps = next((m.shape[0] for m in moving if m is not None), 0)
        if steps == 0:
            return np.zeros(0, dtype=np.float32)
        out = np.repeat(placed[:, None], steps, axis=1)
        for i, m in enumerate(moving):
            if m is not None:
                out[i] = m
        return out
