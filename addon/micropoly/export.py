# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender depsgraph -> micropoly._native.Scene.

Mesh data goes through foreach_get into numpy arrays (no per-vertex Python).
A Subdivision Surface modifier last in an object's stack is not applied: the
mesh before it is rendered as the exact Catmull-Clark limit surface, with the
modifier's boundary and crease settings. Lights, world and materials follow
Cycles' units (docs/blender.md), so that a diffuse scene lit directly matches
Cycles.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from . import (_native, camera_view, export_attributes, export_instances, export_lights, export_materials,
               export_curves, export_mesh, export_motion, export_particle_hair, export_points)


class ExportError(Exception):
    """A scene Micropoly cannot render, with a message for the artist."""


@dataclass
class ExportedScene:
    scene: object
    width: int
    height: int
    warnings: list = field(default_factory=list)
    background: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.float32))
    objects: int = 0
    transparent: bool = False  # Film > Transparent: no world colour behind objects

    @property
    def summary(self):
        return f"{self.objects} objects"

    def crop_origin_bottom_left(self, width, height):
        """Where a (crop) result of width x height starts in Blender's bottom-up pixels."""
        s = self.scene.settings
        x0 = int(math.floor(s.crop_x0 * self.width))
        y_top = int(math.floor(s.crop_y0 * self.height))
        return x0, self.height - y_top - height


def render_size(scene):
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(1, int(r.resolution_x * scale)), max(1, int(r.resolution_y * scale))


def _matrix(m):
    return np.array(m, dtype=np.float32).reshape(4, 4)


def export_camera(native_scene, scene, camera_object, width, height):
    """Blender's view plane (BKE_camera_params_compute_viewplane) as a screen
    window at unit distance (perspective) or in scene units (orthographic)."""
    cam = camera_object.data
    r = scene.render
    frame_w, frame_h = width * r.pixel_aspect_x, height * r.pixel_aspect_y
    fit = cam.sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if frame_w >= frame_h else "VERTICAL"
    if cam.type == "ORTHO":
        extent = cam.ortho_scale
    else:
        sensor = cam.sensor_height if (cam.sensor_fit == "VERTICAL") else cam.sensor_width
        extent = sensor / cam.lens
    if fit == "HORIZONTAL":
        view_w, view_h = extent, extent * frame_h / frame_w
    else:
        view_w, view_h = extent * frame_w / frame_h, extent
    # Shift is in units of the larger side of the view plane.
    shift_scale = max(view_w, view_h)
    cx, cy = cam.shift_x * shift_scale, cam.shift_y * shift_scale
    window = [cx - view_w / 2, cx + view_w / 2, cy - view_h / 2, cy + view_h / 2]
    if cam.type not in ("PERSP", "ORTHO"):
        raise ExportError(f"camera '{camera_object.name}' is {cam.type.lower()}; Micropoly renders "
                          "perspective and orthographic cameras")
    try:
        view = camera_view.view_matrix(camera_object)
    except ValueError as e:
        raise ExportError(str(e)) from None
    native_scene.set_camera(view, orthographic=cam.type == "ORTHO",
                            fov_degrees=90.0, clip_near=max(cam.clip_start, 1e-6), clip_far=cam.clip_end,
                            screen_window=window)
    export_depth_of_field(native_scene, camera_object)


def _focus_point(dof):
    """World position of the depth of field's focus object (its bone's head
    where a bone is named, Blender 4.x's focus_subtarget), or None."""
    target = dof.focus_object
    if target is None:
        return None
    bone = getattr(dof, "focus_subtarget", "")
    if bone and target.type == "ARMATURE" and bone in target.pose.bones:
        return target.matrix_world @ target.pose.bones[bone].head
    return target.matrix_world.translation


def export_depth_of_field(native_scene, camera_object):
    """The camera's Depth of Field as Cycles reads it (blender/camera.cpp):
    aperture radius = focal length / (2 f-stop) in scene units (the lens in
    millimetres), the focus distance along the view axis (to the focus
    object when one is set), blades < 3 a round aperture. Orthographic
    cameras render without it (docs/blender.md)."""
    cam = camera_object.data
    dof = cam.dof
    if not dof.use_dof or cam.type != "PERSP":
        native_scene.set_depth_of_field(0.0, 1.0)
        return
    focus = dof.focus_distance
    point = _focus_point(dof)
    if point is not None:
        axis = camera_object.matrix_world.to_3x3().col[2].normalized()
        focus = abs(axis.dot(point - camera_object.matrix_world.translation))
    radius = cam.lens * 1e-3 / (2.0 * max(dof.aperture_fstop, 1e-5))
    native_scene.set_depth_of_field(radius, max(focus, 1e-5), dof.aperture_blades, dof.aperture_rotation,
                                    dof.aperture_ratio)


@dataclass
class ViewCamera:
    """A view to render instead of the scene camera (the 3D viewport's):
    world_to_camera looks down -Z; screen_window is (left, right, bottom,
    top) at unit distance (perspective) or in scene units (orthographic);
    crop is (x0, x1, y0, y1) as fractions of the image, y0 at the top."""
    width: int
    height: int
    world_to_camera: np.ndarray
    orthographic: bool
    screen_window: tuple
    clip_near: float
    clip_far: float
    crop: tuple = None
    lens_camera: object = None  # looking through the scene camera: its Depth of Field applies

    def apply(self, native_scene):
        native_scene.set_camera(self.world_to_camera, orthographic=self.orthographic, fov_degrees=90.0,
                                clip_near=self.clip_near, clip_far=self.clip_far,
                                screen_window=list(self.screen_window))
        if self.lens_camera is not None and not self.orthographic:
            export_depth_of_field(native_scene, self.lens_camera)
        s = native_scene.settings
        s.width, s.height, s.pixel_aspect = self.width, self.height, 1.0
        s.crop_x0, s.crop_x1, s.crop_y0, s.crop_y1 = self.crop or (0.0, 1.0, 0.0, 1.0)


def pixel_filter_support(filter_type, width):
    """The native filter's full support for Blender's Filter Width, as Cycles
    reads that width: its Blackman-Harris reaches `width` on each side of
    the pixel centre (Cycles doubles the width; docs/blender-conventions.md
    section 4), where the native filter's width is the whole support, as
    RenderMan's are."""
    return 2.0 * width if filter_type == "BLACKMAN_HARRIS" else width


def export_settings(native_scene, scene, width, height):
    settings = native_scene.settings
    mp = scene.micropoly
    r = scene.render
    settings.width, settings.height = width, height
    settings.pixel_aspect = r.pixel_aspect_y / r.pixel_aspect_x
    if r.use_border:
        settings.crop_x0, settings.crop_x1 = r.border_min_x, r.border_max_x
        settings.crop_y0, settings.crop_y1 = 1.0 - r.border_max_y, 1.0 - r.border_min_y
    settings.samples = mp.samples
    settings.shading_rate = mp.shading_rate
    settings.max_grid_size = mp.max_grid_size
    settings.filter = getattr(_native.PixelFilter, mp.filter_type)
    settings.filter_width = pixel_filter_support(mp.filter_type, mp.filter_width)
    settings.bound_split = getattr(_native.BoundSplitMethod, mp.bound_split_method)
    settings.bound_split_memory_mib = mp.bound_split_memory
    settings.occlusion_culling = mp.use_occlusion_culling
    settings.sample_culling = mp.use_sample_culling
    # An opaque film lays the world behind by alpha: held-out samples count
    # as covered so it shows nowhere through a Holdout, as in Cycles.
    settings.holdout_covers = not r.film_transparent
    settings.shadows = mp.use_shadows
    settings.shadow_memory_mib = mp.shadow_memory
    settings.shadow_shading_rate = mp.shadow_shading_rate
    settings.world_probes = mp.world_shadow_directions
    settings.dof_dice_factor = mp.dof_dice_factor
    settings.texture_filter_width = mp.texture_filter_width
    settings.sample_memory_mib = mp.sample_memory


def export_final(depsgraph, frame_set):
    """export_scene for a final frame (F12, RIB export): with Render > Motion
    Blur, the scene is first evaluated at every motion step, then exported at
    the shutter's centre (frame_set(frame, subframe) moves it: the render
    engine's, or the scene's); the frame is restored afterwards."""
    scene = depsgraph.scene
    frame, subframe = scene.frame_current, scene.frame_subframe
    times = export_motion.step_times(scene)
    if not times:
        return export_scene(depsgraph)
    try:
        motion = export_motion.sample(frame_set, depsgraph, times)
        export_motion.frame_set(frame_set, 0.5 * (times[0] + times[-1]))
        return export_scene(depsgraph, motion=motion)
    finally:
        frame_set(frame, subframe)


def export_scene(depsgraph, view=None, meshes=None, motion=None):
    """Returns an ExportedScene; raises ExportError for scenes that cannot render.
    view: a ViewCamera to render instead of the scene camera (the viewport);
    meshes: a MeshCache kept between exports (the viewport's), else a new one;
    motion: an export_motion.Motion (final renders with motion blur)."""
    scene = depsgraph.scene
    camera = scene.camera
    if camera is None and view is None:
        raise ExportError("the scene has no active camera")
    width, height = render_size(scene) if view is None else (view.width, view.height)
    native_scene = _native.Scene()
    out = ExportedScene(scene=native_scene, width=width, height=height,
                        transparent=scene.render.film_transparent)
    export_settings(native_scene, scene, width, height)
    if view is None:
        export_camera(native_scene, scene, camera.evaluated_get(depsgraph), width, height)
    else:
        view.apply(native_scene)
    if motion is not None:
        try:
            motion.apply(native_scene)
        except RuntimeError as e:
            raise ExportError(f"motion blur: {e}") from e
        out.warnings.extend(motion.warnings)
    materials = export_materials.MaterialTable(native_scene, out.warnings)
    meshes = meshes if meshes is not None else export_mesh.MeshCache()
    out.background = export_lights.export_world(native_scene, scene.world, materials, out.warnings,
                                                film_transparent=scene.render.film_transparent)
    # Materials first: their node programs decide which UV maps meshes export.
    # Meanwhile, objects that share their mesh with others (linked
    # duplicates) are counted: without motion blur they become instances
    # (with it, each renders as an object of its own, deforming or not;
    # depsgraph instances stay instances and move by their transforms).
    shared = {}
    seen = set()
    used = {}  # the materials of every surface, compiled before any geometry
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type in ("MESH", "CURVES", "POINTCLOUD"):
            # The UV layers, attributes and Hair Info values a surface
            # carries are those the materials ask for.
            pointers = (obj.as_pointer(), obj.data.as_pointer())
            if pointers not in seen:  # thousands of instances of one object: its materials once
                seen.add(pointers)
                used.update((slot.material, None) for slot in obj.material_slots)
                materials.point_clouds = materials.point_clouds or obj.type == "POINTCLOUD"
        if obj.type == "MESH":
            if motion is None and not inst.is_instance:
                key = export_instances.InstanceTable.key(inst.object, shared_data=True)
                if key is not None:
                    shared[key] = shared.get(key, 0) + 1
    for material in used:
        materials.get(material)
    instances = export_instances.InstanceTable(
        motion, export_attributes.InstanceAttributes(materials.object_attributes, out.warnings))
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type == "MESH" and not inst.is_instance and len(obj.particle_systems) and \
                getattr(inst, "show_particles", True):
            try:
                out.objects += export_particle_hair.export_particle_hair(
                    native_scene, materials, inst, _matrix(inst.matrix_world), out.warnings,
                    depsgraph.mode == "RENDER", motion, as_ribbons=export_curves.ribbons(scene))
            except RuntimeError as e:
                raise ExportError(f"particle hair of '{obj.name}': {e}") from e
        # An instancer whose own geometry is hidden (a particle emitter with
        # Show Emitter off for renders; Cycles reads the same flag).
        if obj.type == "MESH" and not getattr(inst, "show_self", True):
            continue
        if obj.type == "MESH":
            try:
                key = None if inst.is_instance or motion is not None else \
                    export_instances.InstanceTable.key(obj, shared_data=True)
                if inst.is_instance or shared.get(key, 0) > 1:
                    # Instances, and objects that share their mesh, place one prototype per mesh.
                    if instances.add(native_scene, materials, meshes, inst, out.warnings, depsgraph, key=key):
                        out.objects += 1
                elif export_mesh.export_object(native_scene, materials, meshes, obj, _matrix(inst.matrix_world),
                                               out.warnings, depsgraph=depsgraph):
                    out.objects += 1
                    if motion is not None:
                        motion.apply_to_mesh(native_scene, obj.name)
            except RuntimeError as e:  # numpy/native rejections of the data
                raise ExportError(f"object '{obj.name}': {e}") from e
            except MemoryError:
                raise ExportError(
                    f"the computer ran out of memory exporting object '{obj.name}' after {out.objects} mesh "
                    "objects: render fewer or lighter objects, or lower their subdivision levels") from None
        elif obj.type == "CURVES":
            try:
                if inst.is_instance:  # fur on scattered creatures: one prototype per curves data
                    if instances.add(native_scene, materials, meshes, inst, out.warnings, depsgraph):
                        out.objects += 1
                elif export_curves.export_curves(native_scene, materials, inst, _matrix(inst.matrix_world), out.warnings,
                                                 motion, as_ribbons=export_curves.ribbons(scene)):
                    out.objects += 1
            except RuntimeError as e:
                raise ExportError(f"curves '{obj.name}': {e}") from e
        elif obj.type == "POINTCLOUD":
            try:
                if export_points.export_point_cloud(native_scene, materials, inst, _matrix(inst.matrix_world),
                                                    out.warnings, motion):
                    out.objects += 1
            except RuntimeError as e:
                raise ExportError(f"point cloud '{obj.name}': {e}") from e
        elif obj.type == "LIGHT":
            export_lights.export_light(native_scene, obj, inst.matrix_world, out.warnings)
    try:
        instances.flush(native_scene)
    except RuntimeError as e:
        raise ExportError(f"instances: {e}") from e
    try:
        native_scene.validate()
    except RuntimeError as e:
        raise ExportError(str(e)) from e
    if out.objects == 0:
        out.warnings.append("the scene has no mesh objects to render")
    return out
