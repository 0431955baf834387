# SPDX-License-Identifier: GPL-3.0-or-later
"""Converter nodes: Math, Vector Math, Mix (and the older MixRGB), Hue
Saturation Value, Map Range, Clamp, Color Ramp, Separate and Combine,
RGB to BW and Invert. The kernels' side is kernels/materials/mp_node_lib.h.

Each function takes the NodeCompiler and the node and returns the node's
outputs by socket identifier as (expression, kind, value range or None);
NODES maps node types to them (node_registry.py)."""

from .node_kinds import FLOAT, VEC

# The operations' order is their index in the kernels' switch statements.
MATH_OPS = ["ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM", "SQRT", "INVERSE_SQRT",
            "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM", "LESS_THAN", "GREATER_THAN", "SIGN", "COMPARE",
            "SMOOTH_MIN", "SMOOTH_MAX", "ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO",
            "WRAP", "SNAP", "PINGPONG", "SINE", "COSINE", "TANGENT", "ARCSINE", "ARCCOSINE", "ARCTANGENT",
            "ARCTAN2", "SINH", "COSH", "TANH", "RADIANS", "DEGREES"]
VMATH_OPS = ["ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "CROSS_PRODUCT", "PROJECT", "REFLECT",
             "DOT_PRODUCT", "DISTANCE", "LENGTH", "SCALE", "NORMALIZE", "ABSOLUTE", "MINIMUM", "MAXIMUM", "FLOOR",
             "CEIL", "FRACTION", "MODULO", "WRAP", "SNAP", "SINE", "COSINE", "TANGENT", "FACEFORWARD"]
VMATH_VALUE_OPS = {"DOT_PRODUCT", "DISTANCE", "LENGTH"}
BLEND_MODES = ["MIX", "ADD", "MULTIPLY", "SUBTRACT", "SCREEN", "DIVIDE", "DIFFERENCE", "DARKEN", "LIGHTEN",
               "OVERLAY", "DODGE", "BURN", "SOFT_LIGHT", "LINEAR_LIGHT", "EXCLUSION", "HUE", "SATURATION", "VALUE",
               "COLOR"]
RANGE_MODES = ["LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP"]


def emit_math(c, node):
    op = node.operation
    if op not in MATH_OPS:
        c.warn(node, f"operation {op} is not supported")
        return {}
    a, b, c3 = (c.input(node, i, FLOAT) for i in range(3))
    expr = f"mp_math({MATH_OPS.index(op)}, {a[0]}, {b[0]}, {c3[0]})"
    rng = None
    ra, rb, rc = a[2], b[2], c3[2]
    if ra and rb:
        if op == "ADD":
            rng = (ra[0] + rb[0], ra[1] + rb[1])
        elif op == "SUBTRACT":
            rng = (ra[0] - rb[1], ra[1] - rb[0])
        elif op in ("MULTIPLY", "MULTIPLY_ADD"):
            prods = [x * y for x in ra for y in rb]
            rng = (min(prods), max(prods))
            if op == "MULTIPLY_ADD":
                rng = (rng[0] + rc[0], rng[1] + rc[1]) if rc else None
        elif op in ("MINIMUM", "MAXIMUM"):
            f = min if op == "MINIMUM" else max
            rng = (f(ra[0], rb[0]), f(ra[1], rb[1]))
    if op in ("SINE", "COSINE"):
        rng = (-1.0, 1.0)
    if node.use_clamp:
        expr = f"mp_nl_clamp01({expr})"
        rng = (max(0.0, rng[0]), min(1.0, rng[1])) if rng else (0.0, 1.0)
    return {node.outputs[0].identifier: c.fn.temp(FLOAT, expr, rng)}


def emit_vector_math(c, node):
    op = node.operation
    if op not in VMATH_OPS:
        c.warn(node, f"operation {op} is not supported")
        return {}
    a, b, v3 = (c.input(node, i, VEC)[0] for i in range(3))
    scale = c.input(node, 3, FLOAT)[0] if len(node.inputs) > 3 else "1.0f"
    val = c.fn.temp(FLOAT, "0.0f")
    vec = c.fn.temp(VEC, f"mp_vector_math({VMATH_OPS.index(op)}, {a}, {b}, {v3}, {scale}, &{val[0]})")
    return {"Vector": vec, "Value": val}


def _blend(c, node, mode, clamp_result, clamp_factor, fac, a, b, out_id):
    if mode not in BLEND_MODES:
        c.warn(node, f"blend mode {mode} is not supported; Mix is used")
        mode = "MIX"
    t = f"mp_nl_clamp01({fac[0]})" if clamp_factor else fac[0]
    expr = f"mp_blend({BLEND_MODES.index(mode)}, {t}, {a[0]}, {b[0]})"
    if clamp_result:
        expr = f"mp_nl_clamp01_3({expr})"
    return {out_id: c.fn.temp(VEC, expr)}


def emit_mix(c, node):
    dt = node.data_type
    if dt == "FLOAT":
        fac = c.by_id(node, "Factor_Float", FLOAT)
        a, b = c.by_id(node, "A_Float", FLOAT), c.by_id(node, "B_Float", FLOAT)
        t = f"mp_nl_clamp01({fac[0]})" if node.clamp_factor else fac[0]
        return {"Result_Float": c.fn.temp(FLOAT, f"mix({a[0]}, {b[0]}, {t})")}
    if dt == "VECTOR":
        uniform = getattr(node, "factor_mode", "UNIFORM") == "UNIFORM"
        fac = c.by_id(node, "Factor_Float" if uniform else "Factor_Vector", FLOAT if uniform else VEC)
        a, b = c.by_id(node, "A_Vector", VEC), c.by_id(node, "B_Vector", VEC)
        t = fac[0]
        if node.clamp_factor:
            t = f"mp_nl_clamp01({t})" if uniform else f"mp_nl_clamp01_3({t})"
        return {"Result_Vector": c.fn.temp(VEC, f"{a[0]} + ({b[0]} - {a[0]}) * {t}")}
    fac = c.by_id(node, "Factor_Float", FLOAT)
    a, b = c.by_id(node, "A_Color", VEC), c.by_id(node, "B_Color", VEC)
    return _blend(c, node, node.blend_type, node.clamp_result, node.clamp_factor, fac, a, b, "Result_Color")


def emit_mix_rgb(c, node):
    return _blend(c, node, node.blend_type, node.use_clamp, False, c.input(node, "Fac", FLOAT),
                  c.input(node, "Color1", VEC), c.input(node, "Color2", VEC), "Color")


def emit_hue_saturation(c, node):
    h, sat, val, fac = (c.input(node, k, FLOAT)[0] for k in ("Hue", "Saturation", "Value", "Fac"))
    col = c.input(node, "Color", VEC)[0]
    return {"Color": c.fn.temp(VEC, f"mp_hue_saturation({h}, {sat}, {val}, {fac}, {col})")}


def emit_map_range(c, node):
    mode = node.interpolation_type
    if getattr(node, "data_type", "FLOAT") == "FLOAT_VECTOR":
        names = ("Vector", "From_Min_FLOAT3", "From_Max_FLOAT3", "To_Min_FLOAT3", "To_Max_FLOAT3", "Steps_FLOAT3")
        args = [c.by_id(node, n, VEC)[0] for n in names]
        return {"Vector": c.fn.temp(VEC, f"mp_map_range3({RANGE_MODES.index(mode)}, " + ", ".join(args) +
                                         f", {1 if node.clamp else 0})")}
    args = [c.input(node, i, FLOAT) for i in range(6)]
    expr = (f"mp_map_range({RANGE_MODES.index(mode)}, " + ", ".join(a[0] for a in args) +
            f", {1 if node.clamp else 0})")
    lo, hi = args[3][2], args[4][2]
    rng = None
    if node.clamp and lo and hi and mode in ("LINEAR", "STEPPED"):
        rng = (min(lo[0], hi[0]), max(lo[1], hi[1]))
    return {"Result": c.fn.temp(FLOAT, expr, rng)}


def emit_clamp(c, node):
    v, lo, hi = (c.input(node, i, FLOAT) for i in range(3))
    rng = (min(lo[2][0], hi[2][0]), max(lo[2][1], hi[2][1])) if lo[2] and hi[2] else None
    return {"Result": c.fn.temp(FLOAT, f"mp_clamp_node({1 if node.clamp_type == 'RANGE' else 0}, "
                                       f"{v[0]}, {lo[0]}, {hi[0]})", rng)}


def emit_color_ramp(c, node):
    ramp = node.color_ramp
    if ramp.color_mode != "RGB":
        c.warn(node, f"{ramp.color_mode} color mode is not supported; RGB is used")
    interp = {"LINEAR": 0, "CONSTANT": 1, "EASE": 2}.get(ramp.interpolation)
    if interp is None:
        c.warn(node, f"{ramp.interpolation} interpolation is not supported; Linear is used")
        interp = 0
    elems = sorted(ramp.elements, key=lambda e: e.position)
    n = len(elems)
    fac = c.input(node, "Fac", FLOAT)[0]
    k = c.fn.counter
    c.fn.counter += 1
    pos = ", ".join(c.param(e.position) for e in elems)
    cols = ", ".join(c.param4(e.color) for e in elems)
    c.fn.lines.append(f"  const float ramp_pos{k}[{n}] = {{{pos}}};")
    c.fn.lines.append(f"  const float4 ramp_col{k}[{n}] = {{{cols}}};")
    rgba = c.fn.temp("float4", f"mp_color_ramp({interp}, {n}, ramp_pos{k}, ramp_col{k}, {fac})")
    return {"Color": (f"{rgba[0]}.xyz", VEC, None), "Alpha": (f"{rgba[0]}.w", FLOAT, (0.0, 1.0))}


def emit_separate(c, node):
    if node.type == "SEPARATE_COLOR" and node.mode != "RGB":
        c.warn(node, f"{node.mode} mode is not supported; RGB is used")
    v = c.fn.temp(VEC, c.input(node, 0, VEC)[0])
    outs = [o.identifier for o in node.outputs]
    return {outs[0]: (f"{v[0]}.x", FLOAT, None), outs[1]: (f"{v[0]}.y", FLOAT, None),
            outs[2]: (f"{v[0]}.z", FLOAT, None)}


def emit_combine(c, node):
    if node.type == "COMBINE_COLOR" and node.mode != "RGB":
        c.warn(node, f"{node.mode} mode is not supported; RGB is used")
    x, y, z = (c.input(node, i, FLOAT)[0] for i in range(3))
    return {node.outputs[0].identifier: c.fn.temp(VEC, f"(float3)({x}, {y}, {z})")}


def emit_rgb_to_bw(c, node):
    return {"Val": c.fn.temp(FLOAT, f"mp_rgb_to_bw({c.input(node, 0, VEC)[0]})")}


def emit_invert(c, node):
    fac, col = c.input(node, "Fac", FLOAT)[0], c.input(node, "Color", VEC)[0]
    return {"Color": c.fn.temp(VEC, f"mix({col}, (float3)(1.0f) - {col}, {fac})")}


NODES = {
    "MATH": emit_math,
    "VECT_MATH": emit_vector_math,
    "MIX_RGB": emit_mix_rgb,
    "MIX": emit_mix,
    "HUE_SAT": emit_hue_saturation,
    "MAP_RANGE": emit_map_range,
    "CLAMP": emit_clamp,
    "VALTORGB": emit_color_ramp,
    "SEPXYZ": emit_separate,
    "SEPRGB": emit_separate,
    "SEPARATE_COLOR": emit_separate,
    "COMBXYZ": emit_combine,
    "COMBRGB": emit_combine,
    "COMBINE_COLOR": emit_combine,
    "RGBTOBW": emit_rgb_to_bw,
    "INVERT": emit_invert,
}
