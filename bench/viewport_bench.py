"""Rendered viewport timings: how soon the first image and the full
refinement arrive after the view opens, after an edit and after an orbit.
Run with Blender (or a Python with bpy):

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/viewport_bench.py -- [--repeat 5] [--rate 1.0] [--no-shadows] [--material mix] [--edit move|value]

Scene: bench/blender_bench.py's six subdivided Suzannes on a floor, seen
from its camera at 1280x720 through the viewport session
(addon/micropoly/viewport.py) exactly as the 3D view drives it, minus the
drawing: view_update's export (with the mesh cache kept between updates)
and the worker thread's passes: a quarter-resolution image at 1 spp, then
the full view at 16 spp. Times run from just before the export
(the edit) or the view change to the image's arrival. Prints medians and a
JSON line. The lights cast shadows unless --no-shadows; the session keeps
the shadow map pages between requests, so an orbit renders only the pages
the turned view newly needs and an edit (geometry changed) renders all.

--rib PATH writes the same view at 1920x1080, 4 spp as RIB instead, for
the CLI's frames per second on a GPU:
  micropoly-render PATH -o out.png --device gpu --repeat 30"""

import json
import math
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

import blender_bench  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
REPEAT = int(args[args.index("--repeat") + 1]) if "--repeat" in args else 5
RATE = float(args[args.index("--rate") + 1]) if "--rate" in args else 1.0
SHADOWS = "--no-shadows" not in args
# The edit between rounds: "move" (a Suzanne moves: geometry changes) or
# "value" (a node value of a Suzanne's material changes: with --material mix
# its Diffuse colour, else its Principled Base Color).
EDIT = args[args.index("--edit") + 1] if "--edit" in args else "move"
WIDTH, HEIGHT, SAMPLES = 1280, 720, 16


def wait(session, generation, started, timeout=300.0):
    """(first image s, final image s, final image) of one request."""
    first = None
    while time.perf_counter() - started < timeout:
        image = session.image()
        if image is not None and image.generation == generation:
            if first is None:
                first = time.perf_counter() - started
            if image.final:
                return first, time.perf_counter() - started, image
        if session.error():
            raise RuntimeError(session.error())
        time.sleep(0.002)
    raise RuntimeError("the viewport session did not finish")


def write_rib(path):
    scene = blender_bench.build_scene()
    from micropoly import operators

    scene.render.engine = "MICROPOLY"
    scene.render.resolution_x, scene.render.resolution_y = 1920, 1080
    scene.micropoly.samples = 4
    scene.micropoly.shading_rate = RATE
    operators.export_rib(bpy.context.evaluated_depsgraph_get(), path)
    print(f"wrote {path}")


def main():
    if "--rib" in args:
        write_rib(args[args.index("--rib") + 1])
        return
    scene = blender_bench.build_scene()
    from micropoly import export, export_mesh, viewport

    scene.render.engine = "MICROPOLY"
    scene.micropoly.viewport_samples = SAMPLES
    scene.micropoly.viewport_shading_rate = RATE
    scene.micropoly.use_shadows = SHADOWS
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = viewport.view_from_camera(scene, depsgraph, WIDTH, HEIGHT)
    meshes = export_mesh.MeshCache()
    session = viewport.ViewportSession("")
    results = {"open": [], "edit": [], "orbit": []}
    pages = {"edit": [], "orbit": []}  # shadow map pages rendered for the final pass, of those requested
    try:
        for run in range(REPEAT + 1):
            # Open (or re-open after an edit): export, then render.
            started = time.perf_counter()
            exported = export.export_scene(depsgraph, view=view, meshes=meshes)
            export_s = time.perf_counter() - started
            generation = session.request(exported, view, SAMPLES, RATE)
            first, final, image = wait(session, generation, started)
            results["open" if run == 0 else "edit"].append((first, final, export_s))
            pages["edit"].append((image.stats["shadows"]["pages_rendered"], image.stats["shadows"]["pages_requested"]))
            # Orbit: the same scene from a camera turned by 2 degrees.
            cam = scene.camera
            cam.rotation_euler.z += math.radians(2.0) * (1 if run % 2 == 0 else -1)
            depsgraph.update()
            orbit = viewport.view_from_camera(scene, depsgraph, WIDTH, HEIGHT)
            started = time.perf_counter()
            generation = session.restart_view(orbit)
            first, final, image = wait(session, generation, started)
            results["orbit"].append((first, final, 0.0))
            pages["orbit"].append((image.stats["shadows"]["pages_rendered"], image.stats["shadows"]["pages_requested"]))
            view = orbit
            # The edit for the next round.
            obj = next(o for o in scene.objects if o.type == "MESH" and o.modifiers)
            if EDIT == "value":
                nodes = obj.active_material.node_tree.nodes
                shader = next(n for n in nodes if n.type in ("BSDF_DIFFUSE", "BSDF_PRINCIPLED"))
                socket = shader.inputs["Color" if shader.type == "BSDF_DIFFUSE" else "Base Color"]
                socket.default_value = (0.2 + 0.05 * run, 0.4, 0.6, 1.0)
            else:
                obj.location.z += 0.05
            depsgraph.update()
        stats = image.stats
    finally:
        session.close()
    print(f"\nBlender {bpy.app.version_string}, viewport {WIDTH}x{HEIGHT}, {SAMPLES} spp, shading rate {RATE}, "
          f"shadows {'on' if SHADOWS else 'off'}, edit: {EDIT}, device {session.device}; final pass: "
          f"{stats['micropolygons']:,} micropolygons")
    if SHADOWS:
        for name, rows in pages.items():
            print(f"shadow pages rendered / requested in the final pass, {name}: "
                  + ", ".join(f"{r}/{q}" for r, q in rows))
    print("| event | runs | first image s (median) | full refinement s (median) | export s (median) |")
    print("|---|---|---|---|---|")
    for name, rows in results.items():
        if not rows:
            continue
        med = [statistics.median(r[i] for r in rows) for i in range(3)]
        print(f"| {name} | {len(rows)} | {med[0]:.3f} | {med[1]:.3f} | {med[2]:.3f} |")
    print(json.dumps({"version": bpy.app.version_string, "width": WIDTH, "height": HEIGHT, "samples": SAMPLES,
                      "shading_rate": RATE, "shadows": SHADOWS, "shadow_pages": pages, "device": session.device, "micropolygons": stats["micropolygons"],
                      "runs": results}))


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)  # the bpy module can hang in its exit handlers
