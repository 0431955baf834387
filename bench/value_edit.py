"""Time from a node value's edit to a finished F12: the soak tests' scene
(tests/soak/soak_scene.py, 160 x 120, 16 spp, shadow maps on) rendered
again after each edit, as an artist tweaking a material or an animated
value does. Three edits take turns: Suzanne's Principled Roughness, its
Noise texture's Scale and the torus' displacement strength (a Displacement
node's Scale). Prints one JSON line: the seconds of each render after the
first two (warm-up), their median, and the median program build time the
renderer reported.

With --relink the edit is to the tree instead: Suzanne's Noise texture
drives, in turn, her Base Color and her Roughness (two programs that only
shade, each built once in the first two renders), as an artist trying a
material's wiring does; the shadow maps' pages stay.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup \
      --python bench/value_edit.py -- [--renders 12] [--relink]

Run it against an older build by pointing MICROPOLY_ADDON_DIR at that
build's add-on folder (bench/results/history.md, "Node values as parameters").
"""

import json
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "soak"))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402
import soak_scene  # noqa: E402


def main(argv):
    renders = int(argv[argv.index("--renders") + 1]) if "--renders" in argv else 12
    ru.enable_addon()
    from micropoly import engine

    scene = soak_scene.build_scene(160, 120, samples=16)
    suzanne = bpy.data.materials["Suzanne"].node_tree
    bsdf = next(n for n in suzanne.nodes if n.type == "BSDF_PRINCIPLED")
    noise = next(n for n in suzanne.nodes if n.type == "TEX_NOISE")
    torus = bpy.data.materials["Torus"].node_tree
    displacement = next(n for n in torus.nodes if n.type == "DISPLACEMENT")
    relink = "--relink" in argv
    seconds, builds = [], []
    for i in range(renders):
        t = i / renders
        which = i % 3
        if relink:
            for link in [l for l in suzanne.links if l.from_node == noise]:
                suzanne.links.remove(link)
            if i % 2:
                suzanne.links.new(noise.outputs["Fac"], bsdf.inputs["Roughness"])
            else:
                suzanne.links.new(noise.outputs["Color"], bsdf.inputs["Base Color"])
        elif which == 0:
            bsdf.inputs["Roughness"].default_value = 0.3 + 0.4 * t
        elif which == 1:
            noise.inputs["Scale"].default_value = 5.0 + 3.0 * t
        else:
            displacement.inputs["Scale"].default_value = 0.06 + 0.04 * t
        t0 = time.perf_counter()
        bpy.ops.render.render()
        seconds.append(time.perf_counter() - t0)
        builds.append(engine._final_renderers.last_timings.get("program_build_s"))
    kept = seconds[2:]
    known = [b for b in builds[2:] if b is not None]
    print("VALUE_EDIT " + json.dumps({
        "blender": bpy.app.version_string, "edit": "relink" if relink else "values", "renders": renders, "seconds": [round(s, 3) for s in kept],
        "median_s": round(statistics.median(kept), 3),
        "median_program_build_s": round(statistics.median(known), 3) if known else None}))
    return 0


if __name__ == "__main__":
    code = main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    sys.stdout.flush()
    os._exit(code)
