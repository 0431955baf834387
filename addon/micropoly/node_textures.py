# SPDX-License-Identifier: GPL-3.0-or-later
"""Pattern textures and colour nodes.

Each function takes the NodeCompiler and the node and returns the node's
outputs by socket identifier as (expression, kind, value range or None);
NODES maps node types to them (node_registry.py).

Nodes: Checker, Brick, Gradient, Magic, White Noise and Gabor (Blender 4.3+)
Textures (kernels/textures/mp_tex_pattern.h, mp_tex_gabor.h); Blackbody,
Wavelength, RGB Curves, Vector Curves, Float Curve, Bright/Contrast and
Gamma (kernels/textures/mp_tex_color.h).

The module-level helpers that need no compiler (colour space matrices,
curve tables, literals) import nothing from the add-on, so that tests can
load this file on its own and feed texture_probe the very same data."""

import math
import struct

# Cycles samples curve mappings into a table of RAMP_TABLE_SIZE + 1 entries
# at i / RAMP_TABLE_SIZE (Blender 3.x: RAMP_TABLE_SIZE entries at
# i / (RAMP_TABLE_SIZE - 1)); 3.4 and 4.5 are measured, 4.0 is assumed to be
# where the table grew.
CURVE_TABLE_SIZE = 256
CURVE_TABLE_FULL_VERSION = 400
FLT_MAX = 3.4028234663852886e38
GRADIENT_TYPES = ["LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE", "RADIAL"]
# Cycles' fallback XYZ (D65) -> Rec.709 matrix (used here only without
# mathutils); a scene space within 1e-4 of Rec.709 counts as Rec.709.
XYZ_TO_REC709 = ((3.2404542, -1.5371385, -0.4985314),
                 (-0.9692660, 1.8760108, 0.0415560),
                 (0.0556434, -0.2040259, 1.0572252))
REC709_THRESHOLD = 1e-4


def f32(x):
    """x rounded to single precision."""
    return struct.unpack("<f", struct.pack("<f", float(x)))[0]


def flit(x):
    """A single-precision C literal that reads back as f32(x) (0 for non-finite x)."""
    x = float(x)
    if not math.isfinite(x):
        x = 0.0
    s = "%.9g" % f32(x)
    if not any(ch in s for ch in ".e"):
        s += ".0"
    return s + "f"


def vec_lit(v):
    return "(float3)(" + ", ".join(flit(c) for c in v) + ")"


# ---------------------------------------------------------------------------
# Colour spaces


def _mat_mul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


def _mat_inv(m):
    (a, b, c), (d, e, f), (g, h, i) = m
    co = [[e * i - f * h, c * h - b * i, b * f - c * e],
          [f * g - d * i, a * i - c * g, c * d - a * f],
          [d * h - e * g, b * g - a * h, a * e - b * d]]
    det = a * co[0][0] + b * co[1][0] + c * co[2][0]
    return [[co[r][k] / det for k in range(3)] for r in range(3)]


def xyz_to_scene_rows():
    """Rows of the XYZ (D65) -> scene linear matrix of Blender's colour
    management (the OpenColorIO config's XYZ or ACES interchange role, as
    Cycles derives it); Cycles' Rec.709 fallback without mathutils."""
    try:
        from mathutils import Color
        cols = [tuple(Color(v).from_xyz_d65_to_scene_linear()) for v in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    except (ImportError, AttributeError):
        return [[f32(x) for x in row] for row in XYZ_TO_REC709]
    return [[f32(cols[c][r]) for c in range(3)] for r in range(3)]


def rec709_to_scene_rows():
    """Rows of the Rec.709 -> scene linear matrix of Blender's colour
    management, or None where the scene's linear space is Rec.709 (within
    1e-4, as Cycles decides; Blackbody then skips the conversion)."""
    try:
        from mathutils import Color
        cols = [tuple(Color(v).from_rec709_linear_to_scene_linear()) for v in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
        m = [[cols[c][r] for c in range(3)] for r in range(3)]
    except (ImportError, AttributeError):
        m = _mat_mul(xyz_to_scene_rows(), _mat_inv(XYZ_TO_REC709))
    if all(abs(m[r][c] - (1.0 if r == c else 0.0)) <= REC709_THRESHOLD for r in range(3) for c in range(3)):
        return None
    return [[f32(x) for x in row] for row in m]


# ---------------------------------------------------------------------------
# Curve mappings


def curve_minmax(mapping, count):
    """Smallest first and largest last point x over the first `count` curves."""
    lo, hi = FLT_MAX, -FLT_MAX
    for i in range(count):
        points = mapping.curves[i].points
        lo = min(lo, points[0].location[0])
        hi = max(hi, points[len(points) - 1].location[0])
    return f32(lo), f32(hi)


def curve_table(mapping, kind, version):
    """Cycles' table of a curve mapping: (min_x, max_x, extrapolate, values).
    kind "RGB" (R, G, B of the combined curve: 3 floats per entry), "VECTOR"
    (X, Y, Z: 3 floats per entry) or "FLOAT" (1 float per entry); entries
    sample [min_x, max_x] evenly (see CURVE_TABLE_SIZE), in single precision.
    Linear extrapolation beyond the table where the mapping extends by
    extrapolation."""
    count = {"RGB": 4, "VECTOR": 3, "FLOAT": 1}[kind]
    lo, hi = curve_minmax(mapping, count)
    span = f32(hi - lo)
    if hasattr(mapping, "update"):
        mapping.update()
    mapping.initialize()
    curves = [mapping.curves[i] for i in range(count)]
    if version >= CURVE_TABLE_FULL_VERSION:
        entries, steps = CURVE_TABLE_SIZE + 1, CURVE_TABLE_SIZE
    else:
        entries, steps = CURVE_TABLE_SIZE, CURVE_TABLE_SIZE - 1
    values = []
    for i in range(entries):
        t = f32(lo + f32(f32(i / steps) * span))
        if kind == "RGB":
            c = f32(mapping.evaluate(curves[3], t))
            values += [f32(mapping.evaluate(curves[k], c)) for k in range(3)]
        elif kind == "VECTOR":
            values += [f32(mapping.evaluate(curves[k], t)) for k in range(3)]
        else:
            values.append(f32(mapping.evaluate(curves[0], t)))
    extrapolate = getattr(mapping, "extend", "") == "EXTRAPOLATED"
    return lo, hi, extrapolate, values


# ---------------------------------------------------------------------------
# Emission


def _union(a, b):
    return (min(a[0], b[0]), max(a[1], b[1])) if a and b else None


def _default_mapping(node):
    m = getattr(node, "texture_mapping", None)
    if m is None:
        return True
    return (tuple(m.translation) == (0.0, 0.0, 0.0) and tuple(m.rotation) == (0.0, 0.0, 0.0)
            and tuple(m.scale) == (1.0, 1.0, 1.0) and (m.mapping_x, m.mapping_y, m.mapping_z) == ("X", "Y", "Z")
            and not m.use_min and not m.use_max)


def _mapping_warned(handler):
    """handler, after a warning where the texture's own mapping (in the
    node's properties) is not the identity: it is not supported."""
    def emit(compiler, node):
        if node.type.startswith("TEX_") and not _default_mapping(node):
            compiler.warn(node, "its texture mapping (node properties) is not supported; it is ignored")
        return handler(compiler, node)
    return emit


def _inputs(compiler, node, *spec):
    from .node_kinds import FLOAT, VEC

    kinds = {"f": FLOAT, "v": VEC}
    return [compiler.by_id(node, ident, kinds[k]) for ident, k in spec]


def _vector(compiler, node):
    """The Vector input, or Generated coordinates where it is unlinked."""
    return compiler.vector_or_generated(node)


def emit_checker(compiler, node):
    from .node_kinds import FLOAT, VEC

    compiler.headers.add("mp_tex_pattern.h")
    vec = _vector(compiler, node)
    c1, c2, scale = _inputs(compiler, node, ("Color1", "v"), ("Color2", "v"), ("Scale", "f"))
    fac = compiler.fn.temp(FLOAT, f"mp_tex_checker({vec}, {scale[0]})", (0.0, 1.0))
    color = compiler.fn.temp(VEC, f"mp_tex_checker_color({fac[0]}, {c1[0]}, {c2[0]})", _union(c1[2], c2[2]))
    return {"Fac": fac, "Color": color}


def emit_brick(compiler, node):
    from .node_kinds import FLOAT, VEC

    compiler.headers.add("mp_tex_pattern.h")
    vec = _vector(compiler, node)
    c1, c2, mortar, scale, size, smooth, bias, width, height = _inputs(
        compiler, node, ("Color1", "v"), ("Color2", "v"), ("Mortar", "v"), ("Scale", "f"), ("Mortar Size", "f"),
        ("Mortar Smooth", "f"), ("Bias", "f"), ("Brick Width", "f"), ("Row Height", "f"))
    color = compiler.fn.temp(VEC, "(float3)(0.0f)", None)
    args = ", ".join(a[0] for a in (c1, c2, mortar, scale, size, smooth, bias, width, height))
    fac = compiler.fn.temp(FLOAT, f"mp_tex_brick({vec}, {args}, {compiler.param(node.offset)}, "
                                  f"{int(node.offset_frequency)}, {compiler.param(node.squash)}, "
                                  f"{int(node.squash_frequency)}, {compiler.version}, "
                                  f"&{color[0]})", (0.0, 1.0))
    # The colour mixes the brick colours by the tint, then the mortar by Fac.
    rng = _union(_union(c1[2], c2[2]), mortar[2])
    return {"Fac": fac, "Color": (color[0], VEC, rng)}


def emit_gradient(compiler, node):
    from .node_kinds import FLOAT, VEC

    compiler.headers.add("mp_tex_pattern.h")
    vec = _vector(compiler, node)
    gtype = GRADIENT_TYPES.index(node.gradient_type) if node.gradient_type in GRADIENT_TYPES else 0
    fac = compiler.fn.temp(FLOAT, f"mp_tex_gradient({vec}, {gtype})", (0.0, 1.0))
    return {"Fac": fac, "Color": (f"(float3)({fac[0]})", VEC, (0.0, 1.0))}


def emit_magic(compiler, node):
    from .node_kinds import FLOAT, VEC

    compiler.headers.add("mp_tex_pattern.h")
    vec = _vector(compiler, node)
    scale, distortion = _inputs(compiler, node, ("Scale", "f"), ("Distortion", "f"))
    depth = max(0, min(10, int(node.turbulence_depth)))
    # From depth 1 on every channel is Distortion times a sine or cosine
    # before being divided by twice Distortion: [0, 1].
    rng = (0.0, 1.0) if depth > 0 else None
    color = compiler.fn.temp(VEC, f"mp_tex_magic({vec}, {scale[0]}, {depth}, {distortion[0]})", rng)
    fac = compiler.fn.temp(FLOAT, f"mp_tex_magic_fac({color[0]})", rng)
    return {"Fac": fac, "Color": color}


def emit_white_noise(compiler, node):
    from .node_kinds import FLOAT, VEC

    compiler.headers.add("mp_tex_pattern.h")
    dims = int(node.noise_dimensions[0]) if node.noise_dimensions[:1] in ("1", "2", "3", "4") else 3
    # Cycles reads an unlinked Vector as its value (no texture coordinates).
    vec, w = _inputs(compiler, node, ("Vector", "v"), ("W", "f"))
    value = compiler.fn.temp(FLOAT, f"mp_tex_white_noise_value({vec[0]}, {w[0]}, {dims})", (0.0, 1.0))
    color = compiler.fn.temp(VEC, f"mp_tex_white_noise_color({vec[0]}, {w[0]}, {dims})", (0.0, 1.0))
    return {"Value": value, "Color": color}


def emit_gabor(compiler, node):
    from .node_kinds import FAC_RANGE, FLOAT

    compiler.headers.add("mp_tex_gabor.h")
    vec = _vector(compiler, node)
    gtype = 1 if node.gabor_type == "3D" else 0
    scale, freq, aniso, o2, o3 = _inputs(compiler, node, ("Scale", "f"), ("Frequency", "f"), ("Anisotropy", "f"),
                                         ("Orientation 2D", "f"), ("Orientation 3D", "v"))
    fn = compiler.fn
    # Value and Intensity are normalised to stay close to [0, 1] (not bounded).
    value = fn.temp(FLOAT, "0.0f", FAC_RANGE)
    phase = fn.temp(FLOAT, "0.0f", (0.0, 1.0))
    intensity = fn.temp(FLOAT, "0.0f", (0.0, FAC_RANGE[1]))
    fn.lines.append(f"  mp_tex_gabor({vec}, {gtype}, {scale[0]}, {freq[0]}, {aniso[0]}, {o2[0]}, {o3[0]}, "
                    f"&{value[0]}, &{phase[0]}, &{intensity[0]});")
    return {"Value": value, "Phase": phase, "Intensity": intensity}


def emit_blackbody(compiler, node):
    from .node_kinds import VEC

    compiler.headers.add("mp_tex_color.h")
    (t,) = _inputs(compiler, node, ("Temperature", "f"))
    rows = rec709_to_scene_rows()
    if rows is None:
        expr = f"mp_blackbody({t[0]}, 0, (float3)(1.0f, 0.0f, 0.0f), (float3)(0.0f, 1.0f, 0.0f), " \
               f"(float3)(0.0f, 0.0f, 1.0f))"
    else:
        expr = f"mp_blackbody({t[0]}, 1, " + ", ".join(vec_lit(r) for r in rows) + ")"
    return {"Color": compiler.fn.temp(VEC, expr)}


def emit_wavelength(compiler, node):
    from .node_kinds import VEC

    compiler.headers.add("mp_tex_color.h")
    (lam,) = _inputs(compiler, node, ("Wavelength", "f"))
    rows = xyz_to_scene_rows()
    return {"Color": compiler.fn.temp(VEC, f"mp_wavelength({lam[0]}, " + ", ".join(vec_lit(r) for r in rows) + ")")}


def emit_curves(compiler, node):
    from .node_kinds import FLOAT, VEC

    compiler.headers.add("mp_tex_color.h")
    if node.type == "CURVE_FLOAT":
        fac, value = _inputs(compiler, node, ("Factor", "f"), ("Value", "f"))
        lo, hi, extrapolate, values = curve_table(node.mapping, "FLOAT", compiler.version)
        table, lo, hi = compiler.param_table(values), compiler.param(lo), compiler.param(hi)
        expr = f"mp_curve_float_p({table}, {len(values)}, {lo}, {hi}, {int(extrapolate)}, {fac[0]}, {value[0]})"
        return {"Value": compiler.fn.temp(FLOAT, expr)}
    rgb = node.type == "CURVE_RGB"
    key = "Color" if rgb else "Vector"
    fac, value = _inputs(compiler, node, ("Fac", "f"), (key, "v"))
    lo, hi, extrapolate, values = curve_table(node.mapping, "RGB" if rgb else "VECTOR", compiler.version)
    table, lo, hi = compiler.param_table(values), compiler.param(lo), compiler.param(hi)
    expr = f"mp_curves_rgb_p({table}, {len(values) // 3}, {lo}, {hi}, {int(extrapolate)}, {fac[0]}, {value[0]})"
    return {key: compiler.fn.temp(VEC, expr)}


def emit_bright_contrast(compiler, node):
    from .node_kinds import VEC

    compiler.headers.add("mp_tex_color.h")
    color, bright, contrast = _inputs(compiler, node, ("Color", "v"), ("Bright", "f"), ("Contrast", "f"))
    return {"Color": compiler.fn.temp(VEC, f"mp_bright_contrast({color[0]}, {bright[0]}, {contrast[0]})")}


def emit_gamma(compiler, node):
    from .node_kinds import VEC

    compiler.headers.add("mp_tex_color.h")
    color, gamma = _inputs(compiler, node, ("Color", "v"), ("Gamma", "f"))
    return {"Color": compiler.fn.temp(VEC, f"mp_gamma({color[0]}, {gamma[0]})")}


ROTATE_TYPES = ("AXIS_ANGLE", "X_AXIS", "Y_AXIS", "Z_AXIS", "EULER_XYZ")


def emit_vector_rotate(compiler, node):
    """Vector Rotate: the Vector about Center, by the type's inputs (Axis and
    Angle, Angle alone, or Rotation as Euler XYZ); an unlinked Vector is
    (0, 0, 0) as in Cycles."""
    from .node_kinds import VEC

    compiler.headers.add("mp_vector_rotate.h")
    vec, center, axis, angle, rotation = _inputs(compiler, node, ("Vector", "v"), ("Center", "v"), ("Axis", "v"),
                                                 ("Angle", "f"), ("Rotation", "v"))
    kind = ROTATE_TYPES.index(node.rotation_type)
    return {"Vector": compiler.fn.temp(VEC, f"mp_vector_rotate({kind}, {1 if node.invert else 0}, {vec[0]}, "
                                            f"{center[0]}, {axis[0]}, {angle[0]}, {rotation[0]})")}


_HANDLERS = {
    "TEX_CHECKER": emit_checker,
    "TEX_BRICK": emit_brick,
    "TEX_GRADIENT": emit_gradient,
    "TEX_MAGIC": emit_magic,
    "TEX_WHITE_NOISE": emit_white_noise,
    "TEX_GABOR": emit_gabor,
    "BLACKBODY": emit_blackbody,
    "WAVELENGTH": emit_wavelength,
    "CURVE_RGB": emit_curves,
    "CURVE_VEC": emit_curves,
    "CURVE_FLOAT": emit_curves,
    "BRIGHTCONTRAST": emit_bright_contrast,
    "GAMMA": emit_gamma,
    "VECTOR_ROTATE": emit_vector_rotate,
}
# The node types this family compiles (node_registry.py).
NODES = {t: _mapping_warned(h) for t, h in _HANDLERS.items()}
