# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender depsgraph -> micropoly._native.Scene, with numpy and foreach_get.

The first version: mesh instances (polygons, or Catmull-Clark limit surfaces
for objects whose only modifier is a Subdivision Surface), the camera, point,
sun, spot and area lights, world color as ambient light and each material's
base color. Light units follow Cycles: a Lambertian surface of albedo a lit
by a point light of power P at distance d has radiance a P cos / (4 pi^2 d^2).
"""

import math

import numpy as np

from . import _native

FOUR_PI_SQUARED = 4.0 * math.pi * math.pi


def _matrix(m):
    return np.array(m, dtype=np.float32).reshape(4, 4)


def _render_size(scene):
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(1, int(r.resolution_x * scale)), max(1, int(r.resolution_y * scale))


def export_camera(native_scene, scene, width, height):
    cam_obj = scene.camera
    if cam_obj is None:
        raise RuntimeError("the scene has no camera")
    cam = cam_obj.data
    r = scene.render
    aspect_x, aspect_y = r.pixel_aspect_x, r.pixel_aspect_y
    frame_w, frame_h = width * aspect_x, height * aspect_y
    fit = cam.sensor_fit
    horizontal = fit == "HORIZONTAL" or (fit == "AUTO" and frame_w >= frame_h)
    if cam.type == "ORTHO":
        half = cam.ortho_scale / 2.0
    else:
        sensor = cam.sensor_width if fit in ("AUTO", "HORIZONTAL") else cam.sensor_height
        half = sensor / (2.0 * cam.lens)
    if horizontal:
        half_x, half_y = half, half * frame_h / frame_w
    else:
        half_x, half_y = half * frame_w / frame_h, half
    larger = 2.0 * max(half_x, half_y) if fit == "AUTO" else 2.0 * (half_x if horizontal else half_y)
    sx, sy = cam.shift_x * larger, cam.shift_y * larger
    window = [-half_x + sx, half_x + sx, -half_y + sy, half_y + sy]
    world_to_camera = _matrix(cam_obj.matrix_world.inverted())
    native_scene.set_camera(world_to_camera, orthographic=cam.type == "ORTHO", fov_degrees=90.0,
                            clip_near=cam.clip_start, clip_far=cam.clip_end, screen_window=window)


def _base_color(material):
    if material is None:
        return (0.8, 0.8, 0.8)
    if material.use_nodes and material.node_tree:
        for node in material.node_tree.nodes:
            if node.type in ("BSDF_PRINCIPLED", "BSDF_DIFFUSE"):
                return tuple(node.inputs["Base Color" if node.type == "BSDF_PRINCIPLED" else "Color"].default_value)[:3]
    return tuple(material.diffuse_color)[:3]


class _Materials:
    """One native material per Blender material (index 0: the default)."""

    def __init__(self, native_scene):
        self.native = native_scene
        self.index = {}
        native_scene.add_material(name="default", model="matte", color=[0.8, 0.8, 0.8], ka=1.0, kd=1.0)

    def get(self, material):
        if material is None:
            return 0
        key = material.name
        if key not in self.index:
            self.native.add_material(name=key, model="matte", color=list(_base_color(material)), ka=1.0, kd=1.0)
            self.index[key] = self.native.material_count - 1
        return self.index[key]


def _subdivision_cage(obj):
    """The original mesh when the object's only modifier is a Subdivision Surface."""
    mods = [m for m in obj.original.modifiers if m.show_render]
    if len(mods) == 1 and mods[0].type == "SUBSURF" and obj.original.type == "MESH":
        return obj.original.data, mods[0]
    return None, None


def export_mesh(native_scene, materials, obj, matrix):
    cage, subsurf = _subdivision_cage(obj)
    mesh = cage if cage is not None else obj.to_mesh()
    try:
        n_verts, n_polys, n_loops = len(mesh.vertices), len(mesh.polygons), len(mesh.loops)
        if n_polys == 0:
            return
        points = np.empty(n_verts * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", points)
        counts = np.empty(n_polys, dtype=np.int32)
        mesh.polygons.foreach_get("loop_total", counts)
        indices = np.empty(n_loops, dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", indices)
        mat_index = np.empty(n_polys, dtype=np.int32)
        mesh.polygons.foreach_get("material_index", mat_index)
        slots = [materials.get(slot.material) for slot in obj.material_slots] or [0]
        lut = np.array(slots, dtype=np.int32)
        face_materials = lut[np.clip(mat_index, 0, len(lut) - 1)]
        native_scene.add_mesh(obj.name, points.reshape(-1, 3), counts, indices,
                              subdivision=subsurf is not None, object_to_world=_matrix(matrix),
                              face_materials=face_materials,
                              boundary="edge_and_corner" if subsurf is None or subsurf.boundary_smooth == "ALL"
                              else "edge_only")
    finally:
        if cage is None:
            obj.to_mesh_clear()


def export_light(native_scene, obj, matrix):
    light = obj.data
    color = list(light.color)
    position = list(matrix.translation)
    direction = list((matrix.to_3x3() @ _z_down()).normalized())
    if light.type == "SUN":
        native_scene.add_light("distant", color=color, intensity=light.energy / math.pi, direction=direction)
    elif light.type == "SPOT":
        half = light.spot_size / 2.0
        native_scene.add_light("spot", color=color, intensity=light.energy / FOUR_PI_SQUARED, position=position,
                               direction=direction, cone_angle=half, cone_delta_angle=half * light.spot_blend,
                               beam_distribution=0.0)
    else:  # POINT, and AREA lights approximated by a point at their centre
        native_scene.add_light("point", color=color, intensity=light.energy / FOUR_PI_SQUARED, position=position)


def _z_down():
    from mathutils import Vector

    return Vector((0.0, 0.0, -1.0))


def export_scene(depsgraph):
    """Returns (native scene, warnings)."""
    scene = depsgraph.scene
    native_scene = _native.Scene()
    width, height = _render_size(scene)
    settings = native_scene.settings
    settings.width, settings.height = width, height
    settings.pixel_aspect = scene.render.pixel_aspect_y / scene.render.pixel_aspect_x
    if scene.render.use_border:
        r = scene.render
        settings.crop_x0, settings.crop_x1 = r.border_min_x, r.border_max_x
        settings.crop_y0, settings.crop_y1 = 1.0 - r.border_max_y, 1.0 - r.border_min_y
    export_camera(native_scene, scene, width, height)
    materials = _Materials(native_scene)
    world = scene.world
    if world is not None:
        native_scene.add_light("ambient", color=list(world.color), intensity=1.0)
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type == "MESH":
            export_mesh(native_scene, materials, obj, inst.matrix_world)
        elif obj.type == "LIGHT":
            export_light(native_scene, obj, inst.matrix_world)
    return native_scene
