"""Occlusion culling benchmark scenes, built in Blender (run with Blender or a
Python with bpy):

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/occlusion_bench.py -- --rib-only
  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/occlusion_bench.py -- [--repeat 3] [--shells 16]

Scenes, 1920x1080:
- shells N: the camera inside N nested closed shells (cubes of 6 x 6 faces
  per side with a Subdivision Surface modifier, rounded into blobs), the
  innermost 4 m across, each next 4% larger; lit by a point light inside
  (radius 0.1 m, casting shadows); only the innermost is seen.
- shells_out N: the same shells with the lamp outside the outermost, so
  every shell but the outermost lies in its shadow.
- layers (point / sun): one polygon mesh of 1,000 stacked square layers
  (10 m across, 1 cm apart, 8 x 8 faces each), seen from above at an angle,
  lit by a point lamp above it or by a sun; only the top layer is seen
  (the stack's edges lie outside the frame), and each layer hides the ones
  below it from the light.
- field: 2,000 subdivided, displaced rocks (icospheres with a Noise
  displacement) scattered over a 200 m ground plane, seen from eye height
  (1.7 m) under a sun; the near rocks hide many of the far ones.

--rib-only writes bench/out/shells_{1,4,16,64}.rib, shells_out_{1,16,64}.rib,
layers_point.rib, layers_sun.rib and bench/out/field_2000.rib
(--only NAME,NAME: those alone) for the CLI (bench/bench.py occlusion and
culling render them, on PoCL and on a GPU). Without it:
F12 of one scene (--scene shells, shells_out, layers_point or layers_sun;
shells N = --shells, default 16; --percent of 1920x1080, default 100) with
Micropoly, culling on and off (--culled-only: on only), and Cycles (default light paths, 16 samples,
adaptive subdivision at 1 px, denoising off), rounds interleaved; the
medians, ratios and Micropoly's own statistics."""

import json
import math
import os
import random
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
REPEAT = int(args[args.index("--repeat") + 1]) if "--repeat" in args else 3
SCENE = args[args.index("--scene") + 1] if "--scene" in args else "shells"
PERCENT = int(args[args.index("--percent") + 1]) if "--percent" in args else 100
ONLY = args[args.index("--only") + 1].split(",") if "--only" in args else []
SHELLS = int(args[args.index("--shells") + 1]) if "--shells" in args else 16
W, H = 1920, 1080
SAMPLES = 16
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")


def settings(scene):
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = W, H, 100
    scene.render.engine = "MICROPOLY"
    scene.micropoly.samples = SAMPLES
    return scene


def shells_scene(n, lamp_outside=False):
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_cube_add(size=4.0)
    base = bpy.context.object
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.subdivide(number_cuts=5)  # 6 x 6 faces per side
    bpy.ops.object.mode_set(mode="OBJECT")
    base.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    for k in range(n):
        obj = base if k == 0 else base.copy()
        if k:
            obj.data = base.data.copy()
            scene.collection.objects.link(obj)
        obj.name = f"Shell{k}"
        s = 1.04 ** k
        obj.scale = (s, 0.8 * s, 0.6 * s)
        mat = ru.diffuse_material(f"Shell{k}", (0.3 + 0.6 * k / max(n - 1, 1), 0.5, 0.7 - 0.5 * k / max(n - 1, 1)))
        obj.data.materials.clear()
        obj.data.materials.append(mat)
    light = bpy.data.lights.new("Lamp", "POINT")
    light.energy = 300.0
    light.shadow_soft_size = 0.1
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = (3.5, -4.0, 5.0) if lamp_outside else (0.4, -0.3, 0.5)
    if lamp_outside:
        light.energy = 3000.0
    scene.collection.objects.link(lamp)
    ru.add_camera(scene, (-0.3, -0.5, -0.2), (1.0, 1.5, 0.1), lens=24.0)
    return settings(scene)


def layers_scene(lamp, count=1000):
    """One mesh of `count` stacked layers (8 x 8 quads, 10 m across, 1 cm apart)."""
    import numpy as np

    scene = ru.reset_scene()
    n = 8
    g = np.linspace(-5.0, 5.0, n + 1)
    xs, ys = np.meshgrid(g, g)
    layer = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1)
    verts = np.concatenate([layer + (0.0, 0.0, -0.01 * k) for k in range(count)])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    quad = np.stack([a, a + 1, a + n + 2, a + n + 1], axis=1)
    faces = np.concatenate([quad + k * (n + 1) ** 2 for k in range(count)])
    mesh = bpy.data.meshes.new("Layers")
    mesh.from_pydata(verts.tolist(), [], faces.tolist())
    mesh.materials.append(ru.diffuse_material("Layers", (0.6, 0.5, 0.4)))
    obj = bpy.data.objects.new("Layers", mesh)
    scene.collection.objects.link(obj)
    if lamp == "point":
        light = bpy.data.lights.new("Lamp", "POINT")
        light.energy = 800.0
        light.shadow_soft_size = 0.1
        obj = bpy.data.objects.new("Lamp", light)
        obj.location = (1.2, -0.8, 2.0)
        scene.collection.objects.link(obj)
    else:
        ru.add_sun(scene, (math.radians(35), 0.0, math.radians(30)))
    ru.add_camera(scene, (1.5, -2.5, 3.0), (0.0, 0.0, 0.0), lens=35.0)
    return settings(scene)


def field_scene(count=2000, seed=7):
    scene = ru.reset_scene()
    scene.world.color = (0.05, 0.06, 0.08)
    bpy.ops.mesh.primitive_plane_add(size=200.0)
    ground = bpy.context.object
    ground.data.materials.append(ru.diffuse_material("Ground", (0.35, 0.3, 0.25)))
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=1.0)
    rock = bpy.context.object
    rock.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    rock.data.materials.append(ru.add_noise_displacement(ru.diffuse_material("Rock", (0.5, 0.5, 0.45)), 2.0, 0.4))
    rng = random.Random(seed)
    for k in range(count):
        obj = rock if k == 0 else rock.copy()  # instances of one mesh, each placed and sized
        if k:
            scene.collection.objects.link(obj)
        x, y = rng.uniform(-60.0, 60.0), rng.uniform(2.0, 90.0)
        size = rng.uniform(0.4, 1.3)
        obj.location = (x, y, 0.3 * size)
        obj.scale = (size, size * rng.uniform(0.7, 1.3), size * rng.uniform(0.6, 1.0))
        obj.rotation_euler = (0.0, 0.0, rng.uniform(0.0, 2 * math.pi))
    ru.add_sun(scene, (math.radians(50), 0.0, math.radians(30)))
    ru.add_camera(scene, (0.0, -2.0, 1.7), (0.0, 30.0, 1.2), lens=35.0)
    return settings(scene)


def write_ribs():
    os.makedirs(OUT, exist_ok=True)
    for name, build in [(f"shells_{n}", lambda n=n: shells_scene(n)) for n in (1, 4, 16, 64)] + \
                       [(f"shells_out_{n}", lambda n=n: shells_scene(n, True)) for n in (1, 16, 64)] + \
                       [("layers_point", lambda: layers_scene("point")), ("layers_sun", lambda: layers_scene("sun")),
                        ("field_2000", field_scene)]:
        if ONLY and name not in ONLY:
            continue
        build()  # enables the add-on
        from micropoly import operators
        path = os.path.join(OUT, name + ".rib")
        operators.export_rib(bpy.context.evaluated_depsgraph_get(), path)
        print(f"wrote {path}")


def native_stats(scene):
    from micropoly import _native, export, preferences

    exported = export.export_scene(bpy.context.evaluated_depsgraph_get())
    renderer = _native.Renderer(preferences.device_selector(bpy.context))
    return renderer.render(exported.scene)["stats"]


def build_f12_scene():
    """The scene --scene names: shells (N = --shells, lamp inside), shells_out
    (lamp outside) or layers_point / layers_sun (at --percent of 1080p)."""
    if SCENE == "shells_out":
        scene = shells_scene(SHELLS, True)
    elif SCENE.startswith("layers_"):
        scene = layers_scene(SCENE[len("layers_"):])
    else:
        scene = shells_scene(SHELLS)
    scene.render.resolution_percentage = PERCENT
    return scene


def f12_bench():
    def micropoly(culling):
        def setup(scene):
            scene.render.engine = "MICROPOLY"
            scene.micropoly.use_occlusion_culling = culling
        return setup

    def cycles(scene):
        ru.setup_cycles(scene, samples=SAMPLES, shadows=True)
        c = scene.cycles
        c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 12, 4, 4  # Cycles' defaults

    variants = (("Micropoly, occlusion culling", micropoly(True)), ("Micropoly, no culling", micropoly(False)),
                ("Cycles", cycles))
    if "--culled-only" in args:  # the scenes where a frame without culling takes minutes
        variants = tuple(v for v in variants if v[0] != "Micropoly, no culling")
    times = {label: [] for label, _ in variants}
    stats = {}
    for _ in range(REPEAT):
        for label, setup in variants:
            scene = build_f12_scene()
            setup(scene)
            started = time.perf_counter()
            bpy.ops.render.render()
            times[label].append(time.perf_counter() - started)
            if label.startswith("Micropoly") and label not in stats:
                s = native_stats(scene)
                stats[label] = {k: s[k] for k in ("micropolygons", "subpatches_diced", "subpatches_occluded",
                                                  "depth_complexity", "covered_pixels")}
    base = statistics.median(times["Cycles"])
    what = f"{SHELLS} nested shells" if SCENE.startswith("shells") else SCENE
    print(f"\nBlender {bpy.app.version_string}, {what} ({SCENE}), {W * PERCENT // 100}x{H * PERCENT // 100}, "
          f"{SAMPLES} samples, F12, "
          f"rounds interleaved, median of {REPEAT}")
    print("| render | F12 s (median) | runs | time / Cycles' |")
    print("|---|---|---|---|")
    for label, runs in times.items():
        med = statistics.median(runs)
        print(f"| {label} | {med:.2f} | {', '.join(f'{t:.2f}' for t in runs)} | {med / base:.3f} |")
    for label, s in stats.items():
        print(f"{label}: {s['micropolygons']:,} micropolygons, {s['subpatches_diced']:,} sub-patches diced, "
              f"{s['subpatches_occluded']:,} culled as hidden, depth complexity {s['depth_complexity']:.2f}")
    print(json.dumps({"version": bpy.app.version_string, "scene": SCENE, "shells": SHELLS, "percent": PERCENT,
                      "width": W, "height": H,
                      "renders": times, "stats": stats}))


if __name__ == "__main__":
    if "--rib-only" in args:
        write_ribs()
    else:
        f12_bench()
    sys.stdout.flush()
    os._exit(0)  # the bpy module can hang in its exit handlers
