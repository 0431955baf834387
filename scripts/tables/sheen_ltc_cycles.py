"""Fits the shape of Cycles' microfiber sheen lobe (Blender 4.x's Principled
sheen and Sheen BSDF's Microfiber) from renders of it.

Cycles evaluates the lobe as a linearly transformed cosine (Zeltner et al.
2022, "Practical Multiple-Scattering Sheen Using Linearly Transformed
Cosines"): in the frame whose x axis T is the view's direction along the
surface, the lobe times the cosine is

    s * z * (a / ((a x + b z)^2 + (a y)^2 + z^2))^2 / pi

for a light direction (x, y, z), with a, b and the scale s functions of the
view's cosine and the roughness that Cycles reads from its tables. This
script measures that function: planes of the 9 sheen roughnesses side by
side (the 17 roughnesses 0.02, then 1/16 .. 1; coplanar, so none shades
another), lit by a sun of strength pi alone from 40 directions per view (8
elevations x 5 azimuths about T), seen by an orthographic camera from each
of the 17 view cosines 0.02, then 1/16 .. 1, no bounces: each strip's pixel
is s z (a / len^2)^2. It then fits a, b and s for each view cosine and
roughness by least squares (the fits' relative RMS error is below 0.001)
and writes the 3 x 17 x 17 table kernels/closures/mp_bsdf.h reads
(kernels/tables/mp_sheen_ltc_table.h). s is the lobe's directional albedo: it
agrees with the furnace's (scripts/tables/sheen_albedo_cycles.py).
Run with a Python that has the bpy module (4.0 or later):

  build/bpy-4.5.15/bin/python3 scripts/tables/sheen_ltc_cycles.py -- kernels/tables/mp_sheen_ltc_table.h
"""

import math
import os
import sys
import tempfile

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sheen_albedo_cycles as furnace  # noqa: E402  (the strips, the camera)

ELEVATIONS = [10.0, 25.0, 40.0, 55.0, 70.0, 80.0, 85.0, 89.0]  # the light's angle from the normal
AZIMUTHS = [0.0, 45.0, 90.0, 135.0, 180.0]  # about the normal, from the view's side
# The table's axes: view cosine and roughness 0.02, then 1/16 .. 1 in sixteenths.
AXIS = [0.02] + [k / 16 for k in range(1, 17)]


def lit_scene():
    furnace.COSINES, furnace.ROUGHNESS = AXIS, AXIS
    # 17 strips widen the frame: at the most grazing view it spans 570 units
    # of plane along the view.
    furnace.LENGTH = 1200.0
    furnace.W = 12 * len(AXIS)  # whole pixels per strip
    scene, cam = furnace.build_scene()
    bg = next(n for n in scene.world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Strength"].default_value = 0.0
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = math.pi
    sun.data.angle = 0.0
    scene.collection.objects.link(sun)
    scene.cycles.samples = 4
    return scene, cam, sun


def light_direction(elevation, azimuth):
    """Towards the light, in world space: the camera sits towards -y, so the
    view's direction along the plane (T) is -y."""
    t, p = math.radians(elevation), math.radians(azimuth)
    return np.array([math.sin(t) * math.sin(p), -math.sin(t) * math.cos(p), math.cos(t)])


def aim(sun, d):
    """A sun shines along its -Z: turn its +Z onto d."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, d)
    s = np.linalg.norm(axis)
    sun.rotation_mode = "AXIS_ANGLE"
    sun.rotation_axis_angle = (math.atan2(s, d[2]), *(axis / s if s > 1e-9 else (1.0, 0.0, 0.0)))


def ltc(params, x, y, z):
    a, b, s = params
    length2 = (a * x + b * z) ** 2 + (a * y) ** 2 + z ** 2
    return s * z * (a / length2) ** 2


def fit(dirs, values):
    """a, b, s minimising the relative squared error (s in closed form for
    each a, b on a grid refined three times)."""
    x, y, z = dirs[:, 0], dirs[:, 1], dirs[:, 2]
    if not values.max() > 1e-7:
        # Cycles skips a lobe whose LTC or albedo vanishes: nothing to fit.
        return (1.0, 0.0, 0.0), 0.0
    weight = 1.0 / np.maximum(values, 1e-3 * values.max())
    best = (None, np.inf)
    log_a, b_range = (-7.0, 3.0), (-4.0, 4.0)
    for _ in range(4):
        for la in np.linspace(*log_a, 101):
            a = math.exp(la)
            for b in np.linspace(*b_range, 81):
                shape = ltc((a, b, 1.0), x, y, z)
                # s minimising sum (w (s shape - v))^2
                s = np.sum(weight ** 2 * shape * values) / max(np.sum((weight * shape) ** 2), 1e-30)
                err = np.sum((weight * (s * shape - values)) ** 2)
                if err < best[1]:
                    best = ((a, b, s), err)
        a, b, _ = best[0]
        step_a = (log_a[1] - log_a[0]) / 100.0 * 4.0
        step_b = (b_range[1] - b_range[0]) / 80.0 * 4.0
        log_a = (math.log(a) - step_a, math.log(a) + step_a)
        b_range = (b - step_b, b + step_b)
    params = best[0]
    rms = math.sqrt(np.mean(((ltc(params, x, y, z) - values) / np.maximum(values, 1e-6)) ** 2))
    return params, rms


def main():
    scene, cam, sun = lit_scene()
    dirs = np.array([light_direction(e, p) for e in ELEVATIONS for p in AZIMUTHS])
    local = np.stack([-dirs[:, 1], dirs[:, 0], dirs[:, 2]], axis=1)  # (T, B, N) with T = -y
    tables = np.zeros((3, len(AXIS), len(AXIS)))
    worst = 0.0
    for i, nv in enumerate(AXIS):
        values = []
        for d in dirs:
            aim(sun, d)
            values.append(furnace.measure(scene, cam, nv))
        values = np.array(values)  # [light][roughness]
        for j, r in enumerate(AXIS):
            (a, b, s), rms = fit(local, values[:, j])
            tables[:, i, j] = (a, b, s)
            worst = max(worst, rms)
            print(f"nv {nv:.3f} roughness {r:.3f}: a {a:.4f} b {b:.4f} s {s:.4f}, relative RMS {rms:.4f}")
            sys.stdout.flush()
    print(f"worst relative RMS {worst:.4f}")
    path = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "kernels/tables/mp_sheen_ltc_table.h"
    with open(path, "w") as f:
        f.write(header(tables, worst))


def header(tables, worst):
    rows = [", ".join(f"{v:.4f}f" for v in row) + "," for row in tables.reshape(-1, len(AXIS))]
    return "\n".join([
        f"/* Generated by scripts/tables/sheen_ltc_cycles.py from Cycles {bpy.app.version_string}: the",
        " * microfiber sheen's LTC as Cycles evaluates it, fitted to renders of the",
        " * lobe under a sun from 40 directions (worst relative RMS error of a fit",
        f" * {worst:.4f}). [a, b, s][view cosine][roughness], both axes 0.02, then",
        " * 1/16 .. 1 in sixteenths; read by mp_sheen_ltc (mp_bsdf.h). Compiles as",
        " * OpenCL C and C++. */",
        "#ifndef MP_SHEEN_LTC_TABLE_H", "#define MP_SHEEN_LTC_TABLE_H", "", '#include "core/mp_compat.h"', "",
        f"MP_CONSTANT float mp_sheen_ltc_table[{tables.size}] = {{"] + ["  " + r for r in rows] +
        ["};", "", "#endif", ""])


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)
