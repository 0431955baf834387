"""What one texture image adds to an upload of the scene data (its pixels'
copy and upload, and its MIP levels, built on the device): a plane in a
64 x 64 frame rendered through the Python module with one image of each
size, linear or 8-bit sRGB, twice each, against the same scene with a
1 x 1 image. Needs numpy (/usr/bin/python3 on Debian):

  /usr/bin/python3 bench/image_upload_bench.py [--device cpu|gpu|INDEX]
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "addons"))
from micropoly import _native  # noqa: E402


def scene(size, srgb, seed):
    s = _native.Scene()
    s.settings.width, s.settings.height = 64, 64
    s.add_material(name="m", model="matte", color=[0.5, 0.5, 0.5], ka=1.0, kd=1.0)
    points = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    s.add_mesh("plane", points, np.array([4], np.int32), np.arange(4, dtype=np.int32))
    s.add_image("image", np.random.default_rng(seed).random((size, size, 4), dtype=np.float32), srgb=srgb)
    return s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--device", default="")
    args = ap.parse_args()
    renderer = _native.Renderer(args.device)
    renderer.render(scene(1, False, 0))  # builds the programs
    seed = 1  # a new image each time: an unchanged scene is not uploaded again
    for srgb in (False, True):
        base = []
        for _ in range(2):
            seed += 1
            s = scene(1, srgb, seed)
            t = time.perf_counter()
            renderer.render(s)
            base.append(time.perf_counter() - t)
        for size in (2048, 4096):
            times = []
            for _ in range(2):
                seed += 1
                s = scene(size, srgb, seed)
                t = time.perf_counter()
                renderer.render(s)
                times.append(time.perf_counter() - t)
            print(f"{'sRGB' if srgb else 'linear'} {size}x{size}: +{(min(times) - min(base)) * 1000:.0f} ms "
                  f"over a 1 x 1 image ({min(times) * 1000:.0f} ms against {min(base) * 1000:.0f} ms)")


main()
