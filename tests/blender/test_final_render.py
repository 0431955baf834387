"""F12 around the native renderer: one renderer kept from one final render to
the next (its device, programs and uploaded scene), and the Sample Memory
setting, which renders a frame in buckets that give the whole frame's image.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python tests/blender/test_final_render.py
"""
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_utils as ru  # noqa: E402


def build():
    scene = ru.reset_scene()
    ru.add_suzanne_torus_floor(ru.diffuse_material)
    ru.add_sun(scene, (0.6, 0.2, 0.4))
    ru.add_camera(scene, (0.0, -6.0, 3.0), (0.0, 0.0, 0.3))
    return scene


def main():
    ru.enable_addon()
    from micropoly import engine

    failures = []
    scene = build()
    first = ru.render_passes(scene, "MICROPOLY", 320, 240, samples=16)
    kept = engine._final_renderers._renderer
    second = ru.render_passes(scene, "MICROPOLY", 320, 240, samples=16)
    if kept is None or engine._final_renderers._renderer is not kept:
        failures.append("the second F12 made a new renderer")
    if not np.array_equal(first["rgba"], second["rgba"]):
        failures.append("the kept renderer's second image differs from the first")
    if first["rgba"][..., 3].mean() < 0.2:
        failures.append(f"the scene covers only {first['rgba'][..., 3].mean():.2f} of the frame")

    # 640 x 360 at 64 spp: 354 MB of samples; 16 MiB of sample memory makes
    # dozens of buckets.
    whole = ru.render_passes(scene, "MICROPOLY", 640, 360, samples=64)
    if engine._final_renderers.last_timings.get("buckets") != 1:
        failures.append(f"the default sample memory split the frame: {engine._final_renderers.last_timings}")
    scene.micropoly.sample_memory = 16.0
    tiled = ru.render_passes(scene, "MICROPOLY", 640, 360, samples=64)
    buckets = engine._final_renderers.last_timings.get("buckets", 0)
    if buckets < 16:
        failures.append(f"16 MiB of sample memory gave {buckets} buckets for 354 MB of samples")
    psnr = ru.psnr(whole["rgba"], tiled["rgba"], peak=1.0)
    print(f"{buckets} buckets against the whole frame: {psnr:.1f} dB")
    if psnr < 60.0:
        failures.append(f"buckets changed the image: {psnr:.1f} dB")
    if not np.array_equal(whole["rgba"][..., 3], tiled["rgba"][..., 3]):
        failures.append("buckets changed the alpha")
    if whole["depth"] is not None and not np.array_equal(whole["depth"], tiled["depth"]):
        failures.append("buckets changed the Depth pass")
    for f in failures:
        print("FAIL:", f)
    print("final render checks:", "failed" if failures else "passed")
    return 1 if failures else 0


if __name__ == "__main__":
    ru.run_test(main)
