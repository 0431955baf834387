# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender lights and world -> native lights, in Cycles' units.

Native lights carry radiant intensity (point, spot), irradiance (sun) and
radiance (area, ambient); the Principled material applies albedo / pi.
Cycles: a point or spot light of power P emits P / (4 pi) W/sr; a sun of
strength S gives irradiance S; an area light of power P and area A emits
radiance P / (pi A) from its front (-Z) side since Blender 4.0, and P / (4 A)
before (both measured against Cycles). See docs/blender.md."""

import math

import bpy

import numpy as np
from mathutils import Vector

from . import node_compiler


def _world_shader(world):
    """The world's active World Output and the node feeding its Surface
    (past reroutes), or (output, None), or (None, None)."""
    outputs = [n for n in world.node_tree.nodes
               if n.type == "OUTPUT_WORLD" and getattr(n, "target", "ALL") in ("ALL", "CYCLES")]
    out = next((n for n in outputs if n.is_active_output), outputs[0] if outputs else None)
    if out is None:
        return None, None
    return out, node_compiler.linked_from(out.inputs["Surface"])[0]


def _ray_visibility(world):
    """Camera, diffuse and glossy visibility: Object-like ray visibility on
    the world from Blender 3.0 (world.visible_camera ...), else all on."""
    vis = getattr(world, "cycles_visibility", None)
    get = lambda name: bool(getattr(world, f"visible_{name}", getattr(vis, name, True)))
    return get("camera"), get("diffuse"), get("glossy")


# A uniform world's map (equirectangular, texels): the world lighting needs
# no more for a constant (its glossy maps stop at 8 texels wide).
UNIFORM_WORLD_MAP = (16, 32)


def export_world(native_scene, world, materials=None, warnings=None, film_transparent=False):
    """The world: a uniform color as a constant map; a Background whose color
    or strength comes from nodes (an HDRI, a gradient), or a tree of
    Backgrounds mixed or added, as a world program baked into an
    environment map. Both light the scene through the same occluded world
    lighting (native world_lighting.h: probe suns the scene shadows), so no
    world adds unshadowed light. Returns the background color (for a uniform
    world; a baked world's background comes with the render result)."""
    if world is None:
        return np.zeros(3, dtype=np.float32)
    color = np.array(list(world.color)[:3], dtype=np.float32)
    if world.use_nodes and world.node_tree is not None:
        output, shader = _world_shader(world)
        # A Background of plain values is a uniform world (a constant map); one fed
        # by nodes, or a tree of shaders (a Mix Shader of two Backgrounds by
        # Light Path), is compiled and baked.
        compiled = shader is not None and shader.type in ("BACKGROUND", "EMISSION", "MIX_SHADER", "ADD_SHADER",
                                                           "GROUP")
        plain = compiled and shader.type == "BACKGROUND" and not shader.mute and not (
            shader.inputs["Color"].is_linked or shader.inputs["Strength"].is_linked)
        if compiled and not plain and materials is not None:
            compiler = node_compiler.NodeCompiler(world, materials.warnings, resources=materials)
            source = compiler.compile_world(output)
            program = native_scene.add_material_program("world " + world.name, source)
            camera, diffuse, glossy = _ray_visibility(world)
            camera = camera and not film_transparent  # behind objects only on an opaque film
            native_scene.set_world(program=program, camera=camera, diffuse=float(diffuse),
                                   glossy=float(glossy), program_params=compiler.params)
            return np.zeros(3, dtype=np.float32)
        if compiled and shader.type == "BACKGROUND" and not shader.mute:  # plain, or nothing to compile with
            color = np.array(list(shader.inputs["Color"].default_value)[:3], dtype=np.float32)
            color *= float(shader.inputs["Strength"].default_value)
        elif shader is not None and not compiled and warnings is not None:
            warnings.append(f"world '{world.name}': a {shader.bl_label} node at its output is not supported; "
                            "its viewport color lights the scene")
    if np.any(color > 0):
        _, diffuse, glossy = _ray_visibility(world)
        radiance = np.empty(UNIFORM_WORLD_MAP + (4,), dtype=np.float32)
        radiance[..., :3] = color
        radiance[..., 3] = 1.0
        # The camera sees the returned colour; the map only lights.
        native_scene.set_world(radiance=radiance, camera=False, diffuse=float(diffuse), glossy=float(glossy))
    return color


def _spot_cone(spot_size, spot_blend):
    """Cycles' spot mask: smoothstep from cos(size/2) over a blend of
    (1 - cos(size/2)) * blend, written as RenderMan-style cone angles."""
    outer = spot_size / 2.0
    cos_outer = math.cos(outer)
    cos_inner = min(1.0, cos_outer + (1.0 - cos_outer) * spot_blend)
    return outer, outer - math.acos(cos_inner)


def casts_shadow(light):
    """The light's Cast Shadow toggle as Cycles reads it: light.cycles.cast_shadow
    in Blender 3.x (light.use_shadow there is EEVEE's), light.use_shadow from 4.0."""
    cycles = getattr(light, "cycles", None)
    if cycles is not None and hasattr(cycles, "cast_shadow"):
        return bool(cycles.cast_shadow)
    return bool(getattr(light, "use_shadow", True))


def _shadow_settings(light):
    """What shapes a light's shadows: its cast-shadow toggle and its size
    (Radius of point and spot lights, with Soft Falloff from Blender 4.1;
    Angle of suns; area lights' size is their shape)."""
    s = {"cast_shadows": casts_shadow(light)}
    if light.type in ("POINT", "SPOT"):
        s["radius"] = max(float(light.shadow_soft_size), 0.0)
        s["soft_falloff"] = bool(getattr(light, "use_soft_falloff", True))
    elif light.type == "SUN":
        s["angle"] = min(max(float(light.angle), 0.0), math.pi)
    return s


def export_light(native_scene, obj, matrix, warnings):
    light = obj.data
    color = list(light.color)
    position = list(matrix.translation)
    rotation = matrix.to_3x3()
    direction = list((rotation @ Vector((0.0, 0.0, -1.0))).normalized())
    power = float(light.energy)
    shadows = _shadow_settings(light)
    if light.type == "SUN":
        native_scene.add_light("distant", color=color, intensity=power, direction=direction, **shadows)
    elif light.type == "POINT":
        native_scene.add_light("point", color=color, intensity=power / (4.0 * math.pi), position=position,
                               **shadows)
    elif light.type == "SPOT":
        cone, delta = _spot_cone(light.spot_size, light.spot_blend)
        # Cycles in Blender 3.x also weights the cone by cos(angle to the axis).
        native_scene.add_light("spot", color=color, intensity=power / (4.0 * math.pi), position=position,
                               direction=direction, cone_angle=cone, cone_delta_angle=delta,
                               beam_distribution=1.0 if bpy.app.version < (4, 0, 0) else 0.0, **shadows)
    elif light.type == "AREA":
        scale = matrix.to_scale()
        size_u = light.size * abs(scale.x)
        size_v = (light.size_y if light.shape in ("RECTANGLE", "ELLIPSE") else light.size) * abs(scale.y)
        area = size_u * size_v * (math.pi / 4.0 if light.shape in ("DISK", "ELLIPSE") else 1.0)
        if area <= 0.0:
            warnings.append(f"area light '{obj.name}' has no area and is skipped")
            return
        axis_u = list((rotation @ Vector((1.0, 0.0, 0.0))).normalized())
        # Cycles changed its area light normalisation in Blender 4.0.
        radiance = power / ((math.pi if bpy.app.version >= (4, 0, 0) else 4.0) * area)
        native_scene.add_light("area", color=color, intensity=radiance, position=position,
                               direction=direction, shape="ellipse" if light.shape in ("DISK", "ELLIPSE")
                               else "rectangle", axis_u=axis_u, size_u=size_u, size_v=size_v, **shadows)
