# SPDX-License-Identifier: GPL-3.0-or-later
"""Depsgraph instances (Geometry Nodes' Instance on Points, particle systems,
collection instances, instancing by vertices or faces) -> Scene prototypes
and instances (scene.h).

Each distinct instanced mesh becomes one prototype, exported once; every
instance then costs only its matrix and Object Info values, gathered in
numpy arrays and handed over in one call per prototype. Two instances share
a prototype when they place the same evaluated mesh data with the same
material slots (Cycles keys its geometry the same way: by the data, not by
the instancing object).
"""

import numpy as np

from . import export_mesh


class InstanceTable:
    def __init__(self):
        self._prototypes = {}  # key -> prototype index, or None (nothing to render)
        self._placed = {}      # prototype index -> ([matrices], [random], [colour], [pass index], visibility)

    @staticmethod
    def _key(obj):
        slots = tuple(slot.material.name_full if slot.material else "" for slot in obj.material_slots)
        return obj.data.as_pointer(), obj.original.name_full, slots, export_mesh.ray_visibility(obj)

    def add(self, native_scene, materials, meshes, inst, matrix, warnings, depsgraph):
        """Places `inst` (a depsgraph instance of a mesh); returns False when
        its mesh has nothing to render."""
        obj = inst.object
        key = self._key(obj)
        if key not in self._prototypes:
            identity = np.identity(4, dtype=np.float32)
            made = export_mesh.export_object(native_scene, materials, meshes, obj, identity, warnings,
                                             is_instance=True, depsgraph=depsgraph)
            self._prototypes[key] = native_scene.mesh_to_prototype(-1, obj.name) if made else None
        proto = self._prototypes[key]
        if proto is None:
            return False
        placed = self._placed.setdefault(proto, ([], [], [], [], key[3]))
        placed[0].append(matrix)
        placed[1].append(export_mesh.object_random(obj.name, inst.random_id))
        placed[2].append(tuple(obj.color))
        placed[3].append(float(obj.pass_index))
        return True

    def flush(self, native_scene):
        """Hands every prototype's instances to the scene."""
        for proto, (matrices, random, colours, passes, (camera, shadows)) in self._placed.items():
            native_scene.add_instances(
                proto, np.asarray(matrices, dtype=np.float32).reshape(-1, 4, 4),
                random=np.asarray(random, dtype=np.float32), object_color=np.asarray(colours, dtype=np.float32),
                pass_index=np.asarray(passes, dtype=np.float32), visible_camera=camera, cast_shadows=shadows)
        self._placed.clear()
