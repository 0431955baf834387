"""The GPU frame's benchmark scenes, built in Blender and written as RIB for
the CLI (bench/out/outdoor.rib, bench/out/colonnade.rib; the `gpu_frame`
suite in bench/suites.py times them):

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/gpu_frame_scenes.py

outdoor: a tree (a subdivided trunk and boughs, a crown of 3,600 leaves,
60 fruit) on a displaced meadow, with rocks, a bench and a fence around it,
under a soft sun (2 degrees) and a sky-coloured world; about 5 million
micropolygons at 1080p.

colonnade: two rows of twelve fluted columns (subdivided, 24 flutes) with
bases, capitals and an architrave, seen down the row, on a stone floor under
a soft sun; about 6 million micropolygons at 1080p.

Both 1920x1080 at 16 samples per pixel, Principled materials, shading rate 1.
"""

import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

RNG = np.random.default_rng(7)


def mesh_object(scene, name, points, faces, material, subdivision=0, smooth=True):
    """An object of `faces` (lists of point indices) over `points` (n x 3)."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(p) for p in np.asarray(points, dtype=float)], [], [list(f) for f in faces])
    mesh.update()
    if smooth:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    obj.data.materials.append(material)
    if subdivision:
        obj.modifiers.new("Subdivision", "SUBSURF").render_levels = subdivision
    return obj


def cylinder(sides, rings, radius, height, flutes=0, flute_depth=0.0):
    """A closed cylinder along z from 0 to `height`; with `flutes`, the radius
    dips `flute_depth` that many times around (a fluted column)."""
    points, faces = [], []
    for j in range(rings + 1):
        z = height * j / rings
        for i in range(sides):
            a = 2.0 * math.pi * i / sides
            r = radius * (1.0 - (flute_depth if flutes and i % (sides // flutes) == 0 else 0.0))
            points.append((r * math.cos(a), r * math.sin(a), z))
    for j in range(rings):
        for i in range(sides):
            k = j * sides
            faces.append((k + i, k + (i + 1) % sides, k + sides + (i + 1) % sides, k + sides + i))
    faces.append(tuple(range(sides - 1, -1, -1)))
    faces.append(tuple(rings * sides + i for i in range(sides)))
    return points, faces


def box(size):
    sx, sy, sz = size
    points = [(x * sx, y * sy, z * sz) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return points, faces


def placed(points, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1)):
    """`points` scaled, turned (Euler XYZ, radians) and moved."""
    p = np.asarray(points, dtype=float) * np.asarray(scale, dtype=float)
    cx, cy, cz = (math.cos(a) for a in rotation)
    sx, sy, sz = (math.sin(a) for a in rotation)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return p @ (rz @ ry @ rx).T + np.asarray(location, dtype=float)


def merged(parts):
    """(points, faces) of several (points, faces) parts in one mesh."""
    points, faces = [], []
    for p, f in parts:
        base = len(points)
        points.extend(np.asarray(p).tolist())
        faces.extend(tuple(base + i for i in face) for face in f)
    return points, faces


def sphere(rings, segments):
    points, faces = [(0.0, 0.0, -1.0)], []
    for j in range(1, rings):
        t = math.pi * j / rings - math.pi / 2
        for i in range(segments):
            a = 2.0 * math.pi * i / segments
            points.append((math.cos(t) * math.cos(a), math.cos(t) * math.sin(a), math.sin(t)))
    points.append((0.0, 0.0, 1.0))
    top = len(points) - 1
    for i in range(segments):
        faces.append((0, 1 + (i + 1) % segments, 1 + i))
    for j in range(rings - 2):
        k = 1 + j * segments
        for i in range(segments):
            faces.append((k + i, k + (i + 1) % segments, k + segments + (i + 1) % segments, k + segments + i))
    k = 1 + (rings - 2) * segments
    for i in range(segments):
        faces.append((k + i, k + (i + 1) % segments, top))
    return points, faces


def sky_world(scene, color, strength):
    world = scene.world
    world.use_nodes = True
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = strength


def soft_sun(scene, rotation, energy, angle_degrees):
    sun = ru.add_sun(scene, rotation, energy)
    sun.data.angle = math.radians(angle_degrees)
    return sun


def finish(scene, name, camera_from, camera_to, lens):
    ru.add_camera(scene, camera_from, camera_to, lens=lens)
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 1920, 1080, 100
    scene.render.engine = "MICROPOLY"
    scene.micropoly.samples = 16
    ru.write_bench_rib(scene, name)


def outdoor():
    scene = ru.reset_scene()
    sky_world(scene, (0.45, 0.6, 0.85), 0.6)
    bark = ru.principled_material("bark", (0.25, 0.16, 0.1), 0.9)
    leaf = ru.principled_material("leaf", (0.12, 0.35, 0.08), 0.5)
    fruit = ru.principled_material("fruit", (0.75, 0.12, 0.05), 0.3)
    meadow = ru.principled_material("meadow", (0.2, 0.32, 0.1), 0.95)
    ru.add_noise_displacement(meadow, 3.0, 0.08)
    stone = ru.principled_material("stone", (0.45, 0.43, 0.4), 0.8)
    wood = ru.principled_material("wood", (0.4, 0.27, 0.15), 0.7)
    # The meadow: 40 x 40 quads over 60 m, displaced by its material.
    n = 40
    g = np.linspace(-30.0, 30.0, n + 1)
    points = [(x, y, 0.0) for y in g for x in g]
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)
             for j in range(n) for i in range(n)]
    mesh_object(scene, "meadow", points, faces, meadow, subdivision=1)
    # The tree: a trunk and twelve boughs.
    trunk = cylinder(12, 6, 0.35, 4.0)
    boughs = [placed(cylinder(8, 4, 0.12, 2.6)[0], (0, 0, 2.6 + 0.12 * k),
                     (math.radians(55 + 5 * (k % 3)), 0, 2.0 * math.pi * k / 12)) for k in range(12)]
    mesh_object(scene, "tree", *merged([trunk] + [(b, cylinder(8, 4, 0.12, 2.6)[1]) for b in boughs]), bark,
                subdivision=2)
    # The crown: 3,600 leaves (bent quads) in an ellipsoid around the boughs' ends.
    leaf_points, leaf_faces = [], []
    for k in range(3600):
        d = RNG.normal(size=3)
        d /= np.linalg.norm(d)
        c = np.array([0.0, 0.0, 5.2]) + d * np.array([2.8, 2.8, 1.9]) * RNG.uniform(0.55, 1.0)
        quad = placed([(-0.09, 0, 0), (0.0, -0.05, 0.01), (0.09, 0, 0), (0.0, 0.05, 0.01)], c,
                      tuple(RNG.uniform(0, 2 * math.pi, 3)), (1.6, 1.6, 1.6))
        base = len(leaf_points)
        leaf_points.extend(quad.tolist())
        leaf_faces.append((base, base + 1, base + 2, base + 3))
    mesh_object(scene, "leaves", leaf_points, leaf_faces, leaf, smooth=False)
    # 60 fruit among the leaves.
    ball = sphere(8, 12)
    parts = []
    for k in range(60):
        d = RNG.normal(size=3)
        d /= np.linalg.norm(d)
        c = np.array([0.0, 0.0, 4.9]) + d * np.array([2.5, 2.5, 1.6]) * RNG.uniform(0.7, 1.0)
        parts.append((placed(ball[0], c, (0, 0, 0), (0.11, 0.11, 0.11)), ball[1]))
    mesh_object(scene, "fruit", *merged(parts), fruit, subdivision=1)
    # Rocks, a bench and a fence.
    rock = sphere(6, 8)
    for k in range(8):
        a = 2.0 * math.pi * k / 8 + 0.3
        s = RNG.uniform(0.4, 0.9)
        mesh_object(scene, f"rock{k}", placed(rock[0], (6.5 * math.cos(a), 6.5 * math.sin(a), 0.1),
                                               tuple(RNG.uniform(0, 1, 3)), (s, 0.8 * s, 0.6 * s)),
                    rock[1], stone, subdivision=2)
    plank = box((2.2, 0.12, 0.06))
    leg = box((0.08, 0.4, 0.45))
    bench = [(placed(plank[0], (3.5, -3.0 + 0.14 * k, 0.47)), plank[1]) for k in range(4)]
    bench += [(placed(leg[0], (3.5 + x, -2.8, 0.22)), leg[1]) for x in (-0.9, 0.9)]
    mesh_object(scene, "bench", *merged(bench), wood, subdivision=1)
    post, rail = box((0.12, 0.12, 1.2)), box((2.0, 0.06, 0.1))
    fence = []
    for k in range(12):
        x = -11.0 + 2.0 * k
        fence.append((placed(post[0], (x, 9.0, 0.6)), post[1]))
        for h in (0.5, 1.0):
            fence.append((placed(rail[0], (x + 1.0, 9.0, h)), rail[1]))
    mesh_object(scene, "fence", *merged(fence), wood, subdivision=1)
    soft_sun(scene, (math.radians(50), 0.0, math.radians(35)), 4.0, 2.0)
    finish(scene, "outdoor", (9.5, -10.5, 3.2), (0.0, 0.5, 3.0), 32.0)


def colonnade():
    scene = ru.reset_scene()
    sky_world(scene, (0.5, 0.55, 0.65), 0.5)
    marble = ru.principled_material("marble", (0.8, 0.78, 0.72), 0.35)
    floor_mat = ru.principled_material("floor", (0.55, 0.5, 0.45), 0.6)
    shaft = cylinder(48, 12, 0.45, 6.0, flutes=24, flute_depth=0.06)
    base, capital = box((1.2, 1.2, 0.35)), box((1.3, 1.3, 0.4))
    columns = []
    for row in (-2.2, 2.2):
        for k in range(12):
            y = 4.0 * k
            columns.append((placed(shaft[0], (row, y, 0.35)), shaft[1]))
            columns.append((placed(base[0], (row, y, 0.175)), base[1]))
            columns.append((placed(capital[0], (row, y, 6.55)), capital[1]))
    mesh_object(scene, "columns", *merged(columns), marble, subdivision=2)
    beam = box((1.3, 45.5, 0.8))
    mesh_object(scene, "architrave", *merged([(placed(beam[0], (x, 22.0, 7.15)), beam[1]) for x in (-2.2, 2.2)]),
                marble, subdivision=1)
    n = 24
    xs, ys = np.linspace(-8.0, 8.0, n + 1), np.linspace(-6.0, 52.0, n + 1)
    points = [(x, y, 0.0) for y in ys for x in xs]
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)
             for j in range(n) for i in range(n)]
    mesh_object(scene, "floor", points, faces, floor_mat, smooth=False)
    soft_sun(scene, (math.radians(40), 0.0, math.radians(-60)), 4.0, 1.5)
    finish(scene, "colonnade", (0.6, -5.5, 2.4), (0.0, 14.0, 3.2), 28.0)


outdoor()
colonnade()
