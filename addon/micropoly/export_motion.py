"""Motion blur: the scene at the motion steps of the shutter.

Render > Motion Blur as Cycles reads it: the shutter lasts
`motion_blur_shutter` frames and starts at the frame (START), is centred on
it (CENTER) or ends at it (END); the position is a Render setting from 4.x
and a Cycles one before. The scene is evaluated (RenderEngine.frame_set) at
2^steps + 1 times evenly spread over the shutter, like Cycles' object motion
steps, and the camera's transform, each object's transform and, where it
deforms, its points are kept per step; so are the strands of particle
hair (per object and system) and the points of point clouds. The native scene moves linearly between
steps; shading uses the shutter's centre, at which the scene is exported
last. The shutter curve shapes when samples see the scene. Instances
(geometry nodes, particles) move by their transforms.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from . import camera_view, export_mesh, export_particle_hair


def shutter_position(scene):
    owner = scene.render if hasattr(scene.render, "motion_blur_position") else getattr(scene, "cycles", None)
    return getattr(owner, "motion_blur_position", "CENTER")


def step_times(scene):
    """Frame times (floats) of the motion steps, or [] without motion blur."""
    r = scene.render
    if not r.use_motion_blur or not r.motion_blur_shutter > 0.0:
        return []
    steps = 2 ** scene.micropoly.motion_steps + 1
    shutter = r.motion_blur_shutter
    frame = scene.frame_current + scene.frame_subframe
    position = shutter_position(scene)
    first = frame if position == "START" else frame - shutter if position == "END" else frame - 0.5 * shutter
    return [first + shutter * k / (steps - 1) for k in range(steps)]


CURVE_SAMPLES = 65


def shutter_curve(scene):
    """Render > Motion Blur > Shutter Curve sampled evenly over the shutter,
    or an empty array where it is flat (fully open throughout)."""
    mapping = getattr(scene.render, "motion_blur_shutter_curve", None)
    if mapping is None or not mapping.curves:
        return np.zeros(0, dtype=np.float32)
    mapping.initialize()
    values = np.array([mapping.evaluate(mapping.curves[0], k / (CURVE_SAMPLES - 1)) for k in range(CURVE_SAMPLES)],
                      dtype=np.float32)
    values = np.maximum(values, 0.0)
    if np.all(values == values[0]) or not values.sum() > 0.0:
        return np.zeros(0, dtype=np.float32)
    return values


def frame_set(setter, time):
    """setter(frame, subframe): RenderEngine.frame_set, or the scene's."""
    frame = math.floor(time)
    setter(int(frame), float(time - frame))


def _object_blurs(obj):
    """Object > Motion Blur (Cycles' per-object switch, where present)."""
    settings = getattr(obj, "cycles", None)
    return bool(getattr(settings, "use_motion_blur", True))


def _points(obj, depsgraph):
    if obj.type in ("CURVES", "POINTCLOUD"):  # their points, as export_curves and export_points read them
        positions = obj.data.attributes["position"].data
        points = np.empty(len(positions) * 3, dtype=np.float32)
        positions.foreach_get("vector", points)
        return points.reshape(-1, 3)
    subsurf, only = export_mesh.subdivision_modifier(obj)
    if subsurf is not None and only:
        return export_mesh.cage_points(obj, depsgraph)
    mesh = obj.to_mesh()
    try:
        points = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", points)
    finally:
        obj.to_mesh_clear()
    return points.reshape(-1, 3)


def instance_key(inst):
    """What names a depsgraph instance from one motion step to the next:
    its instancer, its persistent id (the instance's path through nested
    instancers) and the object it places."""
    parent = inst.parent
    return (parent.name if parent is not None else "", tuple(inst.persistent_id), inst.object.name)


def _rows(m):
    """A matrix as a tuple of its rows, flat (far cheaper than numpy.array
    of a Matrix, which matters per instance)."""
    return (*m[0], *m[1], *m[2], *m[3])


@dataclass
class Motion:
    """What moves during the shutter: per step the camera's world-to-camera
    matrix, per object name its matrices and (deforming) points, and per
    depsgraph instance (instance_key) its matrices, as (steps, 4, 4) arrays
    of rows."""
    times: list
    camera: np.ndarray = None
    curve: np.ndarray = None
    matrices: dict = field(default_factory=dict)
    points: dict = field(default_factory=dict)
    hair: dict = field(default_factory=dict)  # (object, particle system) name -> (steps, points, 3)
    # Point clouds by instance_key: ((steps, 4, 4) matrices or None, (steps, points, 3) positions or None).
    clouds: dict = field(default_factory=dict)
    instances: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)

    def apply(self, native_scene):
        empty = np.zeros(0, dtype=np.float32)
        native_scene.set_motion(len(self.times), camera_world_to_camera=self.camera if self.camera is not None else empty,
                                shutter_curve=self.curve if self.curve is not None else empty)

    def apply_to_mesh(self, native_scene, name):
        """Motion of the native scene's last mesh, the object `name`'s."""
        matrices, points = self.matrices.get(name), self.points.get(name)
        if matrices is None and points is None:
            return
        empty = np.zeros(0, dtype=np.float32)
        native_scene.set_mesh_motion(-1, points=empty if points is None else points,
                                     object_to_world=empty if matrices is None else matrices)


def sample(setter, depsgraph, times):
    """Evaluates the scene at each time (leaving it at the last) and returns
    its Motion; what does not move is left out."""
    camera, matrices, points, hair, instances, clouds = [], {}, {}, {}, {}, {}
    render = depsgraph.mode == "RENDER"
    for time in times:
        frame_set(setter, time)
        scene = depsgraph.scene
        camera.append(camera_view.view_matrix(scene.camera.evaluated_get(depsgraph)))
        for inst in depsgraph.object_instances:
            obj = inst.object
            if obj.type == "POINTCLOUD" and _object_blurs(obj):
                # Instances or not (Geometry Nodes' points come as instances):
                # the transform and the points at each step.
                clouds.setdefault(instance_key(inst), []).append((np.array(inst.matrix_world, dtype=np.float32),
                                                                  _points(obj, depsgraph)))
                continue
            if obj.type not in ("MESH", "CURVES") or not _object_blurs(obj):
                continue
            if inst.is_instance:  # its transform only: a prototype does not deform
                instances.setdefault(instance_key(inst), []).append(_rows(inst.matrix_world))
                continue
            matrices.setdefault(obj.name, []).append(np.array(inst.matrix_world, dtype=np.float32))
            points.setdefault(obj.name, []).append(_points(obj, depsgraph))
            for psys in export_particle_hair.hair_systems(obj):
                strands = export_particle_hair.strands(obj, psys, render)
                if strands is not None:
                    hair.setdefault((obj.name, psys.name), []).append(strands[0].reshape(-1, 3))
    motion = Motion(times=times, curve=shutter_curve(depsgraph.scene))
    camera = np.stack(camera)
    motion.camera = camera if not np.all(camera == camera[0]) else None
    for key, steps in instances.items():
        if len(steps) == len(times) and any(s != steps[0] for s in steps):  # else: rendered still
            motion.instances[key] = np.asarray(steps, dtype=np.float32).reshape(-1, 4, 4)
    for key, steps in clouds.items():
        if len(steps) != len(times) or len({p.shape for _, p in steps}) != 1:
            motion.warnings.append(f"point cloud '{key[-1]}' changes its points during the shutter: it renders "
                                   "without motion blur")
            continue
        at = np.stack([m for m, _ in steps])
        positions = np.stack([p for _, p in steps])
        moving = (None if np.all(at == at[0]) else at, None if np.all(positions == positions[0]) else positions)
        if moving[0] is not None or moving[1] is not None:
            motion.clouds[key] = moving
    for key, steps in hair.items():
        if len(steps) != len(times) or len({s.shape for s in steps}) != 1:
            motion.warnings.append(f"particle hair '{key[0]}/{key[1]}' changes its strands during the shutter: "
                                   "it renders without deformation blur")
            continue
        stacked = np.stack(steps)
        if not np.all(stacked == stacked[0]):
            motion.hair[key] = stacked
    for name, steps in matrices.items():
        if len(steps) != len(times):
            continue  # not in every step: rendered still
        stacked = np.stack(steps)
        if not np.all(stacked == stacked[0]):
            motion.matrices[name] = stacked
        counts = {p.shape[0] for p in points[name]}
        if len(counts) != 1:
            motion.warnings.append(f"'{name}' changes its vertex count during the shutter: it renders without "
                                   "deformation blur")
            continue
        stacked = np.stack(points[name])
        if not np.all(stacked == stacked[0]):
            motion.points[name] = stacked
    return motion
