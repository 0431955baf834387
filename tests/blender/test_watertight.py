"""Watertight dicing in Blender: closed single-sided surfaces (Material >
Backface Culling), Film > Transparent, 16 samples, from 50 seeded views each:
no pixel inside the silhouette has alpha below 1. Run:
  blender -b --factory-startup --python tests/blender/test_watertight.py
A failure names the object, the view and the seed that reproduce it."""
import math
import os
import random
import sys

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(__file__))
import render_utils as ru  # noqa: E402

SEED = 20261121
VIEWS = 50


def closed_objects(scene):
    """Subdivided Suzanne (head and eyes, holes filled), a Catmull-Clark cube, a torus with
    extraordinary vertices and a polygon sphere, each alone in the scene."""
    def finish(obj, subdivide):
        mat = ru.diffuse_material(obj.name + "_mat", (0.7, 0.6, 0.5))
        mat.use_backface_culling = True
        obj.data.materials.append(mat)
        if subdivide:
            obj.modifiers.new("Subdivision", "SUBSURF")
        return obj

    def only(make):
        for o in list(scene.objects):
            if o.type == "MESH":
                bpy.data.objects.remove(o)
        make()
        return bpy.context.active_object

    def torus():
        bpy.ops.mesh.primitive_torus_add(major_segments=16, minor_segments=8, minor_radius=0.4)
        obj = bpy.context.active_object
        for f in obj.data.polygons:
            f.select = f.index % 7 == 0
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.poke()  # fans of triangles: extraordinary vertices
        bpy.ops.object.mode_set(mode="OBJECT")
        return obj

    def closed_suzanne():
        # Suzanne is open around the eyes (42 boundary edges); single-sided, the
        # background would show through those real holes, so fill them.
        bpy.ops.mesh.primitive_monkey_add()
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.select_all(action="SELECT")
        bpy.ops.mesh.fill_holes(sides=0)
        bpy.ops.object.mode_set(mode="OBJECT")
        return bpy.context.active_object

    yield "subdivided Suzanne", finish(only(closed_suzanne), True), 1.4
    yield "Catmull-Clark cube", finish(only(bpy.ops.mesh.primitive_cube_add), True), 1.8
    yield "torus with extraordinary vertices", finish(only(torus), True), 1.5
    yield "polygon sphere", finish(only(lambda: bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12)),
                                   False), 1.0


def view(rng, radius):
    while True:
        d = Vector((rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)))
        if 0.2 < d.length <= 1.0:
            break
    d.normalize()
    close = rng.random() < 0.4
    distance = radius * (1.6 + 0.6 * rng.random() if close else 2.2 + 4.0 * rng.random())
    target = Vector((0, 0, 0))
    if close:
        jitter = Vector((rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)))
        target = 0.7 * radius * (d + 0.5 * jitter).normalized()
    lens = 25.0 + 35.0 * rng.random()
    return d * distance, target, lens


def main():
    scene = ru.reset_scene()
    rng = random.Random(SEED)
    failures = []
    for name, obj, radius in closed_objects(scene):
        interior_views = 0
        for k in range(VIEWS):
            for o in list(scene.objects):
                if o.type == "CAMERA":
                    bpy.data.objects.remove(o)
            location, target, lens = view(rng, radius)
            cam = ru.add_camera(scene, location, target, lens=lens)
            cam.data.clip_start = 0.001
            out = ru.render_passes(scene, "MICROPOLY", 120, 90, samples=16)
            holes, covered = ru.pinholes(out["rgba"], out["depth"])
            interior_views += covered > 200
            if holes:
                failures.append(f"{name}, view {k} of seed {SEED}: {holes} pixels inside the silhouette below alpha 1")
        print(f"{name}: {VIEWS} views, {interior_views} with more than 200 covered pixels")
        if interior_views < 40:
            failures.append(f"{name}: only {interior_views} views show the object")
    if failures:
        raise AssertionError("\n".join(failures))
    print("watertight: OK")


main()
