# SPDX-License-Identifier: GPL-3.0-or-later
"""Particle hair (hair particle systems on meshes, with their guide-
interpolated children) -> the same round tubes as Curves objects: each
strand's points from the particle system's path cache, its radius from the
particle settings' Hair Shape, as Cycles reads them (a strand is the
children when there are any, else the parents; 2^steps + 1 points each, the
render steps for F12 and the viewport's in the viewport; radius_scale / 2
times a root-to-tip blend bent by Shape, zero at a closed tip).

Blender's Python API hands out the path cache one point at a time
(ParticleSystem.co_hair); reading it is the one per-point loop in the
export, about 1 s per million points. A material that reads a UV map gets
each strand's root UV on the emitter (ParticleSystem.uv_on_emitter, one
call per strand, as Cycles reads it). Hair Info is computed as for Curves
objects, the strands of all the object's systems numbered in one run;
attributes read zero (Cycles gives the emitter's colour attributes)."""

import numpy as np

from . import export_attributes, export_curves


def _shape_radius(shape, root, tip, t):
    """Cycles' radius along a strand at arc-length fraction t."""
    r = 1.0 - t
    if shape < 0.0:
        r = r ** (1.0 + shape)
    elif shape > 0.0:
        r = r ** (1.0 / (1.0 - shape))
    return r * (root - tip) + tip


def strands(obj, psys, render):
    """(positions (n, steps, 3) object space, radii (n, steps)) of one hair
    particle system of evaluated object `obj`, or None for none. The path
    cache is in world space; the positions are brought into the object's."""
    s = psys.settings
    parents, children = len(psys.particles), len(psys.child_particles)
    if s.child_type != "NONE" and children > 0:
        first, count = parents, children
    else:
        first, count = 0, parents
    steps = (1 << (s.render_step if render else s.display_step)) + 1
    if count == 0:
        return None
    co_hair = psys.co_hair
    pos = np.fromiter((c for p in range(first, first + count) for k in range(steps)
                       for c in co_hair(obj, particle_no=p, step=k)), dtype=np.float32, count=count * steps * 3)
    to_object = np.array(obj.matrix_world.inverted_safe(), dtype=np.float64)
    pos = (pos.reshape(-1, 3).astype(np.float64) @ to_object[:3, :3].T + to_object[:3, 3]).astype(np.float32)
    pos = pos.reshape(count, steps, 3)
    seg = np.linalg.norm(np.diff(pos, axis=1), axis=2)
    length = np.concatenate([np.zeros((count, 1), np.float32), np.cumsum(seg, axis=1)], axis=1)
    total = length[:, -1:]
    t = np.divide(length, total, out=np.zeros_like(length), where=total > 0.0)
    half = 0.5 * s.radius_scale
    radii = _shape_radius(s.shape, half * s.root_radius, half * s.tip_radius, t).astype(np.float32)
    if s.use_close_tip:
        radii[:, -1] = 0.0
    return pos, radii


def _root_uvs(obj, psys, name):
    """(strands, 2): each strand's root UV on the emitter in UV map `name`
    ("" the active render one), or None where the mesh has no such map."""
    layers = obj.data.uv_layers
    names = [layer.name for layer in layers]
    if not name:
        name = next((layer.name for layer in layers if layer.active_render), None)
    modifier = next((m for m in obj.modifiers if m.type == "PARTICLE_SYSTEM" and m.particle_system == psys), None)
    if name not in names or modifier is None:
        return None
    parents, children = len(psys.particles), len(psys.child_particles)
    first, count = (parents, children) if psys.settings.child_type != "NONE" and children > 0 else (0, parents)
    # Children take their UV from the system; the particle handed over is
    # the first, as Cycles hands it.
    particles = psys.particles
    uv_no = names.index(name)
    uv = np.fromiter((c for p in range(first, first + count)
                      for c in psys.uv_on_emitter(modifier, particles[p if p < parents else 0], particle_no=p,
                                                  uv_no=uv_no)), dtype=np.float32, count=2 * count)
    return uv.reshape(count, 2)


def hair_systems(obj):
    """The particle systems of `obj` that render as hair strands (hair
    rendered as objects or collections reaches the export as depsgraph
    instances; emitter particles are not hair)."""
    return [p for p in getattr(obj, "particle_systems", ()) if p.settings.type == "HAIR" and
            p.settings.render_type == "PATH"]


def export_particle_hair(native_scene, materials, inst, matrix, warnings, render, motion=None, as_ribbons=True):
    """Adds the hair particle systems of the mesh object `inst` renders;
    returns how many were added."""
    obj = inst.object
    added = 0
    first_curve = 0  # Hair Info's random numbers the strands of all systems in one run
    for psys in hair_systems(obj):
        s = psys.settings
        got = strands(obj, psys, render)
        if got is None:
            continue
        pos, radii = got
        count, steps = radii.shape
        args = export_attributes.object_arguments(obj, inst, materials)
        slots = obj.material_slots
        if 1 <= s.material <= len(slots):
            args["material"] = materials.get(slots[s.material - 1].material)
        moving = {}
        if motion is not None:
            # Its strands and its object's transform at each step, where they move.
            empty = np.zeros(0, dtype=np.float32)
            steps_points, matrices = motion.hair.get((obj.name, psys.name)), motion.matrices.get(obj.name)
            if steps_points is not None and steps_points.shape[1] != count * steps:
                steps_points = None  # the shutter's centre has other strands
            moving = dict(motion_points=empty if steps_points is None else steps_points,
                          motion_object_to_world=empty if matrices is None else matrices)
        offsets = np.arange(0, (count + 1) * steps, steps, dtype=np.int32)
        positions, radii = pos.reshape(-1, 3), radii.reshape(-1)

        def root_uv(name):
            uv = _root_uvs(obj, psys, name)
            return None if uv is None else np.repeat(uv, steps, axis=0)
        layers = export_curves.point_layers(
            materials.uv_names, len(positions),
            export_curves.hair_info(positions, offsets, radii, export_curves.transform_scale(matrix), first_curve),
            lambda name: None, root_uv)
        first_curve += count
        skipped = native_scene.add_curves(f"{obj.name}/{psys.name}", positions, radii, offsets,
                                          object_to_world=matrix, point_layers=layers, ribbons=as_ribbons,
                                          **args, **moving)
        if skipped:
            warnings.append(f"particle hair '{obj.name}/{psys.name}': {skipped} strands with a point that is not "
                            "finite are skipped")
        added += skipped < count
    return added
