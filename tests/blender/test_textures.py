"""Procedural textures of kernels/textures against Blender's own evaluation
(run by blender -b, or by a Python with the bpy module).

Every case is one tile of a single render: a small tilted quad (so Object
coordinates vary in x, y and z) seen from above by an orthographic camera,
with an Emission shader fed by the texture node under test through Object
coordinates (W from the x coordinate in 1D, from x + y in 4D). Cycles renders
at 1 sample, pixel filter width 0.01, no denoising, to a 32-bit float EXR.

Textures: Noise, Musgrave (up to 4.0), Wave, Voronoi, Checker, Brick,
Gradient (every type), Magic (depths 0-10), White Noise (1D-4D) and Gabor
(2D and 3D, from 4.3). Colour nodes: Blackbody, Wavelength, RGB Curves,
Vector Curves, Float Curve (extrapolated and horizontal ends, points outside
[0, 1]), Bright/Contrast and Gamma, fed the Object coordinates as colour or
vector; their scalar inputs (temperature, wavelength, gamma, ...) are either
constant or driven from one coordinate by Math nodes (multiply, add), which
the test repeats in float32 for the probe. The curve tables and colour space
matrices given to the probe come from the add-on's node_textures module
(loaded from MICROPOLY_ADDON_DIR), as the generated programs embed them.

The input point of a pixel is not guessed from its centre: a first render
emits the Object coordinates themselves. Cycles' camera samples depend only
on the pixel, sample and seed, so later renders of the same scene shade the
very same points, bit for bit. Those points go through texture_probe (the
headers evaluated on the host, told the running Blender version) and the
outputs are compared with what Blender rendered.

Pass criteria per case and output: |difference| <= 1e-3 on at least 99.5% of
the pixels and a median |difference| <= 1e-4 (differences come only from
float32 evaluation order; a pixel can differ more only where the texture
jumps, e.g. at a Voronoi cell border that two float evaluations place
differently). Prints a table of max/median differences. Exits non-zero on
failure. The probe is found through MICROPOLY_TEXTURE_PROBE.

Observed: every pixel of every case within 1e-3; worst differences about
2e-5 in Blender 3.4 and 7e-5 in 4.5/5.0 (distorted or multifractal noise,
where float rounding is amplified), medians 1e-7 or below. The pattern and
colour nodes: worst 3e-6 in 3.4 (Brick's smoothed mortar, Float Curve) and
7e-6 in 4.5/5.0 (Gabor), medians 6e-8 or below. Runs in a few seconds."""

import importlib.util
import math
import os
import subprocess
import sys
import tempfile
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import render_utils as ru  # noqa: E402

VERSION = bpy.app.version[0] * 100 + bpy.app.version[1]
TILE = 40  # pixels per case, square
COLS = 12  # at least; more when there are more cases than fit in a square of 12 x 12
TOL = 1e-3
MIN_FRACTION = 0.995
MAX_MEDIAN = 1e-4

DIM_NAMES = {1: "1D", 2: "2D", 3: "3D", 4: "4D"}
NOISE_TYPES = ["FBM", "MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "HETERO_TERRAIN"]
VORONOI_FEATURES = ["F1", "F2", "SMOOTH_F1", "DISTANCE_TO_EDGE", "N_SPHERE_RADIUS"]
VORONOI_METRICS = ["EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI"]
WAVE_BANDS_DIRS = ["X", "Y", "Z", "DIAGONAL"]
WAVE_RINGS_DIRS = ["X", "Y", "Z", "SPHERICAL"]
WAVE_PROFILES = ["SIN", "SAW", "TRI"]
GRADIENT_TYPES = ["LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE", "RADIAL"]


def load_node_textures():
    """The add-on's node_textures module, loaded on its own (it computes the
    colour space matrices and curve tables that the generated programs
    embed; the probe is fed the same)."""
    folder = os.environ.get("MICROPOLY_ADDON_DIR")
    path = os.path.join(folder, "micropoly", "node_textures.py") if folder else ""
    if not os.path.exists(path):
        path = os.path.join(os.path.dirname(__file__), "..", "..", "addon", "micropoly", "node_textures.py")
    spec = importlib.util.spec_from_file_location("mp_node_textures", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


NT = load_node_textures()


# ---------------------------------------------------------------------------
# Cases


def build_cases():
    """Each case: kind, a label, the parameters in the probe's order, and
    the node's settings. Outputs compared: see OUTPUT_GROUPS."""
    cases = []
    new_noise = VERSION >= 400  # Lacunarity and Normalize
    typed_noise = VERSION >= 401  # Musgrave types merged into Noise

    def noise(dims, detail, roughness, distortion, scale=4.0, lacunarity=2.0, normalize=1, ntype=0, offset=0.0,
              gain=1.0, label=""):
        cases.append(dict(kind="noise", label=f"noise {DIM_NAMES[dims]} {NOISE_TYPES[ntype]} {label}".strip(),
                          dims=dims, type=ntype, normalize=normalize, scale=scale, detail=detail,
                          roughness=roughness, lacunarity=lacunarity, offset=offset, gain=gain,
                          distortion=distortion))

    for dims in (1, 2, 3, 4):
        noise(dims, 2.0, 0.5, 0.0, label="d2")
        noise(dims, 3.4, 0.65, 1.3, label="d3.4 dist")
    noise(3, 15.0, 1.0, 0.0, scale=2.0, label="d15 r1")
    noise(2, 0.0, 0.5, 0.4, label="d0 dist")
    noise(3, 1.6, 1.4, 0.0, label="rough>1")  # clamped to 1 before 4.0
    if new_noise:
        noise(3, 2.5, 0.55, 0.0, lacunarity=2.7, label="lac2.7")
        noise(2, 2.5, 0.55, 0.8, lacunarity=1.6, normalize=0, label="lac1.6 raw dist")
        noise(4, 1.5, 0.6, 0.0, lacunarity=3.0, normalize=0, label="raw")
        noise(1, 4.7, 0.7, 0.5, lacunarity=2.2, normalize=0, label="raw dist")
    if typed_noise:
        for ntype, offset, gain in ((1, 0.0, 1.0), (2, 0.9, 1.7), (3, 0.3, 1.4), (4, 0.6, 1.0)):
            for dims in (1, 2, 3, 4):
                noise(dims, 2.5 if dims != 2 else 3.0, 0.5, 0.0 if dims != 3 else 0.6, scale=3.0, lacunarity=2.1,
                      ntype=ntype, offset=offset, gain=gain)

    if VERSION <= 400:
        for mtype, offset, gain in ((0, 0.0, 1.0), (1, 0.0, 1.0), (2, 0.9, 1.7), (3, 0.3, 1.4), (4, 0.6, 1.0)):
            for dims in (1, 2, 3, 4):
                cases.append(dict(kind="musgrave", label=f"musgrave {DIM_NAMES[dims]} {NOISE_TYPES[mtype]}",
                                  dims=dims, type=mtype, scale=3.0, detail=3.5 if dims != 2 else 4.0,
                                  dimension=1.2, lacunarity=2.1, offset=offset, gain=gain))

    for wave_type in (0, 1):
        for direction in range(4):
            for profile in range(3):
                i = (wave_type * 4 + direction) * 3 + profile
                distortion = 0.0 if i % 2 == 0 else 3.0
                name = (WAVE_BANDS_DIRS if wave_type == 0 else WAVE_RINGS_DIRS)[direction]
                cases.append(dict(kind="wave",
                                  label=f"wave {'BANDS' if wave_type == 0 else 'RINGS'} {name} {WAVE_PROFILES[profile]}"
                                        + (" dist" if distortion else ""),
                                  wave_type=wave_type, direction=direction, profile=profile, scale=1.3,
                                  distortion=distortion, detail=1.7 + 0.4 * (i % 3), detail_scale=1.4,
                                  detail_roughness=0.6, phase=0.4 * (i % 5)))

    def voronoi(dims, feature, metric, detail=0.0, roughness=0.5, lacunarity=2.0, normalize=0, scale=3.0,
                smoothness=0.8, exponent=1.5, randomness=0.9, label=""):
        cases.append(dict(kind="voronoi",
                          label=f"voronoi {DIM_NAMES[dims]} {VORONOI_FEATURES[feature]} "
                                f"{VORONOI_METRICS[metric]} {label}".strip(),
                          dims=dims, feature=feature, metric=metric, scale=scale, detail=detail,
                          roughness=roughness, lacunarity=lacunarity, smoothness=smoothness, exponent=exponent,
                          randomness=randomness, normalize=normalize))

    for feature in (0, 1, 2):
        voronoi(1, feature, 0)
        for dims in (2, 3, 4):
            for metric in range(4):
                voronoi(dims, feature, metric, exponent=0.7 if (dims + feature) % 2 else 2.5)
    for feature in (3, 4):
        for dims in (1, 2, 3, 4):
            voronoi(dims, feature, 0, randomness=1.0 if dims % 2 else 0.75)
        voronoi(3, feature, 1 + feature % 3, label="(metric unused)")
    if new_noise:
        voronoi(3, 0, 0, detail=2.5, roughness=0.6, lacunarity=2.2, normalize=1, label="fractal")
        voronoi(2, 1, 1, detail=1.3, roughness=0.7, lacunarity=2.5, normalize=1, label="fractal")
        voronoi(3, 2, 0, detail=1.5, roughness=0.5, lacunarity=2.0, normalize=0, label="fractal")
        voronoi(4, 0, 2, detail=1.0, roughness=0.5, lacunarity=1.8, normalize=1, label="fractal")
        voronoi(1, 1, 0, detail=3.2, roughness=0.8, lacunarity=2.0, normalize=1, label="fractal")
        voronoi(2, 3, 0, detail=2.4, roughness=0.6, lacunarity=2.0, normalize=1, label="fractal")
        voronoi(3, 3, 0, detail=1.7, roughness=0.5, lacunarity=2.3, normalize=0, label="fractal")
        voronoi(2, 2, 3, detail=0.6, roughness=0.5, lacunarity=2.0, normalize=1, smoothness=0.0,
                label="fractal smooth0")
    build_pattern_cases(cases)
    build_color_cases(cases)
    return cases


def build_pattern_cases(cases):
    """Checker, Brick, Gradient, Magic, White Noise and (4.3+) Gabor."""
    for scale, c1, c2 in ((3.0, (0.9, 0.3, 0.1), (0.05, 0.6, 0.8)), (7.5, (0.2, 0.25, 0.7), (1.0, 0.9, 0.4))):
        cases.append(dict(kind="checker", label=f"checker scale {scale}", scale=scale, c1=c1, c2=c2))
    colors = ((0.8, 0.2, 0.1), (0.3, 0.9, 0.4), (0.1, 0.1, 0.6))
    for label, params in (
            ("default-like", dict(scale=2.0, mortar_size=0.05, mortar_smooth=0.3, bias=0.0, brick_width=0.5,
                                  row_height=0.25, offset=0.5, offset_frequency=2, squash=1.0, squash_frequency=2)),
            ("hard mortar squash", dict(scale=3.3, mortar_size=0.08, mortar_smooth=0.0, bias=-0.2, brick_width=0.7,
                                        row_height=0.3, offset=0.3, offset_frequency=3, squash=0.6,
                                        squash_frequency=2)),
            ("smooth 1 bias", dict(scale=2.6, mortar_size=0.1, mortar_smooth=1.0, bias=0.4, brick_width=0.45,
                                   row_height=0.2, offset=0.7, offset_frequency=1, squash=1.5, squash_frequency=3))):
        cases.append(dict(kind="brick", label=f"brick {label}", colors=colors, **params))
    for gtype in range(len(GRADIENT_TYPES)):
        cases.append(dict(kind="gradient", label=f"gradient {GRADIENT_TYPES[gtype]}", gtype=gtype))
    for depth, scale, distortion in ((0, 1.2, 1.0), (1, 2.0, 1.5), (2, 1.5, 2.0), (3, 1.0, 0.0), (4, 1.0, 1.3),
                                     (7, 0.8, 0.9), (10, 0.6, 0.7)):
        cases.append(dict(kind="magic", label=f"magic depth {depth} dist {distortion}", depth=depth, scale=scale,
                          distortion=distortion))
    for dims in (1, 2, 3, 4):
        cases.append(dict(kind="white_noise", label=f"white noise {DIM_NAMES[dims]}", dims=dims))
    if VERSION >= 403:
        for gtype, scale, freq, aniso, o2, o3 in ((0, 3.0, 2.0, 1.0, 0.785, (1.0, 1.0, 0.0)),
                                                   (0, 4.0, 3.5, 0.3, 1.3, (1.0, 1.0, 0.0)),
                                                   (1, 2.5, 2.0, 1.0, 0.0, (1.4142135, 1.4142135, 0.0)),
                                                   (1, 3.0, 1.5, 0.4, 0.0, (0.3, -0.5, 0.8)),
                                                   (1, 2.0, 2.5, 0.0, 0.0, (0.0, 1.0, 0.2))):
            cases.append(dict(kind="gabor", label=f"gabor {'3D' if gtype else '2D'} freq {freq} aniso {aniso}",
                              gtype=gtype, scale=scale, frequency=freq, anisotropy=aniso, o2=o2, o3=o3))


# Curve points per curve index: (x, y) pairs replacing the default ones.
RGB_CURVE = {3: [(-0.4, -0.2), (0.3, 0.55), (1.2, 0.9)], 0: [(0.0, 0.0), (0.5, 0.7), (1.0, 1.0)],
             1: [(0.0, 0.1), (0.3, 0.1), (1.0, 0.95)]}
VECTOR_CURVE = {0: [(-1.0, -1.0), (0.0, 0.4), (1.0, 1.0)], 1: [(-1.0, -0.8), (-0.5, 0.3), (0.6, -0.2), (1.0, 0.7)]}
FLOAT_CURVE = {0: [(0.0, 0.0), (0.3, 0.8), (0.7, 0.2), (1.0, 1.0)]}


def build_color_cases(cases):
    """Blackbody, Wavelength, the curves, Bright/Contrast and Gamma. `drive`
    sets an input to coordinate[axis] * mul + add (Math nodes in the scene,
    the same float operations here); `const` sets an input's value; the
    nodes' colour or vector input is the Object coordinate."""
    cases.append(dict(kind="blackbody", label="blackbody 200-11800 K", drive={"Temperature": (0, 5800.0, 6000.0)}))
    cases.append(dict(kind="blackbody", label="blackbody 7000-15000 K", drive={"Temperature": (1, 4000.0, 11000.0)}))
    cases.append(dict(kind="wavelength", label="wavelength 365-795 nm", drive={"Wavelength": (0, 215.0, 580.0)}))
    cases.append(dict(kind="wavelength", label="wavelength 380-780 nm (y)", drive={"Wavelength": (1, 200.0, 580.0)}))
    cases.append(dict(kind="curves", label="rgb curves extrapolated", curve="RGB", points=RGB_CURVE,
                      extend="EXTRAPOLATED", const={"Fac": 1.0}))
    cases.append(dict(kind="curves", label="rgb curves horizontal fac 0.85", curve="RGB", points=RGB_CURVE,
                      extend="HORIZONTAL", const={"Fac": 0.85}))
    cases.append(dict(kind="curves", label="vector curves extrapolated", curve="VECTOR", points=VECTOR_CURVE,
                      extend="EXTRAPOLATED", const={"Fac": 1.0}))
    cases.append(dict(kind="curves", label="vector curves horizontal fac 0.6", curve="VECTOR", points=VECTOR_CURVE,
                      extend="HORIZONTAL", const={"Fac": 0.6}))
    cases.append(dict(kind="float_curve", label="float curve extrapolated", curve="FLOAT", points=FLOAT_CURVE,
                      extend="EXTRAPOLATED", const={"Factor": 1.0}, drive={"Value": (0, 0.8, 0.5)}))
    cases.append(dict(kind="float_curve", label="float curve horizontal fac 0.7", curve="FLOAT", points=FLOAT_CURVE,
                      extend="HORIZONTAL", const={"Factor": 0.7}, drive={"Value": (0, 0.8, 0.5)}))
    cases.append(dict(kind="bright_contrast", label="bright/contrast 0.2 0.5", const={"Bright": 0.2, "Contrast": 0.5}))
    cases.append(dict(kind="bright_contrast", label="bright/contrast driven",
                      drive={"Bright": (1, 0.5, 0.0), "Contrast": (0, 0.8, -0.2)}))
    cases.append(dict(kind="gamma", label="gamma 2.2", const={"Gamma": 2.2}))
    cases.append(dict(kind="gamma", label="gamma 0.33-1.98 (z)", drive={"Gamma": (2, 1.5, 1.0)}))
    cases.append(dict(kind="gamma", label="gamma 0", const={"Gamma": 0.0}))
    # Vector Rotate (a converter, checked here as the colour nodes are): the
    # Object coordinate rotated about a centre, by a driven angle.
    rotate = dict(kind="vector_rotate", const={"Center": (0.1, -0.2, 0.3), "Axis": (1.0, 2.0, 0.5),
                                                "Rotation": (0.3, -1.2, 2.0)})
    cases.append(dict(rotate, label="vector rotate axis-angle", rtype="AXIS_ANGLE", invert=False,
                      drive={"Angle": (0, 3.0, 0.4)}))
    cases.append(dict(rotate, label="vector rotate axis-angle inverted", rtype="AXIS_ANGLE", invert=True,
                      drive={"Angle": (1, 3.0, -0.7)}))
    cases.append(dict(rotate, label="vector rotate x axis", rtype="X_AXIS", invert=False, drive={"Angle": (2, 2.0, 1.0)}))
    cases.append(dict(rotate, label="vector rotate y axis inverted", rtype="Y_AXIS", invert=True,
                      drive={"Angle": (0, 2.0, 1.0)}))
    cases.append(dict(rotate, label="vector rotate z axis", rtype="Z_AXIS", invert=False, drive={"Angle": (1, 2.0, 1.0)}))
    cases.append(dict(rotate, label="vector rotate euler xyz", rtype="EULER_XYZ", invert=False))
    cases.append(dict(rotate, label="vector rotate euler xyz inverted", rtype="EULER_XYZ", invert=True))
    cases.append(dict(kind="vector_rotate", label="vector rotate zero axis", rtype="AXIS_ANGLE", invert=False,
                      const={"Center": (0.1, -0.2, 0.3), "Axis": (0.0, 0.0, 0.0), "Angle": 1.0,
                             "Rotation": (0.0, 0.0, 0.0)}))


# Output groups rendered per kind: (name, probe columns).
# Probe columns: noise/wave: fac r g b; musgrave: fac; voronoi: distance r g b px py pz w radius.
OUTPUT_GROUPS = {
    "noise": [("color", (1, 2, 3)), ("fac", (0, 0, 0))],
    "musgrave": [("fac", (0, 0, 0))],
    "wave": [("fac", (0, 0, 0)), ("color", (1, 2, 3))],
    "voronoi": [("color", (1, 2, 3)), ("position", (4, 5, 6)), ("distance,w,radius", (0, 7, 8))],
    # Probe columns: checker/brick/gradient/magic: fac r g b; white_noise: value r g b;
    # gabor: value phase intensity; float_curve: value; the colour nodes: r g b.
    "checker": [("fac", (0, 0, 0)), ("color", (1, 2, 3))],
    "brick": [("fac", (0, 0, 0)), ("color", (1, 2, 3))],
    "gradient": [("fac", (0, 0, 0)), ("color", (1, 2, 3))],
    "magic": [("fac", (0, 0, 0)), ("color", (1, 2, 3))],
    "white_noise": [("value", (0, 0, 0)), ("color", (1, 2, 3))],
    "gabor": [("value,phase,intensity", (0, 1, 2))],
    "blackbody": [("color", (0, 1, 2))],
    "wavelength": [("color", (0, 1, 2))],
    "curves": [("color", (0, 1, 2))],
    "float_curve": [("value", (0, 0, 0))],
    "bright_contrast": [("color", (0, 1, 2))],
    "gamma": [("color", (0, 1, 2))],
    "vector_rotate": [("vector", (0, 1, 2))],
}
NEW_KINDS = {"checker", "brick", "gradient", "magic", "white_noise", "gabor", "blackbody", "wavelength", "curves",
             "float_curve", "bright_contrast", "gamma", "vector_rotate"}


def g(x):
    return f"{float(x):.9g}"


def gs(values):
    return " ".join(g(v) for v in values)


def new_probe_line(case, x, y, z, w, d):
    """The probe query of a pattern or colour case at (x, y, z, w); d: the
    driven inputs' values."""
    k, xyz = case["kind"], f"{g(x)} {g(y)} {g(z)}"
    if k == "checker":
        return f"checker {g(case['scale'])} {gs(case['c1'])} {gs(case['c2'])} {VERSION} {xyz}"
    if k == "brick":
        p = case
        return (f"brick {gs(p[n] for n in ('scale', 'mortar_size', 'mortar_smooth', 'bias', 'brick_width'))} "
                f"{g(p['row_height'])} {g(p['offset'])} {p['offset_frequency']} {g(p['squash'])} "
                f"{p['squash_frequency']} {gs(sum(p['colors'], ()))} {VERSION} {xyz}")
    if k == "gradient":
        return f"gradient {case['gtype']} {VERSION} {xyz}"
    if k == "magic":
        return f"magic {case['depth']} {g(case['scale'])} {g(case['distortion'])} {VERSION} {xyz}"
    if k == "white_noise":
        return f"white_noise {case['dims']} {VERSION} {xyz} {g(w)}"
    if k == "gabor":
        return (f"gabor {case['gtype']} {g(case['scale'])} {g(case['frequency'])} {g(case['anisotropy'])} "
                f"{g(case['o2'])} {gs(case['o3'])} {VERSION} {xyz}")
    if k == "blackbody":
        rows = case["_rows"]
        flat = sum(rows, []) if rows is not None else [1, 0, 0, 0, 1, 0, 0, 0, 1]
        return f"blackbody {0 if rows is None else 1} {gs(flat)} {VERSION} {g(d['Temperature'])}"
    if k == "wavelength":
        return f"wavelength {gs(sum(case['_rows'], []))} {VERSION} {g(d['Wavelength'])}"
    if k in ("curves", "float_curve"):
        lo, hi, extrapolate, _ = case["_table"]
        fac = case["const"]["Fac" if k == "curves" else "Factor"]
        head = f"{k} {case['_table_id']} {g(lo)} {g(hi)} {int(extrapolate)} {g(fac)} {VERSION}"
        return f"{head} {xyz}" if k == "curves" else f"{head} {g(d['Value'])}"
    if k == "bright_contrast":
        c = dict(case.get("const", {}), **d)
        return f"bright_contrast {g(c['Bright'])} {g(c['Contrast'])} {VERSION} {xyz}"
    c = dict(case.get("const", {}), **d)
    if k == "vector_rotate":
        kind = ("AXIS_ANGLE", "X_AXIS", "Y_AXIS", "Z_AXIS", "EULER_XYZ").index(case["rtype"])
        return (f"vector_rotate {kind} {int(case['invert'])} {gs(c['Center'])} {gs(c['Axis'])} {g(c.get('Angle', 0.0))} "
                f"{gs(c['Rotation'])} {VERSION} {xyz}")
    return f"gamma {g(c['Gamma'])} {VERSION} {xyz}"


def probe_line(case, x, y, z, w):
    k = case["kind"]
    if k == "noise":
        head = (f"noise {case['dims']} {case['type']} {case['normalize']} {case['scale']!r} {case['detail']!r} "
                f"{case['roughness']!r} {case['lacunarity']!r} {case['offset']!r} {case['gain']!r} "
                f"{case['distortion']!r} {VERSION}")
    elif k == "musgrave":
        head = (f"musgrave {case['dims']} {case['type']} {case['scale']!r} {case['detail']!r} "
                f"{case['dimension']!r} {case['lacunarity']!r} {case['offset']!r} {case['gain']!r} {VERSION}")
    elif k == "wave":
        head = (f"wave {case['wave_type']} {case['direction']} {case['profile']} {case['scale']!r} "
                f"{case['distortion']!r} {case['detail']!r} {case['detail_scale']!r} "
                f"{case['detail_roughness']!r} {case['phase']!r} {VERSION}")
        return f"{head} {x:.9g} {y:.9g} {z:.9g}"
    else:
        head = (f"voronoi {case['dims']} {case['feature']} {case['metric']} {case['scale']!r} {case['detail']!r} "
                f"{case['roughness']!r} {case['lacunarity']!r} {case['smoothness']!r} {case['exponent']!r} "
                f"{case['randomness']!r} {case['normalize']} {VERSION}")
    return f"{head} {x:.9g} {y:.9g} {z:.9g} {w:.9g}"


# ---------------------------------------------------------------------------
# Scene


def find_socket(sockets, name):
    """By iteration: Blender 4.5 hides unavailable sockets from lookups by name."""
    return next((s for s in sockets if s.name == name), None)


def available(sockets, name):
    sock = find_socket(sockets, name)
    return sock if sock is not None and sock.enabled else None


def set_input(node, name, value):
    sock = find_socket(node.inputs, name)
    if sock is None:
        raise KeyError(f"{node.bl_idname} has no input {name!r} in Blender {bpy.app.version_string}")
    sock.default_value = value


def set_input_id(node, identifier, value):
    sock = next((s for s in node.inputs if s.identifier == identifier), None)
    if sock is None:
        raise KeyError(f"{node.bl_idname} has no input {identifier!r} in Blender {bpy.app.version_string}")
    sock.default_value = value


def set_curve(mapping, points, extend):
    """Replaces the given curves' points; the mapping is unclipped so that
    points may lie outside [0, 1] (and the table's range with them)."""
    mapping.use_clip = False
    for index, pts in points.items():
        curve = mapping.curves[index]
        while len(curve.points) > 2:
            curve.points.remove(curve.points[1])
        curve.points[0].location = pts[0]
        curve.points[-1].location = pts[-1]
        for x, y in pts[1:-1]:
            curve.points.new(x, y)
    mapping.extend = extend
    mapping.update()


def drive_input(nt, coords, node, identifier, axis, mul, add):
    """Input = coordinate[axis] * mul + add, by Math nodes."""
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(coords, sep.inputs[0])
    m = nt.nodes.new("ShaderNodeMath")
    m.operation = "MULTIPLY"
    nt.links.new(sep.outputs[axis], m.inputs[0])
    m.inputs[1].default_value = mul
    a = nt.nodes.new("ShaderNodeMath")
    a.operation = "ADD"
    nt.links.new(m.outputs[0], a.inputs[0])
    a.inputs[1].default_value = add
    sock = next(s for s in node.inputs if s.identifier == identifier)
    nt.links.new(a.outputs[0], sock)


COLOR_NODES = {"blackbody": "ShaderNodeBlackbody", "wavelength": "ShaderNodeWavelength",
               "bright_contrast": "ShaderNodeBrightContrast", "gamma": "ShaderNodeGamma",
               "float_curve": "ShaderNodeFloatCurve", "vector_rotate": "ShaderNodeVectorRotate"}


def new_texture_node(nt, case, coords):
    """Node and outputs of a pattern or colour case."""
    k = case["kind"]
    if k == "checker":
        n = nt.nodes.new("ShaderNodeTexChecker")
        set_input_id(n, "Scale", case["scale"])
        set_input_id(n, "Color1", case["c1"] + (1.0,))
        set_input_id(n, "Color2", case["c2"] + (1.0,))
        return n, {"fac": n.outputs["Fac"], "color": n.outputs["Color"]}
    if k == "brick":
        n = nt.nodes.new("ShaderNodeTexBrick")
        for ident, key in (("Scale", "scale"), ("Mortar Size", "mortar_size"), ("Mortar Smooth", "mortar_smooth"),
                           ("Bias", "bias"), ("Brick Width", "brick_width"), ("Row Height", "row_height")):
            set_input_id(n, ident, case[key])
        for ident, color in zip(("Color1", "Color2", "Mortar"), case["colors"]):
            set_input_id(n, ident, color + (1.0,))
        n.offset, n.offset_frequency = case["offset"], case["offset_frequency"]
        n.squash, n.squash_frequency = case["squash"], case["squash_frequency"]
        return n, {"fac": n.outputs["Fac"], "color": n.outputs["Color"]}
    if k == "gradient":
        n = nt.nodes.new("ShaderNodeTexGradient")
        n.gradient_type = GRADIENT_TYPES[case["gtype"]]
        return n, {"fac": n.outputs["Fac"], "color": n.outputs["Color"]}
    if k == "magic":
        n = nt.nodes.new("ShaderNodeTexMagic")
        n.turbulence_depth = case["depth"]
        set_input_id(n, "Scale", case["scale"])
        set_input_id(n, "Distortion", case["distortion"])
        return n, {"fac": n.outputs["Fac"], "color": n.outputs["Color"]}
    if k == "white_noise":
        n = nt.nodes.new("ShaderNodeTexWhiteNoise")
        n.noise_dimensions = DIM_NAMES[case["dims"]]
        return n, {"value": n.outputs["Value"], "color": n.outputs["Color"]}
    if k == "gabor":
        n = nt.nodes.new("ShaderNodeTexGabor")
        n.gabor_type = "3D" if case["gtype"] else "2D"
        for ident, key in (("Scale", "scale"), ("Frequency", "frequency"), ("Anisotropy", "anisotropy"),
                           ("Orientation 2D", "o2"), ("Orientation 3D", "o3")):
            set_input_id(n, ident, case[key])
        combine = nt.nodes.new("ShaderNodeCombineXYZ")
        for i, name in enumerate(("Value", "Phase", "Intensity")):
            nt.links.new(n.outputs[name], combine.inputs[i])
        return n, {"value,phase,intensity": combine.outputs[0]}
    if k == "curves":
        n = nt.nodes.new("ShaderNodeRGBCurve" if case["curve"] == "RGB" else "ShaderNodeVectorCurve")
        set_curve(n.mapping, case["points"], case["extend"])
        if case["curve"] == "RGB":
            nt.links.new(coords, n.inputs["Color"])  # the Vector one is linked by build_scene
    else:
        n = nt.nodes.new(COLOR_NODES[k])
        if k == "float_curve":
            set_curve(n.mapping, case["points"], case["extend"])
        if k in ("bright_contrast", "gamma"):
            nt.links.new(coords, n.inputs["Color"])
        if k == "vector_rotate":
            n.rotation_type, n.invert = case["rtype"], case["invert"]
            nt.links.new(coords, n.inputs["Vector"])
    for ident, value in case.get("const", {}).items():
        set_input_id(n, ident, value)
    for ident, (axis, mul, add) in case.get("drive", {}).items():
        drive_input(nt, coords, n, ident, axis, mul, add)
    key = {"float_curve": "value", "vector_rotate": "vector"}.get(k, "color")
    return n, {key: n.outputs[0]}


def texture_node(nt, case, coords):
    k = case["kind"]
    if k in NEW_KINDS:
        return new_texture_node(nt, case, coords)
    if k == "noise":
        n = nt.nodes.new("ShaderNodeTexNoise")
        n.noise_dimensions = DIM_NAMES[case["dims"]]
        for name in ("Scale", "Detail", "Roughness", "Distortion"):
            set_input(n, name, case[name.lower()])
        if VERSION >= 400:
            n.normalize = bool(case["normalize"])
            set_input(n, "Lacunarity", case["lacunarity"])
        if VERSION >= 401:
            n.noise_type = NOISE_TYPES[case["type"]]
            set_input(n, "Offset", case["offset"])
            set_input(n, "Gain", case["gain"])
        return n, {"color": n.outputs["Color"], "fac": n.outputs["Fac"]}
    if k == "musgrave":
        n = nt.nodes.new("ShaderNodeTexMusgrave")
        n.musgrave_dimensions = DIM_NAMES[case["dims"]]
        n.musgrave_type = NOISE_TYPES[case["type"]]
        for name in ("Scale", "Detail", "Dimension", "Lacunarity", "Offset", "Gain"):
            set_input(n, name, case[name.lower()])
        return n, {"fac": n.outputs[0]}
    if k == "wave":
        n = nt.nodes.new("ShaderNodeTexWave")
        n.wave_type = "BANDS" if case["wave_type"] == 0 else "RINGS"
        if case["wave_type"] == 0:
            n.bands_direction = WAVE_BANDS_DIRS[case["direction"]]
        else:
            n.rings_direction = WAVE_RINGS_DIRS[case["direction"]]
        n.wave_profile = WAVE_PROFILES[case["profile"]]
        for name, key in (("Scale", "scale"), ("Distortion", "distortion"), ("Detail", "detail"),
                          ("Detail Scale", "detail_scale"), ("Detail Roughness", "detail_roughness"),
                          ("Phase Offset", "phase")):
            set_input(n, name, case[key])
        return n, {"fac": n.outputs["Fac"], "color": n.outputs["Color"]}
    n = nt.nodes.new("ShaderNodeTexVoronoi")
    n.voronoi_dimensions = DIM_NAMES[case["dims"]]
    n.feature = VORONOI_FEATURES[case["feature"]]
    n.distance = VORONOI_METRICS[case["metric"]]
    for name in ("Scale", "Smoothness", "Exponent", "Randomness"):
        set_input(n, name, case[name.lower()])
    if VERSION >= 400:
        n.normalize = bool(case["normalize"])
        for name in ("Detail", "Roughness", "Lacunarity"):
            set_input(n, name, case[name.lower()])
    combine = nt.nodes.new("ShaderNodeCombineXYZ")
    for out_name, idx in (("Distance", 0), ("W", 1), ("Radius", 2)):
        sock = available(n.outputs, out_name)
        if sock is not None:  # links from unavailable sockets are ignored by Blender
            nt.links.new(sock, combine.inputs[idx])
    outs = {"distance,w,radius": combine.outputs[0]}
    for name in ("Color", "Position"):
        outs[name.lower()] = available(n.outputs, name)  # e.g. no Position in 1D, no Color for edges
    return n, outs


def tilted_quad(name):
    """A unit quad in x, y in [-1, 1], tilted in its own space so that Object
    coordinates span z as well."""
    verts = [(x, y, 0.35 * x + 0.2 * y + 0.1) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], [(0, 1, 2, 3)])
    mesh.update()
    return mesh


def build_scene(cases):
    global COLS
    # The camera's ortho scale spans the wider side of the image: keep it the width.
    COLS = max(COLS, math.ceil(math.sqrt(len(cases))))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    rows = (len(cases) + COLS - 1) // COLS
    tile_world = 2.0  # world units per tile; quads are scaled to leave a gap
    for i, case in enumerate(cases):
        row, col = divmod(i, COLS)
        mat, emission = ru.emission_material(f"case{i}")
        nt = mat.node_tree
        coords = nt.nodes.new("ShaderNodeTexCoord")
        tex, outs = texture_node(nt, case, coords.outputs["Object"])
        if available(tex.inputs, "Vector") is not None:
            nt.links.new(coords.outputs["Object"], tex.inputs["Vector"])
        if available(tex.inputs, "W") is not None:
            sep = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(coords.outputs["Object"], sep.inputs[0])
            if case.get("dims") == 1:
                nt.links.new(sep.outputs["X"], tex.inputs["W"])
            else:
                add = nt.nodes.new("ShaderNodeMath")
                add.operation = "ADD"
                nt.links.new(sep.outputs["X"], add.inputs[0])
                nt.links.new(sep.outputs["Y"], add.inputs[1])
                nt.links.new(add.outputs[0], tex.inputs["W"])
        case["_material"] = mat
        case["_emission"] = emission
        case["_outputs"] = outs
        case["_coords"] = coords.outputs["Object"]
        case["_tile"] = (row, col)
        mesh = tilted_quad(f"quad{i}")
        mesh.materials.append(mat)
        ru.add_tile(scene, f"quad{i}", mesh, row, col, rows, COLS, tile_world)

    cam_data = bpy.data.cameras.new("Camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = COLS * tile_world
    cam_data.clip_start = 0.1
    cam_data.clip_end = 100.0
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = (0.0, 0.0, 10.0)
    scene.camera = cam

    world = bpy.data.worlds.new("World")
    world.color = (0.0, 0.0, 0.0)
    scene.world = world

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y = COLS * TILE, rows * TILE
    r.resolution_percentage = 100
    r.film_transparent = True
    r.use_persistent_data = False
    c = scene.cycles
    c.device = "CPU"
    c.samples = 1
    if hasattr(c, "use_adaptive_sampling"):
        c.use_adaptive_sampling = False
    c.use_denoising = False
    c.pixel_filter_type = "BLACKMAN_HARRIS"
    c.filter_width = 0.01
    c.seed = 0
    c.use_animated_seed = False
    c.max_bounces = 0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    s = r.image_settings
    s.file_format = "OPEN_EXR"
    s.color_depth = "32"
    s.color_mode = "RGBA"
    s.exr_codec = "ZIP"
    return scene, rows


def relink(cases, group_index):
    """Points every tile's Emission at output group `group_index` (-1: the
    Object coordinates)."""
    for case in cases:
        nt = case["_material"].node_tree
        target = case["_emission"].inputs["Color"]
        for link in list(target.links):
            nt.links.remove(link)
        if group_index < 0:
            nt.links.new(case["_coords"], target)
            continue
        groups = OUTPUT_GROUPS[case["kind"]]
        socket = case["_outputs"][groups[group_index][0]] if group_index < len(groups) else None
        if socket is not None:
            nt.links.new(socket, target)
        else:
            target.default_value = (0.0, 0.0, 0.0, 1.0)


def render(scene, path, height, width):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    px = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, 4)[::-1]
    bpy.data.images.remove(image)
    return px


# ---------------------------------------------------------------------------
# Comparison


def run_probe(lines):
    probe = os.environ.get("MICROPOLY_TEXTURE_PROBE")
    if not probe or not os.path.exists(probe):
        raise RuntimeError("MICROPOLY_TEXTURE_PROBE must name the texture_probe executable")
    result = subprocess.run([probe], input="\n".join(lines) + "\n", capture_output=True, text=True, check=False)
    if result.returncode != 0:
        raise RuntimeError(f"texture_probe failed: {result.stderr[:2000]}")
    rows = [row.split() for row in result.stdout.splitlines()]
    if len(rows) != len(lines):
        raise RuntimeError(f"texture_probe answered {len(rows)} lines for {len(lines)} queries")
    return rows


def main():
    t0 = time.time()
    cases = build_cases()
    scene, rows = build_scene(cases)
    height, width = rows * TILE, COLS * TILE
    folder = tempfile.mkdtemp(prefix="mp-textures-")
    relink(cases, -1)
    coords = render(scene, os.path.join(folder, "coords.exr"), height, width)
    n_groups = max(len(g) for g in OUTPUT_GROUPS.values())
    images = []
    for g in range(n_groups):
        relink(cases, g)
        images.append(render(scene, os.path.join(folder, f"group{g}.exr"), height, width))
    t_render = time.time() - t0

    # Pixels that saw a quad in every render.
    covered = coords[..., 3] == 1.0
    for img in images:
        covered &= img[..., 3] == 1.0

    # What the add-on embeds in a program: curve tables, colour space matrices.
    prefix = []
    xyz_rows = NT.xyz_to_scene_rows()
    for i, case in enumerate(cases):
        if case["kind"] in ("curves", "float_curve"):
            node = next(n for n in case["_material"].node_tree.nodes if hasattr(n, "mapping"))
            case["_table"] = NT.curve_table(node.mapping, case["curve"], VERSION)
            case["_table_id"] = i
            values = case["_table"][3]
            prefix.append(f"table {i} {len(values)} {gs(values)}")
        elif case["kind"] == "wavelength":
            case["_rows"] = xyz_rows
        elif case["kind"] == "blackbody":
            case["_rows"] = NT.rec709_to_scene_rows()

    failures = []
    # Sanity: the coordinate render is the Object coordinate of the pixel's
    # centre to well within a pixel (a wrong colour transform would show here).
    pixel_obj = 2.0 / (0.9 * TILE)  # object units per pixel (quad of 2 units over 0.9 tile)
    lines, where = [], []
    for i, case in enumerate(cases):
        row, col = case["_tile"]
        y0, x0 = row * TILE, col * TILE
        tile_cov = covered[y0:y0 + TILE, x0:x0 + TILE]
        ys, xs = np.nonzero(tile_cov)
        if len(ys) < 0.5 * (0.9 * TILE) ** 2:
            failures.append(f"{case['label']}: only {len(ys)} covered pixels")
        xyz = coords[y0 + ys, x0 + xs, :3]
        centre_x = ((xs + 0.5) - TILE / 2.0) * pixel_obj
        centre_y = (TILE / 2.0 - (ys + 0.5)) * pixel_obj
        err = max(np.abs(xyz[:, 0] - centre_x).max(initial=0.0), np.abs(xyz[:, 1] - centre_y).max(initial=0.0))
        if err > 0.5 * pixel_obj:
            failures.append(f"{case['label']}: coordinate render is off the pixel centres by {err:.3g}")
        x = xyz[:, 0].astype(np.float32)
        y = xyz[:, 1].astype(np.float32)
        z = xyz[:, 2].astype(np.float32)
        w = x if case.get("dims") == 1 else (x + y).astype(np.float32)  # the Math node's float add
        driven = {}
        for ident, (axis, mul, add) in case.get("drive", {}).items():
            c = (x, y, z)[axis]
            driven[ident] = ((c * np.float32(mul)).astype(np.float32) + np.float32(add)).astype(np.float32)
        for k in range(len(ys)):
            if case["kind"] in NEW_KINDS:
                d = {ident: float(v[k]) for ident, v in driven.items()}
                lines.append(new_probe_line(case, float(x[k]), float(y[k]), float(z[k]), float(w[k]), d))
            else:
                lines.append(probe_line(case, float(x[k]), float(y[k]), float(z[k]), float(w[k])))
        where.append((i, y0 + ys, x0 + xs))
    t_probe0 = time.time()
    answers = run_probe(prefix + lines)[len(prefix):]
    t_probe = time.time() - t_probe0

    print(f"\nBlender {bpy.app.version_string} (version code {VERSION}): {len(cases)} cases, "
          f"{len(lines)} points; render {t_render:.1f} s, probe {t_probe:.1f} s")
    print(f"{'case':58s} {'output':18s} {'max':>9s} {'median':>9s} {'<=1e-3':>8s}")
    offset = 0
    summary = {}
    for i, ys, xs in where:
        case = cases[i]
        n = len(ys)
        probe_vals = np.array(answers[offset:offset + n], dtype=np.float64) if n else np.zeros((0, 9))
        offset += n
        for g, (group, columns) in enumerate(OUTPUT_GROUPS[case["kind"]]):
            if case["_outputs"][group] is None:
                continue  # the node does not offer this output for these settings
            got = images[g][ys, xs, :3].astype(np.float64)
            ref = probe_vals[:, list(columns)]
            diff = np.abs(got - ref)
            diff[np.isnan(diff)] = np.inf
            per_pixel = diff.max(axis=1) if n else np.zeros(0)
            worst = float(per_pixel.max()) if n else 0.0
            median = float(np.median(per_pixel)) if n else 0.0
            fraction = float((per_pixel <= TOL).mean()) if n else 0.0
            print(f"{case['label']:58s} {group:18s} {worst:9.2e} {median:9.2e} {100 * fraction:7.2f}%")
            kind_stats = summary.setdefault(case["kind"], [0.0, [], 0, 0])
            kind_stats[0] = max(kind_stats[0], worst)
            kind_stats[1].append(per_pixel)
            kind_stats[2] += int((per_pixel <= TOL).sum())
            kind_stats[3] += n
            if fraction < MIN_FRACTION or median > MAX_MEDIAN:
                failures.append(f"{case['label']} [{group}]: max {worst:.3g}, median {median:.3g}, "
                                f"{100 * fraction:.2f}% within {TOL}")
    print("\nper texture (all outputs): max | median | fraction within 1e-3")
    for kind, (worst, diffs, ok, total) in summary.items():
        med = float(np.median(np.concatenate(diffs))) if diffs else 0.0
        print(f"  {kind:9s} {worst:9.2e} {med:9.2e} {100.0 * ok / max(total, 1):8.3f}%")
    print(f"total {time.time() - t0:.1f} s")
    if failures:
        print("\nFAILED:\n  " + "\n  ".join(failures))
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    ru.run_test(main)
