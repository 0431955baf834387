"""Puts the shadow test's images together for docs/images/shadows_vs_cycles.png:
each light type hard and soft, Micropoly left of Cycles, two cases a row.

  MICROPOLY_ADDON_DIR=build/addons MICROPOLY_TEST_OUTPUT=DIR MICROPOLY_TEST_SCALE=2 \\
      blender -b --factory-startup --python tests/blender/test_shadows.py
  blender -b --factory-startup --python scripts/figures/shadow_figure.py -- DIR OUT.png
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "blender"))
import render_utils as ru  # noqa: E402

CASES = ("sun hard", "sun angle 12 deg", "spot hard", "spot radius 0.6", "point hard", "point radius 0.6",
         "area 0.02 x 0.02", "area 1.6 x 0.9", "displaced ridges, sun at 10 deg", "contact")


def load(path):
    image = bpy.data.images.load(path)
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    return px.reshape(h, w, 4)[::-1, :, :3]  # rows top first, display values


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    folder, out = args[0], args[1]
    pairs = []
    for name in CASES:
        row = load(os.path.join(folder, name + ".png"))
        w = row.shape[1] // 3
        cycles, micro = row[:, :w], row[:, w:2 * w]
        gap = np.ones((row.shape[0], 4, 3), dtype=np.float32)
        pairs.append(np.concatenate([micro, gap * 0.0, cycles], axis=1))
    rows = []
    for k in range(0, len(pairs), 2):
        gap = np.ones((pairs[k].shape[0], 16, 3), dtype=np.float32)
        rows.append(np.concatenate([pairs[k], gap, pairs[k + 1]], axis=1))
        rows.append(np.ones((16, rows[-1].shape[1], 3), dtype=np.float32))
    ru.save_png(out, np.concatenate(rows[:-1], axis=0))
    print(f"wrote {out}")


main()
sys.stdout.flush()
os._exit(0)
