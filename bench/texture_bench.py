"""The image-texture benchmark. Run with Blender (or a Python with bpy):

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/texture_bench.py

Writes the two scenes of tests/blender/test_texture_filtering.py at 1920x1080
and 16 samples as RIB, with their images (bench/out/texture_floor.rib: a
checkerboard floor receding to the horizon; bench/out/texture_card.rib: a
busy image on a small distant card), for the CLI's per-stage timings with
filtered and unfiltered lookups (bench/bench.py textures)."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))

import render_utils as ru  # noqa: E402
from texture_scenes import card_scene, floor_scene  # noqa: E402


def main():
    ru.enable_addon()
    for name, make in (("texture_floor", floor_scene), ("texture_card", card_scene)):
        scene = make()
        scene.render.resolution_x, scene.render.resolution_y = 1920, 1080
        scene.render.resolution_percentage = 100
        scene.render.film_transparent = True
        scene.micropoly.samples = 16
        ru.write_bench_rib(scene, name)
    return 0


ru.run_test(main)
