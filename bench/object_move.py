"""Time from an object's move to a finished F12, in a scene larger than
the object: 48 spheres scattered over a 60 m plane under a sun, a point
lamp (both with shadow maps) and the world's probe suns off, 480 x 270,
16 spp. Before each render one sphere moves 0.3 m, as an artist placing an
object and pressing F12 again, or an animation in which one thing moves.
Prints one JSON line: the seconds of each render after the first two
(warm-up), their median, the median shadows' wall time, and the shadow
pages requested and rendered in the last render.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup \
      --python bench/object_move.py -- [--renders 10] [--no-lamp]

Run it against an older build by pointing MICROPOLY_ADDON_DIR at that
build's add-on folder.
"""

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


def build_scene(lamp):
    scene = ru.reset_scene()
    material = ru.principled_material("Field", (0.6, 0.6, 0.6), 0.5)
    bpy.ops.mesh.primitive_plane_add(size=60)
    bpy.context.object.data.materials.append(material)
    rng = random.Random(1)
    for _ in range(48):
        x, y = rng.uniform(-25, 25), rng.uniform(-25, 25)
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(x, y, 0.6))
        bpy.context.object.data.materials.append(material)
    sun = ru.add_sun(scene, (math.radians(40), math.radians(15), math.radians(30)))
    ru.set_cast_shadow(sun.data, True)
    if lamp:
        point = ru.add_aimed_light(scene, "POINT", (-6.0, 4.0, 6.0), (0.0, 0.0, 0.0), 2000.0,
                                   shadow_soft_size=0.3)
        ru.set_cast_shadow(point.data, True)
    ru.add_camera(scene, (30, -30, 25), (0, 0, 0), lens=35.0)
    scene.render.engine = "MICROPOLY"
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 480, 270, 100
    scene.micropoly.samples = 16
    scene.micropoly.use_shadows = True
    scene.micropoly.world_shadow_directions = 0
    return scene


def main(argv):
    renders = int(argv[argv.index("--renders") + 1]) if "--renders" in argv else 10
    ru.enable_addon()
    from micropoly import engine

    stats = {}
    write_result = engine.MicropolyRenderEngine._write_result

    def keep_stats(self, scene, view_layer, exported, result):
        stats.update(result["stats"])
        return write_result(self, scene, view_layer, exported, result)

    engine.MicropolyRenderEngine._write_result = keep_stats
    build_scene("--no-lamp" not in argv)
    moved = bpy.data.objects["Sphere"]
    seconds, shadows = [], []
    for i in range(renders):
        moved.location.x += 0.3 if i % 2 else -0.3
        t0 = time.perf_counter()
        bpy.ops.render.render()
        seconds.append(time.perf_counter() - t0)
        shadows.append(stats["timings_ms"]["shadows_wall"] / 1000.0)
    print("OBJECT_MOVE " + json.dumps({
        "blender": bpy.app.version_string, "renders": renders, "seconds": [round(s, 3) for s in seconds[2:]],
        "median_s": round(statistics.median(seconds[2:]), 3),
        "median_shadows_s": round(statistics.median(shadows[2:]), 3),
        "shadow_pages_requested": stats["shadows"]["pages_requested"],
        "shadow_pages_rendered": stats["shadows"]["pages_rendered"]}))
    return 0


if __name__ == "__main__":
    code = main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    sys.stdout.flush()
    os._exit(code)
