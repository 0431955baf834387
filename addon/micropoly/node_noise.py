# SPDX-License-Identifier: GPL-3.0-or-later
"""Procedural noise textures: Noise, Musgrave (before 4.1), Wave and
Voronoi, as kernels/textures/mp_tex_noise.h, mp_tex_wave.h and
mp_tex_voronoi.h compute them, in every dimension and with every version's
conventions (the compiler's Blender version is passed on).

Each function takes the NodeCompiler and the node and returns the node's
outputs by socket identifier as (expression, kind, value range or None);
NODES maps node types to them (node_registry.py)."""

import math

from .node_kinds import FAC_RANGE, FLOAT, VEC

FRACTAL_TYPES = ["FBM", "MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "HETERO_TERRAIN"]
VORONOI_FEATURES = ["F1", "F2", "SMOOTH_F1", "DISTANCE_TO_EDGE", "N_SPHERE_RADIUS"]
VORONOI_METRICS = ["EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI"]
TEXTURE_HEADERS = {"TEX_NOISE": "mp_tex_noise.h", "TEX_MUSGRAVE": "mp_tex_noise.h",
                   "TEX_VORONOI": "mp_tex_voronoi.h", "TEX_WAVE": "mp_tex_wave.h"}


def _dims(s):
    return int(s[0]) if s and s[0] in "1234" else 3


def emit_noise_texture(c, node):
    t, fn, ver = node.type, c.fn, c.version
    c.headers.add(TEXTURE_HEADERS[t])
    inp = lambda name, default="0.0f": c.input(node, name, FLOAT)[0] if name in node.inputs else default
    vec = c.vector_or_generated(node)
    if t == "TEX_NOISE":
        dims = _dims(node.noise_dimensions)
        ntype = FRACTAL_TYPES.index(getattr(node, "noise_type", "FBM"))
        normalize = 1 if getattr(node, "normalize", True) else 0
        fac, col = fn.temp(FLOAT, "0.0f", FAC_RANGE), fn.temp(VEC, "(float3)(0.0f)")
        fn.lines.append(f"  mp_tex_noise({vec}, {inp('W')}, {dims}, {ntype}, {normalize}, {inp('Scale')}, "
                        f"{inp('Detail')}, {inp('Roughness')}, {inp('Lacunarity', '2.0f')}, "
                        f"{inp('Offset')}, {inp('Gain', '1.0f')}, {inp('Distortion')}, {ver}, "
                        f"&{fac[0]}, &{col[0]});")
        return {"Fac": fac, "Color": col}
    if t == "TEX_MUSGRAVE":
        dims = _dims(node.musgrave_dimensions)
        mtype = FRACTAL_TYPES.index(node.musgrave_type)
        expr = (f"mp_tex_musgrave({vec}, {inp('W')}, {dims}, {mtype}, {inp('Scale')}, {inp('Detail')}, "
                f"{inp('Dimension')}, {inp('Lacunarity')}, {inp('Offset')}, {inp('Gain')}, {ver})")
        return {"Fac": fn.temp(FLOAT, expr)}
    if t == "TEX_WAVE":
        wtype = 0 if node.wave_type == "BANDS" else 1
        direction = (["X", "Y", "Z", "DIAGONAL"].index(node.bands_direction) if wtype == 0 else
                     ["X", "Y", "Z", "SPHERICAL"].index(node.rings_direction))
        profile = ["SIN", "SAW", "TRI"].index(node.wave_profile)
        fac, col = fn.temp(FLOAT, "0.0f", FAC_RANGE), fn.temp(VEC, "(float3)(0.0f)")
        fn.lines.append(f"  mp_tex_wave({vec}, {wtype}, {direction}, {profile}, {inp('Scale')}, "
                        f"{inp('Distortion')}, {inp('Detail')}, {inp('Detail Scale')}, "
                        f"{inp('Detail Roughness')}, {inp('Phase Offset')}, {ver}, &{fac[0]}, &{col[0]});")
        return {"Fac": fac, "Color": col}
    # Voronoi
    dims = _dims(node.voronoi_dimensions)
    feature = VORONOI_FEATURES.index(node.feature)
    metric = VORONOI_METRICS.index(node.distance)
    normalize = 1 if getattr(node, "normalize", False) else 0
    # F1 lies within the point's own cell: at most the cell diagonal away.
    near = node.feature in ("F1", "SMOOTH_F1") and node.distance == "EUCLIDEAN"
    dist = fn.temp(FLOAT, "0.0f", (0.0, math.sqrt(dims)) if near else None)
    col = fn.temp(VEC, "(float3)(0.0f)")
    pos, w, rad = fn.temp(VEC, "(float3)(0.0f)"), fn.temp(FLOAT, "0.0f"), fn.temp(FLOAT, "0.0f")
    fn.lines.append(f"  mp_tex_voronoi({vec}, {inp('W')}, {dims}, {feature}, {metric}, {inp('Scale')}, "
                    f"{inp('Detail')}, {inp('Roughness', '0.5f')}, {inp('Lacunarity', '2.0f')}, "
                    f"{inp('Smoothness', '1.0f')}, {inp('Exponent', '0.5f')}, {inp('Randomness', '1.0f')}, "
                    f"{normalize}, {ver}, &{dist[0]}, &{col[0]}, &{pos[0]}, &{w[0]}, &{rad[0]});")
    return {"Distance": dist, "Color": col, "Position": pos, "W": w, "Radius": rad}


NODES = {t: emit_noise_texture for t in TEXTURE_HEADERS}
