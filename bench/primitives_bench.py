"""Point clouds and curves: scene memory and frame time against their size.

  MICROPOLY_ADDON_DIR=build/addons python3 bench/primitives_bench.py [--points N ...] [--strands N ...]

Renders, at 640x360 with 4 spp and a distant light, a cloud of N spheres
(radius 0.02, random in a 4 x 4 x 1 box) and a field of N strands (8 keys,
0.8 tall, radius 0.004), one renderer each, two frames: the scene's device
bytes (stats scene_bytes), micropolygons and both frames' totals (the
first includes the upload). Only numpy and the native module are used."""

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.environ.get("MICROPOLY_ADDON_DIR", "build/addons"))
from micropoly import _native  # noqa: E402


def arg_list(name, default):
    args = sys.argv[1:]
    if name not in args:
        return default
    i = args.index(name) + 1
    out = []
    while i < len(args) and args[i].isdigit():
        out.append(int(args[i]))
        i += 1
    return out


def scene():
    s = _native.Scene()
    s.settings.width, s.settings.height = 640, 360
    s.settings.samples_x = s.settings.samples_y = 2
    eye, target = np.array([0.0, -5.0, 2.0]), np.zeros(3)
    f = (target - eye) / np.linalg.norm(target - eye)
    side = np.cross(f, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    up = np.cross(side, f)
    m = np.identity(4)
    m[0, :3], m[1, :3], m[2, :3] = side, up, -f
    m[:3, 3] = -m[:3, :3] @ eye
    s.set_camera(m.astype(np.float32), fov_degrees=50.0)
    s.add_light("distant", direction=[-0.3, 0.5, -1.0])
    return s


def run(label, s):
    r = _native.Renderer()
    t = time.time()
    a = r.render(s)
    first = time.time() - t
    t = time.time()
    b = r.render(s)
    second = time.time() - t
    st = b["stats"]
    print(f"{label}: scene {st['scene_bytes'] / 2**20:.1f} MiB, {st['micropolygons']:,} micropolygons, "
          f"frames {first:.2f} s (with upload) and {second:.2f} s", flush=True)


rng = np.random.default_rng(1)
for n in arg_list("--points", [10000, 100000]):
    s = scene()
    pos = (rng.random((n, 3)) * [4.0, 4.0, 1.0] - [2.0, 2.0, 0.0]).astype(np.float32)
    s.add_points("cloud", pos, np.full(n, 0.02, np.float32))
    run(f"{n:,} points", s)
for n in arg_list("--strands", [10000, 50000]):
    s = scene()
    roots = rng.random((n, 2)) * 4.0 - 2.0
    t = np.linspace(0.0, 1.0, 8)
    pts = np.empty((n, 8, 3), np.float32)
    pts[..., 0] = roots[:, :1] + 0.2 * t ** 2
    pts[..., 1] = roots[:, 1:]
    pts[..., 2] = 0.8 * t
    s.add_curves("hair", pts.reshape(-1, 3), np.full(n * 8, 0.004, np.float32),
                 np.arange(0, n * 8 + 1, 8, dtype=np.int32))
    run(f"{n:,} strands (7 segments, 28 patches each)", s)
