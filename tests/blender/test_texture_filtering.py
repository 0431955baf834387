"""Filtered image textures against Cycles: minified images must show the
average Cycles' many samples per pixel give, not aliasing.

Two glowing (Emission) scenes, black world, Micropoly at 16 samples per
pixel against Cycles at 1024 (its pixel filter averages the texture):

- a checkerboard floor receding to the horizon (an 8-bit sRGB checker
  repeated through a Mapping node, so the lookup's coordinates come from a
  node chain);
- a small distant card showing a high-frequency image (pixel noise and fine
  stripes), seen at an angle.

The card must reach 32 dB (whole frame, normalised to the 99th
percentile) at the default shading rate, and the floor at shading rate 0.5;
at the default rate the floor must beat the unfiltered lookups (Texture
Filter Width 0) by 3 dB: there the error left is where checks are one or
two pixels tall, which vertices a pixel apart cannot hold whatever the
filter (docs/pipeline.md, Image textures). Then the floor under a slow
24-frame camera move: the frame-to-frame change (flicker) of its minified
part with filtering must be at most half of what unfiltered lookups give.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python tests/blender/test_texture_filtering.py

MICROPOLY_TEST_OUTPUT=folder saves Cycles | Micropoly | difference x4 there.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_utils as ru  # noqa: E402
from texture_scenes import card_scene, floor_scene  # noqa: E402

OUTPUT = os.environ.get("MICROPOLY_TEST_OUTPUT")
W, H = 240, 144
FLICKER_W, FLICKER_H, FLICKER_FRAMES = 160, 96, 24


def render_micropoly(make, width, height, filter_width, shading_rate=1.0):
    scene = make()
    scene.micropoly.texture_filter_width = filter_width
    scene.micropoly.shading_rate = shading_rate
    return ru.render_passes(scene, "MICROPOLY", width, height, samples=16)["rgba"]


def frame_db(cycles, micro):
    peak = max(float(np.percentile(cycles[..., :3], 99)), 1e-6)
    return ru.psnr(micro[..., :3], cycles[..., :3], peak=peak)


def flicker(make_at, filter_width):
    """Mean absolute change between consecutive frames over the floor's far
    half (rows between the horizon and the image's middle), where it is
    minified: the camera moves 2 cm a frame."""
    frames = [render_micropoly(lambda k=k: make_at(0.02 * k), FLICKER_W, FLICKER_H, filter_width)[..., :3]
              for k in range(FLICKER_FRAMES)]
    rows = slice(int(FLICKER_H * 0.25), int(FLICKER_H * 0.5))
    changes = [float(np.mean(np.abs(b[rows] - a[rows]))) for a, b in zip(frames, frames[1:])]
    return float(np.mean(changes))


def main():
    ru.enable_addon()
    failures = []
    # (name, scene, shading rate, what it must reach: dB, or None for 3 dB over unfiltered)
    cases = (("receding checkerboard", floor_scene, 1.0, None),
             ("receding checkerboard at shading rate 0.5", floor_scene, 0.5, 32.0),
             ("busy distant card", card_scene, 1.0, 32.0))
    for name, make, rate, target in cases:
        scene = make()
        ru.setup_cycles(scene, samples=1024, adaptive_subdivision=False)
        cycles = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
        filtered = render_micropoly(make, W, H, 1.0, rate)
        unfiltered = render_micropoly(make, W, H, 0.0, rate)
        file = name.replace(" ", "_").replace(".", "")
        ru.save_side_by_side(OUTPUT, file, cycles, filtered)
        ru.save_side_by_side(OUTPUT, file + "_unfiltered", cycles, unfiltered)
        db, before = frame_db(cycles, filtered), frame_db(cycles, unfiltered)
        ok = db >= (target if target is not None else before + 3.0) and db > before
        need = f"{target:g} dB" if target is not None else "3 dB over unfiltered"
        print(f"{'ok  ' if ok else 'FAIL'} {name}: {db:.2f} dB against Cycles at 1024 samples "
              f"(unfiltered lookups: {before:.2f} dB; needs {need})")
        if not ok:
            failures.append(f"{name}: {db:.2f} dB (unfiltered {before:.2f}), needs {need}")
    moving, still = flicker(floor_scene, 1.0), flicker(floor_scene, 0.0)
    ok = moving <= 0.5 * still
    print(f"{'ok  ' if ok else 'FAIL'} flicker over {FLICKER_FRAMES} frames of a slow move: {moving:.5f} filtered, "
          f"{still:.5f} unfiltered ({moving / max(still, 1e-12):.2f} of it)")
    if not ok:
        failures.append(f"flicker {moving:.5f} is more than half the unfiltered {still:.5f}")
    return ru.verdict(failures, "minified image textures are filtered as Cycles' supersampling averages them")


ru.run_test(main)
